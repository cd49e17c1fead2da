//! The region a 2D profile covers, kept beside its distance so that an extrusion of it
//! can be meshed from its outlines: polygons and circles (moved, turned and scaled) and
//! their sharp unions, intersections and differences. At lowering the circles become
//! polygons of a detail's segments, the booleans are taken on the polygons (iOverlay,
//! the engine behind the `geo` crate's, robust where edges meet or overlap), and each
//! resulting outline with its holes is triangulated (iTriangle) into the prism's caps.

use std::sync::Arc;

use glam::DVec2;
use i_triangle::float::triangulatable::Triangulatable;
use i_triangle::i_overlay::core::fill_rule::FillRule;
use i_triangle::i_overlay::core::overlay_rule::OverlayRule;
use i_triangle::i_overlay::float::simplify::SimplifyShape;
use i_triangle::i_overlay::float::single::SingleFloatOverlay;

use super::outline::{Outline, Seg};
use super::TriMesh;

/// How a region's parts combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    /// Covered by any part.
    Union,
    /// Covered by every part.
    Intersect,
    /// Covered by the first part and by none of the others.
    Subtract,
}

/// A 2D region of `[u, v]` points.
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    /// A simple polygon's inside, corners in order (either winding).
    Polygon(Vec<DVec2>),
    /// A disc.
    Circle {
        /// Its centre.
        centre: DVec2,
        /// Its radius.
        r: f64,
    },
    /// Sharp CSG of regions.
    Csg(Combine, Vec<Region>),
    /// Closed curves filled by the non-zero rule (`text`'s glyphs).
    Outline(Arc<Outline>),
}

/// Polygons (outlines, each followed by its holes) in iOverlay's form.
type Shapes = Vec<Vec<Vec<[f64; 2]>>>;

/// Coordinates beyond which a region is not meshed from its outlines (the overlay maps
/// them to integers over the region's extent, and a far-flung one would cost precision).
const MAX_COORDINATE: f64 = 1e9;

impl Region {
    /// The region moved by `f`, a rigid motion or a uniform scale by `k` (so a circle's
    /// radius scales by `k`).
    pub fn moved(&self, f: &impl Fn(DVec2) -> DVec2, k: f64) -> Region {
        match self {
            Region::Polygon(c) => Region::Polygon(c.iter().map(|p| f(*p)).collect()),
            Region::Circle { centre, r } => Region::Circle { centre: f(*centre), r: r * k },
            Region::Csg(op, parts) => Region::Csg(*op, parts.iter().map(|p| p.moved(f, k)).collect()),
            Region::Outline(o) => Region::Outline(Arc::new(o.moved(f))),
        }
    }

    /// The largest circle's radius, 0 when the region is all polygons (its outline is
    /// then exact at any detail).
    pub fn largest_radius(&self) -> f64 {
        match self {
            Region::Polygon(_) => 0.0,
            Region::Circle { r, .. } => *r,
            Region::Csg(_, parts) => parts.iter().map(Region::largest_radius).fold(0.0, f64::max),
            Region::Outline(o) => o.equivalent_radius(),
        }
    }

    /// Whether every coordinate is within reach of the overlay's integers.
    fn in_reach(&self) -> bool {
        match self {
            Region::Polygon(c) => c.iter().all(|p| p.abs().max_element() < MAX_COORDINATE),
            Region::Circle { centre, r } => centre.abs().max_element() + r < MAX_COORDINATE,
            Region::Csg(_, parts) => parts.iter().all(Region::in_reach),
            Region::Outline(o) => o.min.abs().max(o.max.abs()).max_element() < MAX_COORDINATE,
        }
    }

    /// The region as polygons with holes, each circle inscribed with `sides(r)` sides.
    fn shapes(&self, sides: &dyn Fn(f64) -> u32) -> Shapes {
        match self {
            Region::Polygon(c) => vec![vec![c.iter().map(|p| p.to_array()).collect()]],
            Region::Circle { centre, r } => {
                let n = sides(*r).max(3);
                let ring = (0..n).map(|i| {
                    let (sin, cos) = (std::f64::consts::TAU * f64::from(i) / f64::from(n)).sin_cos();
                    (*centre + DVec2::new(cos, sin) * *r).to_array()
                });
                vec![vec![ring.collect()]]
            }
            Region::Csg(op, parts) => {
                let rule = match op {
                    Combine::Union => OverlayRule::Union,
                    Combine::Intersect => OverlayRule::Intersect,
                    Combine::Subtract => OverlayRule::Difference,
                };
                let mut parts = parts.iter().map(|p| p.shapes(sides));
                let first = parts.next().unwrap_or_default();
                parts.fold(first, |acc, p| acc.overlay(&p, rule, FillRule::NonZero))
            }
            // Each curve's share of a circle's sides by how far it turns (`sides` of the
            // outline's equivalent radius), the contours resolved into outlines with holes.
            Region::Outline(o) => o.polygons(sides(o.equivalent_radius())).simplify_shape(FillRule::NonZero),
        }
    }
}

