//! Parts an isosurface cannot see: a solid that fits between the grid's points leaves
//! no sign change, so dual contouring has nothing to mesh there. Every solid part of a
//! shape has known bounds, so the parts smaller than a few cells are checked against
//! the grid the mesher used, and the ones no grid point finds inside are reported
//! instead of vanishing without a word.

use glam::{DAffine3, DVec3, Vec3A};
use rayon::prelude::*;

use super::octree::Grid;
use super::samples::inside;
use crate::ir::{self, CsgOp, Shape, ShapeKind};
use crate::span::Span;

/// Parts at least this many cells across in every direction are not checked: a grid
/// point always lies well inside them.
const CHECKED_BELOW: f64 = 4.0;

/// A solid part of a shape: its bounds in the grid's frame, and where it was written.
#[derive(Clone, Copy, Debug)]
pub struct SolidPart {
    /// Lowest corner of its bounds.
    pub min: DVec3,
    /// Highest corner of its bounds.
    pub max: DVec3,
    /// The part in the source.
    pub span: Span,
}

impl SolidPart {
    /// Its smallest extent.
    pub fn across(&self) -> f64 {
        (self.max - self.min).min_element()
    }
}

/// The parts of `shape` (placed by `xf`) that add solid: the primitives of unions and
/// of the first operand of a subtraction; an intersection, a rounded or hollowed shape
/// counts as one part (its operands' sizes say little about its own), and a repetition
/// by its first copy (the others are the same size). Subtracted operands cut, so
/// losing one only fills a hole, and unbounded parts cannot be small.
pub fn solid_parts(shape: &Shape, xf: DAffine3, out: &mut Vec<SolidPart>) {
    let whole = |out: &mut Vec<SolidPart>| {
        if let Some(b) = ir::shape_bounds(shape) {
            let b = b.transform(&xf);
            out.push(SolidPart { min: b.min, max: b.max, span: shape.span });
        }
    };
    match &shape.kind {
        ShapeKind::Primitive(_)
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Field { .. }
        | ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. } => whole(out),
        ShapeKind::Csg { op: CsgOp::Intersect, .. } => whole(out),
        ShapeKind::Csg { op: CsgOp::Union, children, .. } => {
            for c in children {
                solid_parts(c, xf, out);
            }
        }
        ShapeKind::Csg { op: CsgOp::Subtract, children, .. } => {
            if let Some(first) = children.first() {
                solid_parts(first, xf, out);
            }
        }
        ShapeKind::Repeat { child, period, count } => {
            let first = -(DVec3::new(count[0] as f64, count[1] as f64, count[2] as f64) - 1.0) * 0.5 * *period;
            solid_parts(child, xf * DAffine3::from_translation(first), out);
        }
        ShapeKind::Transform { child, xf: inner } => solid_parts(child, xf * *inner, out),
        ShapeKind::Paint { child, .. } => solid_parts(child, xf, out),
    }
}

/// The parts under four cells across (`CHECKED_BELOW`) that no point of `grid` inside their
/// bounds finds inside the shape `f`, in the order given.
pub fn lost<'a>(parts: &'a [SolidPart], grid: &Grid, f: &(dyn Fn(Vec3A) -> f32 + Sync)) -> Vec<&'a SolidPart> {
    parts.par_iter().filter(|p| p.across() < CHECKED_BELOW * grid.cell && !seen(p, grid, f)).collect::<Vec<_>>()
}

/// Whether some grid point within the part's bounds is inside the shape.
fn seen(part: &SolidPart, grid: &Grid, f: &(dyn Fn(Vec3A) -> f32 + Sync)) -> bool {
    let first = ((part.min - grid.lo) / grid.cell).ceil().max(DVec3::ZERO);
    let last = ((part.max - grid.lo) / grid.cell).floor();
    if first.cmpgt(last).any() {
        return false;
    }
    let (a, b) = (first.as_u64vec3(), last.as_u64vec3());
    (a.x..=b.x).any(|i| (a.y..=b.y).any(|j| (a.z..=b.z).any(|k| inside(f(grid.point([i, j, k]).as_vec3a())))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere between the grid's points is lost; one that holds a point is seen; a
    /// large part is not checked.
    #[test]
    fn parts_between_grid_points_are_lost() {
        let grid = Grid { lo: DVec3::ZERO, cell: 1.0, levels: 4 };
        let sphere = |c: DVec3, r: f64| move |p: Vec3A| ((p.as_dvec3() - c).length() - r) as f32;
        let part = |c: DVec3, r: f64| SolidPart { min: c - r, max: c + r, span: Span::default() };
        let between = DVec3::splat(2.5);
        let f = sphere(between, 0.3);
        assert_eq!(lost(&[part(between, 0.3)], &grid, &f).len(), 1);
        let on = DVec3::new(2.0, 2.9, 3.1);
        let f = sphere(on, 0.3);
        assert!(lost(&[part(on, 0.3)], &grid, &f).is_empty());
        let big = |p: Vec3A| p.length() - 100.0;
        assert!(lost(&[part(DVec3::ZERO, 3.0)], &grid, &big).is_empty());
    }
}
