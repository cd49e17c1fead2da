//! What the mesher has learnt of a field: its value at grid points and where the surface
//! crosses grid edges, each found once and shared by every cell that asks — a cell's
//! test, its children's, its neighbours' of other sizes, and every refinement round.
//!
//! A point's value always comes from the distance bound (never from the closure that
//! also gives the gradient, whose last bits may differ): every cell reads one sign for
//! it, which is what keeps neighbouring cells' sheets consistent, and the same one
//! whichever thread asked first.

use std::collections::HashMap;
use std::sync::Mutex;

use foldhash::fast::FixedState;
use glam::{DVec3, Vec3A};

use super::octree::{key, Grid};
use crate::sdf::Surf;

/// Shards of each table: with two to a few dozen threads, a lock is rarely contended.
const SHARDS: usize = 64;

/// The field an isosurface is made of: its distance bound, and the same with its
/// gradient (for the normals at crossings).
#[derive(Clone, Copy)]
pub struct IsoField<'a> {
    /// The distance bound.
    pub dist: &'a (dyn Fn(Vec3A) -> f32 + Sync),
    /// The bound with its gradient.
    pub surf: &'a (dyn Fn(Vec3A) -> Surf + Sync),
}

impl IsoField<'_> {
    /// The bound at `p`.
    pub fn at(&self, p: DVec3) -> f64 {
        f64::from((self.dist)(p.as_vec3a()))
    }

    /// The unit normal at `p` (the gradient's direction); `None` at a flat spot.
    pub fn normal(&self, p: DVec3) -> Option<DVec3> {
        let g = (self.surf)(p.as_vec3a()).g.as_dvec3();
        g.try_normalize()
    }
}

/// A grid edge: the key of its lower end (finest-grid coordinates), its axis and its
/// level (it is `2^level` finest cells long).
pub type EdgeId = (u64, u8, u8);

/// Where the surface crosses a grid edge and its normal there.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    /// The crossing point.
    pub point: DVec3,
    /// The surface's unit normal there.
    pub normal: DVec3,
}

/// A table split in shards, each behind its own lock.
struct Sharded<K, V> {
    shards: Vec<Mutex<HashMap<K, V, FixedState>>>,
}

impl<K: std::hash::Hash + Eq + Copy, V: Copy> Sharded<K, V> {
    fn new() -> Self {
        Sharded { shards: (0..SHARDS).map(|_| Mutex::new(HashMap::with_hasher(FixedState::default()))).collect() }
    }

    fn shard(&self, k: &K) -> &Mutex<HashMap<K, V, FixedState>> {
        use std::hash::BuildHasher;
        let h = FixedState::with_seed(0x5eed).hash_one(k);
        &self.shards[(h >> 58) as usize % SHARDS]
    }

    /// The value for `k`, made by `make` (outside the lock) when there is none yet. Two
    /// threads may both make it; both make the same value.
    fn get_or(&self, k: K, make: impl FnOnce() -> V) -> V {
        let shard = self.shard(&k);
        if let Some(v) = lock(shard).get(&k) {
            return *v;
        }
        let v = make();
        *lock(shard).entry(k).or_insert(v)
    }

    fn len(&self) -> usize {
        self.shards.iter().map(|s| lock(s).len()).sum()
    }
}

/// A shard's table; a panic elsewhere while it was held leaves nothing half-written in it
/// (an insert either happened or did not), so a poisoned lock is taken as it is.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Bytes one table entry takes, its share of the table's spare room included.
pub const ENTRY_BYTES: u64 = 64;

/// The values and crossings of one isosurface's field on its grid.
pub struct Samples<'a> {
    field: IsoField<'a>,
    grid: Grid,
    values: Sharded<u64, f32>,
    crossings: Sharded<EdgeId, Crossing>,
    /// Whether crossings are kept: only cells' tests and later rounds ask for one twice.
    keep_crossings: bool,
}

impl<'a> Samples<'a> {
    /// Nothing known yet of `field` on `grid`; crossings are kept for whoever asks again
    /// when `keep_crossings` says so.
    pub fn new(field: IsoField<'a>, grid: Grid, keep_crossings: bool) -> Samples<'a> {
        Samples { field, grid, values: Sharded::new(), crossings: Sharded::new(), keep_crossings }
    }

    /// The field.
    pub fn field(&self) -> IsoField<'a> {
        self.field
    }

    /// The value at the grid point at finest-grid coordinates `c`, kept for whoever asks
    /// next.
    pub fn value(&self, c: [u32; 3]) -> f32 {
        self.values.get_or(key(c.map(u64::from)), || self.evaluate(c))
    }

