//! Guaranteed integration of a solid given by a distance bound.
//!
//! A distance bound `f` never overstates the distance to the surface and has the sign
//! of the side (the contract the sphere tracer relies on). So a cube of circumradius `r`
//! whose centre has `|f| > r` holds no surface: it is wholly inside (`f < 0`) or wholly
//! outside — the Lipschitz form of interval arithmetic, proved per cell. The cubes left
//! unproved (the *boundary*) are split in eight, level by level, until the integrals
//! they leave open are within the tolerance or the cell budget is spent. Every integrand
//! is a monomial in coordinates that are never negative (the origin is the solid's box's
//! corner), so each integral lies between the proved-inside cells' sum and that plus the
//! boundary's.

use glam::{DVec3, Vec3A};
use rayon::prelude::*;

use super::moments::Moments;

/// What the integration proved.
#[derive(Clone, Debug, PartialEq)]
pub struct Integrated {
    /// The integrals over what was proved inside: every integral's lower end.
    pub inside: Moments,
    /// The integrals over what was left unproved: each integral's upper end is
    /// `inside + boundary`.
    pub boundary: Moments,
    /// The box of what was proved inside (its corners), if anything was.
    pub inner: Option<(DVec3, DVec3)>,
    /// The box of everything not proved outside, if anything.
    pub outer: Option<(DVec3, DVec3)>,
    /// Cells evaluated.
    pub cells: u64,
    /// The half-side of the finest cells.
    pub finest: f64,
    /// Whether the tolerance was met (else the budget ran out first).
    pub met: bool,
}

/// A cell of the current level: its centre and the bound there.
#[derive(Clone, Copy)]
struct Cell {
    c: [f32; 3],
    f: f32,
}

/// What one chunk of a level found.
#[derive(Default)]
struct Found {
    inside: Moments,
    boundary: Vec<Cell>,
    inner: Option<(DVec3, DVec3)>,
}

fn grow(b: &mut Option<(DVec3, DVec3)>, lo: DVec3, hi: DVec3) {
    *b = Some(match *b {
        Some((a, z)) => (a.min(lo), z.max(hi)),
        None => (lo, hi),
    });
}

fn join(a: Option<(DVec3, DVec3)>, b: Option<(DVec3, DVec3)>) -> Option<(DVec3, DVec3)> {
    match (a, b) {
        (Some(x), Some(y)) => Some((x.0.min(y.0), x.1.max(y.1))),
        (x, None) | (None, x) => x,
    }
}