impl Region {
    /// Points whose convex hull holds the region: polygons' corners, and the corners of
    /// an octagon around each circle (a subtraction's and an intersection's first part's).
    fn hull_points(&self, out: &mut Vec<DVec2>) {
        match self {
            Region::Polygon(c) => out.extend(c),
            Region::Circle { centre, r } => {
                let reach = r / (std::f64::consts::PI / 8.0).cos();
                out.extend((0..8).map(|i| {
                    let (sin, cos) = (std::f64::consts::FRAC_PI_4 * (f64::from(i) + 0.5)).sin_cos();
                    *centre + DVec2::new(cos, sin) * reach
                }));
            }
            Region::Csg(Combine::Union, parts) => parts.iter().for_each(|p| p.hull_points(out)),
            // A quadratic lies in the triangle of its control points.
            Region::Outline(o) => {
                for (_, contour) in o.contours() {
                    for seg in contour {
                        match *seg {
                            Seg::Line(a, b) => out.extend([a, b]),
                            Seg::Quad(a, b, c) => out.extend([a, b, c]),
                        }
                    }
                }
            }
            Region::Csg(_, parts) => {
                if let Some(first) = parts.first() {
                    first.hull_points(out);
                }
            }
        }
    }

    /// The convex hull's edges as lines `n·p ≤ d` (unit `n`), counter-clockwise: they
    /// hold the region, exactly when it is a convex polygon.
    pub fn hull_lines(&self) -> Vec<(DVec2, f64)> {
        let mut pts = Vec::new();
        self.hull_points(&mut pts);
        convex_lines(pts)
    }

    /// Lines `n·[r, v] ≤ d` with `n.x ≥ 0` holding the region revolved about the `v`
    /// axis (its part at `u ≥ 0`): the edges on the right of the hull of the region and
    /// its mirror image, which is symmetric, so `r = |u|` meets them exactly where `u` does.
    pub fn revolved_hull_lines(&self) -> Vec<(DVec2, f64)> {
        let mut pts = Vec::new();
        self.hull_points(&mut pts);
        let mirrored = pts.iter().flat_map(|p| [DVec2::new(p.x.abs(), p.y), DVec2::new(-p.x.abs(), p.y)]).collect();
        convex_lines(mirrored).into_iter().filter(|(n, _)| n.x >= 0.0).collect()
    }
}

impl Region {
    /// Whether the region is one convex polygon, so that its extrusion is exactly the
    /// prism of [`hull_lines`](Self::hull_lines): its hull has no more area than it has.
    pub fn is_convex_polygon(&self) -> bool {
        match self {
            Region::Polygon(c) => is_convex_union(c.clone(), area(c)),
            Region::Circle { .. } | Region::Csg(..) | Region::Outline(_) => false,
        }
    }

    /// Whether the region revolved about the `v` axis is exactly what
    /// [`revolved_hull_lines`](Self::revolved_hull_lines) revolve: one polygon at `u ≥ 0`
    /// (so it and its mirror image overlap nowhere) whose union with its mirror image is
    /// convex, the hull of the two having no more area than both.
    pub fn revolves_convex(&self) -> bool {
        match self {
            Region::Polygon(c) if c.iter().all(|p| p.x >= 0.0) => {
                let both = c.iter().flat_map(|p| [*p, DVec2::new(-p.x, p.y)]).collect();
                is_convex_union(both, 2.0 * area(c))
            }
            Region::Polygon(_) | Region::Circle { .. } | Region::Csg(..) | Region::Outline(_) => false,
        }
    }
}

/// A simple polygon's area, either winding.
fn area(c: &[DVec2]) -> f64 {
    let twice: f64 = (0..c.len()).map(|i| c[i].perp_dot(c[(i + 1) % c.len()])).sum();
    0.5 * twice.abs()
}

/// Whether points covering `area` between them (simple polygons overlapping nowhere)
/// cover their convex hull: its area is theirs, to rounding.
fn is_convex_union(pts: Vec<DVec2>, area_covered: f64) -> bool {
    let hull = super::polygon::convex_hull(pts);
    area_covered > 0.0 && area(&hull) <= area_covered * (1.0 + 1e-9)
}

