//! A polyhedron holding a field's solid, from interval arithmetic: for each of 26
//! directions (the cube's faces, edges and corners), the farthest the solid can reach
//! that way, by branch and bound over boxes whose interval of the body is above zero
//! (no point of the solid in them). Rays are clipped to it before the march
//! (`geom::hull`), so a ray missing the polyhedron costs no step and one entering it
//! starts near the surface, not at the corner of the field's bounds.

use std::collections::BinaryHeap;

use glam::DVec3;
use rayon::prelude::*;

use super::interval::Interval;
use super::lipschitz::Cell;
use super::tape::{Distances, Tape};
use crate::geom::DAabb;

/// Interval evaluations one direction may spend.
const BUDGET: usize = 256;

/// The largest `n·p` over the box `lo..hi`.
fn reach(n: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    n.dot(DVec3::select(n.cmpge(DVec3::ZERO), hi, lo))
}

/// Whether a box within `b` holds no point where the body is at most `level`, by
/// interval arithmetic. A box is ruled out only where the body is clearly above the
/// level: the march runs it in f32.
fn ruled_out<'a>(
    tape: &'a Tape,
    b: DAabb,
    level: f64,
    dist: &'a (dyn Distances<Interval> + Sync),
) -> impl Fn(DVec3, DVec3) -> bool + Sync + 'a {
    let slack = 1e-6 * (1.0 + b.min.abs().max(b.max.abs()).max_element());
    move |lo: DVec3, hi: DVec3| {
        let at = [0, 1, 2].map(|i| Interval::new(lo[i], hi[i]));
        tape.eval::<Interval>(&at, dist).lo > level + slack
    }
}

/// Planes `n·p ≤ offset` (unit `n`) holding where the body is at most `level` within
/// `b`, for the directions where that is nearer than `b`'s own face; `None` when no
/// point of `b` can be in the solid. Only an upper bound of each reach is taken (the
/// largest reach of the boxes not ruled out), so the planes hold the solid whatever the
/// budget.
pub fn support_planes(
    tape: &Tape,
    b: DAabb,
    level: f64,
    dist: &(dyn Distances<Interval> + Sync),
) -> Option<Vec<(DVec3, f64)>> {
    let tol = (b.max - b.min).length() / 256.0;
    let empty = ruled_out(tape, b, level, dist);
    if empty(b.min, b.max) {
        return None;
    }
    // The cube's 26 directions, searched in parallel.
    let dirs: Vec<DVec3> = (0..27)
        .filter_map(|i| {
            DVec3::new(f64::from(i % 3) - 1.0, f64::from(i / 3 % 3) - 1.0, f64::from(i / 9) - 1.0).try_normalize()
        })
        .collect();
    let offsets: Option<Vec<(DVec3, f64)>> =
        dirs.par_iter().map(|&n| Some((n, farthest(n, b, tol, &empty)?))).collect();
    let planes = offsets?.into_iter().filter(|&(n, o)| o < reach(n, b.min, b.max) - tol).collect();
    Some(planes)
}

/// Interval evaluations the ball's search ([`support_radius`]) spends in each eighth
/// of the box. Over a round solid the bound closes in only as the boxes across the
/// whole surface shrink: a ball of radius 0.4 in its box is bounded by 0.448, 0.432 and
/// 0.423 at 512, 1024 and 2048 per eighth, against the box's 0.69 (unit test
/// `support_radius_holds_the_solid_and_is_tight`). 1024 is as fast to trace as 2048
/// at half the lowering (`benches/scenes/field-spheres-64.scn`; docs/performance.md,
/// "Measurements behind the code").
const RADIAL_BUDGET: usize = 1024;

/// The radius of a ball about `centre` holding where the body is at most `level`
/// within `b`, from interval arithmetic as for [`support_planes`]: the farthest from
/// `centre` that a box not ruled out reaches, each eighth of `b` searched on its own
/// (in parallel). `None` when no point of `b` can be in the solid.
pub fn support_radius(
    tape: &Tape,
    b: DAabb,
    level: f64,
    centre: DVec3,
    dist: &(dyn Distances<Interval> + Sync),
) -> Option<f64> {
    let tol = (b.max - b.min).length() / 1024.0;
    let empty = ruled_out(tape, b, level, dist);
    let far = |lo: DVec3, hi: DVec3| (lo - centre).abs().max((hi - centre).abs()).length();
    let near = |lo: DVec3, hi: DVec3| (lo - centre).max(centre - hi).max(DVec3::ZERO).length();
    let mid = centre.clamp(b.min, b.max);
    let eighths: Vec<DAabb> = (0..8)
        .map(|i| {
            let pick = |a: usize, bit: u32| if i >> bit & 1 == 0 { (b.min[a], mid[a]) } else { (mid[a], b.max[a]) };
            let [(x0, x1), (y0, y1), (z0, z1)] = [pick(0, 0), pick(1, 1), pick(2, 2)];
            DAabb { min: DVec3::new(x0, y0, z0), max: DVec3::new(x1, y1, z1) }
        })
        .filter(|e| e.min.cmplt(e.max).all())
        .collect();
    let found: Vec<f64> =
        eighths.par_iter().filter_map(|&e| search(e, tol, RADIAL_BUDGET, &far, &near, &empty)).collect();
    found.into_iter().reduce(f64::max)
}

/// An upper bound of the largest `n·p` over the boxes within `b` not ruled `empty`, to
/// within `tol` or the budget; `None` if every box is.
fn farthest(n: DVec3, b: DAabb, tol: f64, empty: &(dyn Fn(DVec3, DVec3) -> bool + Sync)) -> Option<f64> {
    search(b, tol, BUDGET, &|lo, hi| reach(n, lo, hi), &|lo, hi| -reach(-n, lo, hi), empty)
}

/// Branch and bound: an upper bound of the largest `far` of the boxes within `b` not
/// ruled `empty`, to within `tol` (a box whose `far` and `near` are that close) or
/// `budget` evaluations; `None` if every box is.
fn search(
    b: DAabb,
    tol: f64,
    budget: usize,
    far: &(dyn Fn(DVec3, DVec3) -> f64 + Sync),
    near: &(dyn Fn(DVec3, DVec3) -> f64 + Sync),
    empty: &(dyn Fn(DVec3, DVec3) -> bool + Sync),
) -> Option<f64> {
    let mut heap = BinaryHeap::from([Cell { bound: far(b.min, b.max), lo: b.min, hi: b.max }]);
    let mut spent = 0;
    while let Some(cell) = heap.pop() {
        let extent = cell.bound - near(cell.lo, cell.hi);
        if spent >= budget || extent <= tol {
            // Every box left reaches no farther than this one.
            return Some(cell.bound);
        }
        spent += 1;
        if empty(cell.lo, cell.hi) {
            continue;
        }
        let axis = (cell.hi - cell.lo).max_position();
        let mid = 0.5 * (cell.lo[axis] + cell.hi[axis]);
        let (mut upper, mut lower) = (cell.hi, cell.lo);
        upper[axis] = mid;
        lower[axis] = mid;
        for (lo, hi) in [(cell.lo, upper), (lower, cell.hi)] {
            heap.push(Cell { bound: far(lo, hi), lo, hi });
        }
    }
    None
}