/// Integrates the solid `f < 0` inside the cube `[0, side]³` (which must hold all of it),
/// refining until the boundary's volume is at most `tolerance` times the volume's
/// midpoint, or until a level would evaluate more than `budget` cells or hold more than
/// `memory` bytes of open cells.
///
/// Long because it is one loop over the levels, each a parallel pass that splits and
/// proves the boundary, with the stopping rules between them.
pub fn integrate(f: &(dyn Fn(Vec3A) -> f32 + Sync), side: f64, tolerance: f64, budget: u64, memory: u64) -> Integrated {
    // f32 rounding of the bound and of the cell centres, with room to spare: a cell is
    // proved only past its circumradius plus this.
    let margin = (side * 4e-6) as f32;
    let classify = |c: DVec3, h: f64, found: &mut Found| {
        let p = Vec3A::new(c.x as f32, c.y as f32, c.z as f32);
        let d = f(p);
        let r = (h * 3f64.sqrt()) as f32 + margin;
        if d < -r {
            found.inside.add(&Moments::cube(c, h));
            grow(&mut found.inner, c - h, c + h);
        } else if d.is_nan() || d <= r {
            // Unproved (NaN included: a cell the bound cannot speak for stays open).
            found.boundary.push(Cell { c: [p.x, p.y, p.z], f: d });
        }
    };
    // A first grid of 16³ cells.
    let mut h = side / 32.0;
    let mut cells: u64 = 16 * 16 * 16;
    let first: Vec<Found> = (0..16u32)
        .into_par_iter()
        .map(|i| {
            let mut found = Found::default();
            for j in 0..16u32 {
                for k in 0..16u32 {
                    let c = DVec3::new(f64::from(i), f64::from(j), f64::from(k)) * (2.0 * h) + h;
                    classify(c, h, &mut found);
                }
            }
            found
        })
        .collect();
    let mut inside = Moments::default();
    let mut inner = None;
    let mut boundary = Vec::new();
    for found in first {
        inside.add(&found.inside);
        inner = join(inner, found.inner);
        boundary.extend(found.boundary);
    }
    let met = loop {
        let open = boundary.len() as f64 * 8.0 * h * h * h;
        let proved = inside.volume();
        if open <= tolerance * (proved + 0.5 * open) {
            break true;
        }
        let next = boundary.len() as u64 * 8;
        // f32 centres stop telling cells apart long before this.
        // A level's open cells are at most all its cells, each held with its bound.
        let bytes = next * std::mem::size_of::<Cell>() as u64;
        if cells + next > budget || bytes > memory || h < side * 1e-6 {
            break false;
        }
        cells += next;
        let half = h / 2.0;
        let found: Vec<Found> = boundary
            .par_chunks(1024)
            .map(|chunk| {
                let mut found = Found { boundary: Vec::with_capacity(chunk.len() * 4), ..Found::default() };
                for cell in chunk {
                    let c = DVec3::new(f64::from(cell.c[0]), f64::from(cell.c[1]), f64::from(cell.c[2]));
                    for k in 0..8 {
                        let o = DVec3::new(
                            if k & 1 == 0 { -half } else { half },
                            if k & 2 == 0 { -half } else { half },
                            if k & 4 == 0 { -half } else { half },
                        );
                        classify(c + o, half, &mut found);
                    }
                }
                found
            })
            .collect();
        boundary = Vec::with_capacity(found.iter().map(|f| f.boundary.len()).sum());
        for f in found {
            inside.add(&f.inside);
            inner = join(inner, f.inner);
            boundary.extend(f.boundary);
        }
        h = half;
    };
    // Inside a boundary cell, the cube inscribed in the ball of radius |f| about its
    // centre is proved too: inside where f < 0, outside where f > 0.
    let mut open = Moments::default();
    let mut outer = inner;
    for cell in &boundary {
        let c = DVec3::new(f64::from(cell.c[0]), f64::from(cell.c[1]), f64::from(cell.c[2]));
        let whole = Moments::cube(c, h);
        grow(&mut outer, c - h, c + h);
        // (`f64::min` would take `h` over a NaN: the test comes first.)
        let q = (f64::from(cell.f.abs()) - f64::from(margin)) / 3f64.sqrt();
        if q.is_nan() || q <= 0.0 {
            open.add(&whole);
            continue;
        }
        let q = q.min(h);
        let sure = Moments::cube(c, q);
        if cell.f < 0.0 {
            inside.add(&sure);
            grow(&mut inner, c - q, c + q);
        }
        open.add(&whole.minus(&sure));
    }
    Integrated { inside, boundary: open, inner, outer, cells, finest: h, met }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ball's integrals are proved to lie around its exact ones, the interval
    /// narrowing as the tolerance does.
    #[test]
    fn a_ball_lies_in_its_interval() {
        let c = Vec3A::splat(1.0);
        let ball = move |p: Vec3A| (p - c).length() - 0.8;
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.8f64.powi(3);
        let mut widths = Vec::new();
        for tol in [0.05, 0.01] {
            let r = integrate(&ball, 2.0, tol, 1 << 26, 1 << 30);
            let (lo, hi) = (r.inside.volume(), r.inside.volume() + r.boundary.volume());
            assert!(r.met && lo <= exact && exact <= hi, "{lo} {exact} {hi}");
            assert!((hi - lo) <= tol * hi, "{lo} {hi}");
            let cx = (r.inside.0[1] / hi, (r.inside.0[1] + r.boundary.0[1]) / lo);
            assert!(cx.0 <= 1.0 && 1.0 <= cx.1, "{cx:?}");
            let (inner, outer) = (r.inner.unwrap(), r.outer.unwrap());
            assert!(outer.0.x <= 0.2 + 1e-6 && 0.2 <= inner.0.x && inner.1.x <= 1.8 && 1.8 <= outer.1.x + 1e-6);
            widths.push(hi - lo);
        }
        assert!(widths[1] < widths[0] / 3.0, "{widths:?}");
    }

    /// A bound that cannot speak (NaN) proves nothing: the solid stays open.
    #[test]
    fn nan_proves_nothing() {
        let r = integrate(&|_| f32::NAN, 1.0, 0.01, 1 << 16, 1 << 30);
        assert!(!r.met && r.inside.volume() == 0.0 && (r.boundary.volume() - 1.0).abs() < 1e-9);
    }
}