/// The edges of the convex hull of `pts` as lines `n·p ≤ d` (unit `n`),
/// counter-clockwise; none when the points span no area.
fn convex_lines(pts: Vec<DVec2>) -> Vec<(DVec2, f64)> {
    let hull = super::polygon::convex_hull(pts);
    // `convex_hull` hands back fewer than three points as they are: two would make a
    // slab of no width.
    if hull.len() < 3 {
        return Vec::new();
    }
    (0..hull.len())
        .filter_map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            // The outward normal of a counter-clockwise edge is its direction turned right.
            let n = DVec2::new(b.y - a.y, a.x - b.x).try_normalize()?;
            Some((n, n.dot(a)))
        })
        .collect()
}

/// The prism of `region` from `y = -half_height` to `half_height` (its `[u, v]` as `x`,
/// `z`), circles with `segments` sides: closed and wound outward, or `None` when the
/// region comes out empty or too far out to mesh this way.
pub fn extrusion(region: &Region, half_height: f64, segments: u32) -> Option<TriMesh> {
    if !region.in_reach() {
        return None;
    }
    let mut points = Vec::new();
    let mut triangles = Vec::new();
    for shape in region.shapes(&|_| segments) {
        let t = shape.triangulate().to_triangulation::<u32>();
        let base = points.len() as u32;
        points.extend(t.points.iter().map(|p| DVec2::from_array(*p)));
        triangles.extend(t.indices.chunks_exact(3).map(|c| [c[0] + base, c[1] + base, c[2] + base]));
    }
    (!triangles.is_empty()).then(|| super::polygon::prism_of_caps(&points, &triangles, half_height))
}

/// The solid of `region` revolved about `y` in `segments` steps (its `[u, v]` the
/// radius and the height; a part at `u < 0` clipped, as the distance clips it), circles
/// with [`revolved_circle_sides`]: each outline revolved as a lathe, each hole's turned inside
/// out. `None` when the region comes out empty, too far out, or with an outline that
/// meets the axis other than along one edge or at one corner (`polygon::lathe_ok`).
pub fn revolution(region: &Region, segments: u32) -> Option<TriMesh> {
    if !region.in_reach() {
        return None;
    }
    let reach = {
        let mut pts = Vec::new();
        region.hull_points(&mut pts);
        pts.iter().fold(0.0f64, |m, p| m.max(p.x.abs()))
    };
    let shapes = region.shapes(&|r| revolved_circle_sides(segments, r, reach));
    let far = shapes.iter().flatten().flatten().fold(1.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs())) * 2.0;
    let half_plane = vec![vec![[0.0, -far], [far, -far], [far, far], [0.0, far]]];
    let clipped = shapes.overlay(&half_plane, OverlayRule::Intersect, FillRule::NonZero);
    let on_axis = far * SNAP_TO_AXIS;
    let mut out = TriMesh::default();
    for shape in clipped {
        for (k, contour) in shape.iter().enumerate() {
            let corners: Vec<DVec2> =
                contour.iter().map(|p| DVec2::new(if p[0] <= on_axis { 0.0 } else { p[0] }, p[1])).collect();
            if !super::polygon::lathe_ok(&corners) {
                return None;
            }
            let mut m = super::polygon::lathe(&corners, segments);
            // The first contour is the outline, the others its holes.
            if k > 0 {
                m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
            }
            out.append(m);
        }
    }
    (!out.triangles.is_empty()).then_some(out)
}

/// The sides of a circle of radius `r` in a profile revolved in `segments` steps, whose
/// farthest point is `reach` from the axis: as many as keep the circle's sagitta within
/// the revolution's at `reach` (`r/n² = reach/segments²`, so `segments·√(r/reach)`), as
/// a torus's tube has fewer sides than its ring; never more than `segments`.
pub fn revolved_circle_sides(segments: u32, r: f64, reach: f64) -> u32 {
    let n = (f64::from(segments) * (r / reach).sqrt()).ceil();
    if n.is_finite() {
        (n as u32).clamp(3, segments.max(3))
    } else {
        segments
    }
}