    /// The value at the grid point at finest-grid coordinates `c`, not kept: for a point
    /// only one cell asks for (the same value [`value`](Self::value) gives, as the field is
    /// evaluated the same way at the same point).
    pub fn evaluate(&self, c: [u32; 3]) -> f32 {
        (self.field.dist)(self.point(c).as_vec3a())
    }

    /// The grid point at finest-grid coordinates `c`.
    pub fn point(&self, c: [u32; 3]) -> DVec3 {
        self.grid.point(c.map(u64::from))
    }

    /// The side of a finest cell.
    pub fn cell(&self) -> f64 {
        self.grid.cell
    }

    /// Where the surface crosses the edge of `2^level` finest cells along `axis` from
    /// `start`, whose end values `ends` have opposite signs.
    pub fn crossing(&self, start: [u32; 3], axis: usize, level: u32, ends: [f32; 2]) -> Crossing {
        let make = || {
            let mut end = start;
            end[axis] += 1 << level;
            crossing(self.field, self.point(start), self.point(end), ends[0], ends[1], self.grid.cell)
        };
        if !self.keep_crossings {
            return make();
        }
        self.crossings.get_or((key(start.map(u64::from)), axis as u8, level as u8), make)
    }

    /// Bytes the tables hold now.
    pub fn bytes(&self) -> u64 {
        (self.values.len() + self.crossings.len()) as u64 * ENTRY_BYTES
    }
}

/// Where the surface crosses the segment `p0`–`p1` whose ends have the values `f0` and
/// `f1` of opposite signs, by false position (Illinois variant, until the value is within
/// a thousandth of a finest cell `cell` of zero: along an edge a distance field is
/// nearly linear and that takes a step or two, more where the edge passes a kink of a CSG
/// field), and the unit normal there (the edge's own direction, outward, at a flat spot).
pub fn crossing(field: IsoField, p0: DVec3, p1: DVec3, f0: f32, f1: f32, cell: f64) -> Crossing {
    let at = |t: f64| field.at(p0 + (p1 - p0) * t);
    let (mut a, mut fa) = (0.0, f64::from(f0));
    let (mut b, mut fb) = (1.0, f64::from(f1));
    let mut side = 0;
    for _ in 0..12 {
        let t = (a - fa * (b - a) / (fb - fa)).clamp(a, b);
        let ft = at(t);
        if ft.abs() < 1e-3 * cell || !ft.is_finite() {
            a = t;
            b = t;
            break;
        }
        if (ft < 0.0) == (fa < 0.0) {
            (a, fa) = (t, ft);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = (t, ft);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    let point = p0 + (p1 - p0) * ((a + b) * 0.5);
    let along = (p1 - p0).normalize() * if f0 < 0.0 { 1.0 } else { -1.0 };
    Crossing { point, normal: field.normal(point).unwrap_or(along) }
}

/// Whether a value is inside the shape. NaN counts as outside.
pub(super) fn inside(v: f32) -> bool {
    v < 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere() -> (impl Fn(Vec3A) -> f32 + Sync, impl Fn(Vec3A) -> Surf + Sync) {
        (|p: Vec3A| p.length() - 1.0, |p: Vec3A| Surf { d: p.length() - 1.0, g: p.normalize_or_zero(), mat: 0 })
    }

    /// A crossing lies on the surface with the surface's normal, and the tables hand back
    /// what they made.
    #[test]
    fn crossings_are_on_the_surface_and_kept() {
        let (dist, surf) = sphere();
        let grid = Grid::new(DVec3::splat(-1.5), DVec3::splat(1.5), 0.1).unwrap();
        let samples = Samples::new(IsoField { dist: &dist, surf: &surf }, grid, true);
        // A grid edge along x through the sphere's surface.
        let y = ((1.0 - grid.lo.y) / grid.cell).floor() as u32 - 3;
        let start = [((0.5 - grid.lo.x) / grid.cell) as u32, y, ((0.0 - grid.lo.z) / grid.cell) as u32];
        let mut level = 0;
        while samples.value(start).signum() == samples.value([start[0] + (1 << level), start[1], start[2]]).signum() {
            level += 1;
        }
        let end = [start[0] + (1 << level), start[1], start[2]];
        let ends = [samples.value(start), samples.value(end)];
        let x = samples.crossing(start, 0, level, ends);
        assert!((x.point.length() - 1.0).abs() < 1e-4, "{}", x.point);
        assert!((x.normal - x.point.normalize()).length() < 1e-4);
        let again = samples.crossing(start, 0, level, ends);
        assert_eq!(again.point, x.point);
        assert!(samples.bytes() > 0);
    }
}