/// Corners this close to the axis, relative to the region's extent, are on it: the
/// overlay's integer grid leaves the clip's edge a rounding away from `u = 0`.
const SNAP_TO_AXIS: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(h: DVec2) -> Region {
        Region::Polygon(vec![-h, DVec2::new(h.x, -h.y), h, DVec2::new(-h.x, h.y)])
    }

    /// A plate with a round hole is closed and outward, holds the plate less the hole's
    /// polygon, and has a hole: no triangle covers the hole's centre.
    #[test]
    fn a_plate_with_a_hole_is_closed_and_holed() {
        let plate = Region::Csg(
            Combine::Subtract,
            vec![rect(DVec2::new(1.0, 0.7)), Region::Circle { centre: DVec2::new(0.2, 0.0), r: 0.3 }],
        );
        let n = 64;
        let m = extrusion(&plate, 0.1, n).expect("a plate");
        assert_eq!(m.open_edges(), (0, 0));
        let hole = 0.5 * f64::from(n) * 0.09 * (std::f64::consts::TAU / f64::from(n)).sin();
        let want = (2.0 * 1.4 - hole) * 0.2;
        assert!((m.signed_volume() - want).abs() < 1e-9, "{} not {want}", m.signed_volume());
        // Flat-faced but the hole: the plate's 4 corners and the hole's 64, twice.
        assert_eq!(m.positions.len(), 2 * (4 + 64));
    }

    /// Union, intersection and a ring (a disc less a smaller one) keep the areas the
    /// polygons have; two apart squares are two prisms; a region cut away wholly is none.
    #[test]
    fn booleans_keep_their_areas() {
        let a = rect(DVec2::splat(1.0));
        let b = rect(DVec2::splat(1.0)).moved(&|p| p + DVec2::new(1.0, 1.0), 1.0);
        let area = |r: &Region| extrusion(r, 0.5, 32).map_or(0.0, |m| m.signed_volume());
        assert!((area(&Region::Csg(Combine::Union, vec![a.clone(), b.clone()])) - 7.0).abs() < 1e-9);
        assert!((area(&Region::Csg(Combine::Intersect, vec![a.clone(), b.clone()])) - 1.0).abs() < 1e-9);
        let far = a.moved(&|p| p + DVec2::new(5.0, 0.0), 1.0);
        let two = extrusion(&Region::Csg(Combine::Union, vec![a.clone(), far]), 0.5, 32).expect("two");
        assert_eq!(two.open_edges(), (0, 0));
        assert!((two.signed_volume() - 8.0).abs() < 1e-9);
        let disc = |r| Region::Circle { centre: DVec2::ZERO, r };
        let ring = extrusion(&Region::Csg(Combine::Subtract, vec![disc(1.0), disc(0.5)]), 0.5, 48).expect("ring");
        assert_eq!(ring.open_edges(), (0, 0));
        let polygon_area = |r: f64| 0.5 * 48.0 * r * r * (std::f64::consts::TAU / 48.0).sin();
        let want = polygon_area(1.0) - polygon_area(0.5);
        // Within the overlay's integer grid (about 1e-9 of the extent) of the polygons'.
        assert!((ring.signed_volume() - want).abs() < 1e-8, "{} not {want}", ring.signed_volume());
        assert!(extrusion(&Region::Csg(Combine::Subtract, vec![rect(DVec2::splat(0.5)), a]), 0.5, 32).is_none());
    }

    /// A disc off the axis revolves into a closed torus, a disc on it into a closed
    /// ball (its left half clipped), a ring into a torus with a toroidal hole; each holds
    /// its polygon's volume by Pappus (area times the path of its centroid).
    #[test]
    fn revolved_regions_are_closed_and_hold_pappus_volumes() {
        let n = 48;
        let disc = |centre: DVec2, r: f64| Region::Circle { centre, r };
        let torus = revolution(&disc(DVec2::new(1.0, 0.2), 0.3), n).expect("a torus");
        assert_eq!(torus.open_edges(), (0, 0));
        // A circle has the sides that keep its sagitta within the revolution's.
        let area = |r: f64, reach: f64| {
            let k = revolved_circle_sides(n, r, reach);
            0.5 * f64::from(k) * r * r * (std::f64::consts::TAU / f64::from(k)).sin()
        };
        // The revolved polygon's path is itself a polygon of n sides: its centroid's
        // circle shrinks to the inscribed perimeter, n·sin(2π/n)/(2π) of it.
        let path = f64::from(n) * (std::f64::consts::TAU / f64::from(n)).sin() / std::f64::consts::TAU;
        let want = area(0.3, 1.3) * std::f64::consts::TAU * 1.0 * path;
        assert!((torus.signed_volume() - want).abs() < 1e-6 * want, "{} not {want}", torus.signed_volume());
        let ball = revolution(&disc(DVec2::ZERO, 0.5), n).expect("a ball");
        assert_eq!(ball.open_edges(), (0, 0));
        assert!((ball.signed_volume() - 4.0 / 3.0 * std::f64::consts::PI * 0.125).abs() < 0.02 * 0.52);
        let ring =
            Region::Csg(Combine::Subtract, vec![disc(DVec2::new(1.0, 0.0), 0.4), disc(DVec2::new(1.0, 0.0), 0.2)]);
        let hollow = revolution(&ring, n).expect("a hollow torus");
        assert_eq!(hollow.open_edges(), (0, 0));
        let want = (area(0.4, 1.4) - area(0.2, 1.4)) * std::f64::consts::TAU * path;
        assert!((hollow.signed_volume() - want).abs() < 1e-6 * want, "{} not {want}", hollow.signed_volume());
    }
}
