//! Measurement: each object's volume, centre of mass, bounding box and inertia tensor as
//! intervals proved from its distance bound ([`octree`]), beside the same figures and the
//! surface area of its mesh ([`moments`]).
//!
//! Intervals are guaranteed as far as the bound is: a field, warp or displacement whose
//! slope the scene *states* (`lipschitz = …`) is only as good as that statement, and the
//! result says so. Surface area has no interval: a distance bound says where the surface
//! may be, not how much it may fold there, so only the mesh estimates it.

pub mod moments;
pub mod octree;

use glam::{DAffine3, DVec3};

use crate::diag::Diagnostic;
use crate::export::Placement;
use crate::geom::axes::{from_file, Up};
use crate::ir::{self, Body, Scene, Shape, ShapeKind};
use crate::mesh::Detail;
use crate::source::Loader;
use crate::span::Span;
use moments::Moments;

/// An interval `[lo, hi]` a figure is proved to lie in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Bounds {
    fn new(lo: f64, hi: f64) -> Bounds {
        Bounds { lo, hi }
    }

    /// The midpoint.
    pub fn mid(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }

    /// The width relative to the midpoint's size (0 for a point at 0).
    pub fn relative_width(&self) -> f64 {
        let m = self.mid().abs();
        if m > 0.0 {
            (self.hi - self.lo) / m
        } else {
            0.0
        }
    }

    /// Whether `x` lies inside.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }
}

/// How to measure.
#[derive(Clone, Copy, Debug)]
pub struct MeasureOptions {
    /// The volume interval's width to reach, relative to the volume.
    pub tolerance: f64,
    /// Most cells the integrations may evaluate in all: each object and the total get an
    /// equal share.
    pub cells: u64,
    /// The mesh estimate's tessellation detail.
    pub detail: Detail,
    /// Most bytes the meshes may take, and the open cells of a proof.
    pub memory_limit: u64,
}

/// Cells an integration evaluates by default: about a second for a library body on two
/// cores (`scnc measure benches/nine/cone.scn`).
pub const DEFAULT_CELLS: u64 = 1 << 24;

/// The fewest cells an integration gets, however many objects share the budget.
pub const MIN_SHARE: u64 = 1 << 16;

/// Figures proved from the distance bound.
#[derive(Clone, Debug, PartialEq)]
pub struct Proved {
    /// The volume.
    pub volume: Bounds,
    /// The mass: the volume times the object's density.
    pub mass: Bounds,
    /// The centre of mass (uniform density).
    pub centre: [Bounds; 3],
    /// The bounding box's least corner, per axis.
    pub min: [Bounds; 3],
    /// Its greatest corner.
    pub max: [Bounds; 3],
    /// The inertia tensor about the centre of mass at the object's density, row by row.
    pub inertia: [[Bounds; 3]; 3],
    /// Whether the volume's interval is within the tolerance (else the cell budget ran out).
    pub met: bool,
    /// Whether the bound is one the scene states (a field's `lipschitz = …`): the
    /// intervals are then only as sure as that statement.
    pub stated: bool,
    /// Cells evaluated.
    pub cells: u64,
    /// The finest cells' side.
    pub cell: f64,
}

/// Figures of the object's mesh (exact for the polyhedron).
#[derive(Clone, Debug, PartialEq)]
pub struct Estimated {
    /// The volume.
    pub volume: f64,
    /// The mass: the volume times the density.
    pub mass: f64,
    /// The surface area.
    pub area: f64,
    /// The centre of mass.
    pub centre: DVec3,
    /// The bounding box's corners.
    pub min: DVec3,
    /// The greatest corner.
    pub max: DVec3,
    /// The inertia tensor about the centre of mass at the object's density.
    pub inertia: [[f64; 3]; 3],
    /// Triangles.
    pub triangles: usize,
}

/// One object measured, or the whole scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The object's name (`total` for the scene).
    pub name: String,
    /// Its `object` statement (none for the total).
    pub span: Option<Span>,
    /// Its materials' density (`material(density = …)`, 1 when none is given); `None`
    /// when its parts have different ones, and then its mass and inertia are at density 1.
    pub density: Option<f64>,
    /// From the distance bound: none for an explicit mesh (its mesh is exact) or an
    /// unbounded shape.
    pub proved: Option<Proved>,
    /// From the mesh: none for an unbounded shape.
    pub mesh: Option<Estimated>,
}

/// Measures every object of `scene` and, when it has more than one, the scene as one
/// solid (the union of its shapes; a sum where it has explicit meshes, which may overlap).
pub fn measure(scene: &Scene, opts: &MeasureOptions, loader: &dyn Loader) -> Result<Vec<Measured>, Diagnostic> {
    let meshes = mesh_estimates(scene, opts, loader)?;
    let integrations = scene.objects.len() as u64 + u64::from(scene.objects.len() > 1);
    let opts = &MeasureOptions { cells: (opts.cells / integrations.max(1)).max(MIN_SHARE), ..*opts };
    let mut out = Vec::with_capacity(scene.objects.len() + 1);
    for (object, mesh) in scene.objects.iter().zip(meshes) {
        let density = density_of(&object.geometry);
        let rho = density.unwrap_or(1.0);
        let proved = match &object.geometry {
            Body::Shape(shape) => ir::shape_bounds(shape).map(|b| prove(&[shape], b.min, b.max, opts).weighed(rho)),
            Body::Mesh(_) => None,
        };
        let mesh = mesh.map(|m| m.weighed(rho));
        out.push(Measured { name: object.name.clone(), span: Some(object.span), density, proved, mesh });
    }
    if scene.objects.len() > 1 {
        out.push(total(scene, &out, opts));
    }
    Ok(out)
}

/// The density every part of `geometry` has, or `None` when parts differ: a part's is
/// the innermost material's above it (1 where none is).
fn density_of(geometry: &Body) -> Option<f64> {
    fn leaves(shape: &Shape, above: f64, out: &mut Vec<f64>) {
        let here = match &shape.kind {
            ShapeKind::Paint { material, .. } => material.density,
            _ => above,
        };
        if shape.children().is_empty() {
            out.push(here);
        }
        shape.children().iter().for_each(|c| leaves(c, here, out));
    }
    let mut all = Vec::new();
    match geometry {
        Body::Shape(s) => leaves(s, 1.0, &mut all),
        Body::Mesh(m) => all.push(m.material.as_ref().map_or(1.0, |m| m.density)),
    }
    let first = *all.first()?;
    all.iter().all(|d| *d == first).then_some(first)
}

impl Proved {
    /// The figures at density `rho`: the mass and the inertia scale by it.
    fn weighed(mut self, rho: f64) -> Proved {
        self.mass = Bounds::new(self.volume.lo * rho, self.volume.hi * rho);
        for row in &mut self.inertia {
            for b in row {
                *b = Bounds::new(b.lo * rho, b.hi * rho);
            }
        }
        self
    }
}

impl Estimated {
    /// The figures at density `rho`: the mass and the inertia scale by it.
    fn weighed(mut self, rho: f64) -> Estimated {
        self.mass = self.volume * rho;
        self.inertia = self.inertia.map(|row| row.map(|x| x * rho));
        self
    }
}

/// The scene as one solid: the union of its shapes proved as one (when every object has
/// the same density), the meshes' moments summed weighted by their densities.
fn total(scene: &Scene, each: &[Measured], opts: &MeasureOptions) -> Measured {
    let densities: Option<Vec<f64>> = each.iter().map(|m| m.density).collect();
    let density = densities.as_ref().and_then(|d| d.iter().all(|x| *x == d[0]).then(|| d[0]));
    let shapes: Vec<&std::sync::Arc<Shape>> = scene
        .objects
        .iter()
        .filter_map(|o| match &o.geometry {
            Body::Shape(s) => Some(s),
            Body::Mesh(_) => None,
        })
        .collect();
    let boxes: Option<Vec<ir::DAabb>> = shapes.iter().map(|s| ir::shape_bounds(s)).collect();
    let proved = match (boxes, density) {
        (Some(b), Some(rho)) if shapes.len() == scene.objects.len() => {
            let lo = b.iter().fold(DVec3::INFINITY, |a, x| a.min(x.min));
            let hi = b.iter().fold(DVec3::NEG_INFINITY, |a, x| a.max(x.max));
            Some(prove(&shapes, lo, hi, opts).weighed(rho))
        }
        _ => None,
    };
    let estimates: Option<Vec<&Estimated>> = each.iter().map(|m| m.mesh.as_ref()).collect();
    let mesh = estimates.filter(|e| !e.is_empty() && densities.is_some()).map(|e| {
        let mut sum = Moments::default();
        let mut area = 0.0;
        for m in &e {
            sum.add(&from_figures(m));
            area += m.area;
        }
        let (min, max) =
            e.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, z), m| (a.min(m.min), z.max(m.max)));
        Estimated {
            volume: e.iter().map(|m| m.volume).sum(),
            mass: sum.volume(),
            area,
            centre: sum.centre(),
            min,
            max,
            inertia: sum.inertia(),
            triangles: e.iter().map(|m| m.triangles).sum(),
        }
    });
    Measured { name: "total".into(), span: None, density, proved, mesh }
}

/// The ten integrals of the mass back from a mesh's figures (about the origin), for
/// summing objects: their zeroth is the mass.
fn from_figures(m: &Estimated) -> Moments {
    let (v, c, i) = (m.mass, m.centre, m.inertia);
    // Second moments about the centre from the inertia tensor: C = tr(I)/2·E − I.
    let half = 0.5 * (i[0][0] + i[1][1] + i[2][2]);
    let cxx = half - i[0][0];
    let cyy = half - i[1][1];
    let czz = half - i[2][2];
    Moments([
        v,
        v * c.x,
        v * c.y,
        v * c.z,
        cxx + v * c.x * c.x,
        cyy + v * c.y * c.y,
        czz + v * c.z * c.z,
        -i[0][1] + v * c.x * c.y,
        -i[1][2] + v * c.y * c.z,
        -i[2][0] + v * c.z * c.x,
    ])
}

/// The union of `shapes`, inside the box `lo`–`hi`, proved.
fn prove(shapes: &[&std::sync::Arc<Shape>], lo: DVec3, hi: DVec3, opts: &MeasureOptions) -> Proved {
    // Coordinates from the box's least corner (a little below it, so no surface point
    // sits on the first cells' faces), where every monomial is non-negative.
    let side = (hi - lo).max_element().max(1e-9) * 1.01;
    let origin = lo - 0.005 * side;
    let xf = DAffine3::from_translation(-origin);
    let mut materials = crate::trace::MaterialTable::default();
    let mut builder = crate::sdf::Builder::new(&mut materials);
    let dists: Vec<crate::sdf::Sdf> =
        shapes.iter().map(|s| crate::sdf::SdfObject::new(s, xf, &mut builder).dist).collect();
    // The least of bounds is a bound of the union: outside, the distance to the union is
    // the least distance; inside one part, leaving the union means leaving that part.
    let f = move |p: glam::Vec3A| dists.iter().map(|d| d(p)).fold(f32::INFINITY, f32::min);
    let r = octree::integrate(&f, side, opts.tolerance, opts.cells, opts.memory_limit);
    let stated = shapes.iter().any(|s| stated_slope(s));
    let lo_m = r.inside.0;
    let hi_m: [f64; 10] = std::array::from_fn(|i| lo_m[i] + r.boundary.0[i]);
    let v = Bounds::new(lo_m[0], hi_m[0]);
    let centre = std::array::from_fn(|k| {
        if v.lo > 0.0 {
            Bounds::new(lo_m[1 + k] / v.hi + origin[k], hi_m[1 + k] / v.lo + origin[k])
        } else {
            let (a, z) = r.outer.unwrap_or((DVec3::ZERO, DVec3::splat(side)));
            Bounds::new(a[k] + origin[k], z[k] + origin[k])
        }
    });
    let m = |i: usize| Bounds::new(lo_m[i], hi_m[i]);
    let inertia = inertia_intervals(v, [m(1), m(2), m(3)], [m(4), m(5), m(6)], [m(7), m(8), m(9)]);
    // Each corner lies between the box of what was proved inside and the box of
    // everything not proved outside (none proved inside: no inner end).
    let shift = |b: Option<(DVec3, DVec3)>, none: f64| {
        b.map_or((DVec3::splat(none), DVec3::splat(-none)), |(a, z)| (a + origin, z + origin))
    };
    let (outer_lo, outer_hi) = shift(r.outer, f64::NAN);
    let (inner_lo, inner_hi) = shift(r.inner, f64::INFINITY);
    let min = std::array::from_fn(|k| Bounds::new(outer_lo[k], inner_lo[k]));
    let max = std::array::from_fn(|k| Bounds::new(inner_hi[k], outer_hi[k]));
    Proved { volume: v, mass: v, centre, min, max, inertia, met: r.met, stated, cells: r.cells, cell: 2.0 * r.finest }
}

/// The inertia tensor about the centre of mass from intervals of the volume, the first
/// moments and the second moments (squares, then xy, yz, zx), all of non-negative
/// integrands: `∫x_i x_j − M_i M_j / V` per pair, in interval arithmetic.
fn inertia_intervals(v: Bounds, m1: [Bounds; 3], sq: [Bounds; 3], cross: [Bounds; 3]) -> [[Bounds; 3]; 3] {
    let central = |s: Bounds, a: Bounds, b: Bounds| {
        let hi = if v.hi > 0.0 { s.hi - a.lo * b.lo / v.hi } else { s.hi };
        let lo = if v.lo > 0.0 { s.lo - a.hi * b.hi / v.lo } else { f64::NEG_INFINITY };
        Bounds::new(lo, hi)
    };
    let c = [central(sq[0], m1[0], m1[0]), central(sq[1], m1[1], m1[1]), central(sq[2], m1[2], m1[2])];
    let xy = central(cross[0], m1[0], m1[1]);
    let yz = central(cross[1], m1[1], m1[2]);
    let zx = central(cross[2], m1[2], m1[0]);
    let add = |a: Bounds, b: Bounds| Bounds::new(a.lo + b.lo, a.hi + b.hi);
    let neg = |a: Bounds| Bounds::new(-a.hi, -a.lo);
    [[add(c[1], c[2]), neg(xy), neg(zx)], [neg(xy), add(c[0], c[2]), neg(yz)], [neg(zx), neg(yz), add(c[0], c[1])]]
}

/// Whether the shape's bound rests on a slope the scene states rather than one the
/// checker proved.
fn stated_slope(shape: &Shape) -> bool {
    match &shape.kind {
        ShapeKind::Field { body, lipschitz, .. } => lipschitz.given || body.shapes().iter().any(|s| stated_slope(s)),
        ShapeKind::Warp { child, lipschitz, .. } => lipschitz.given || stated_slope(child),
        ShapeKind::Displace { child, lipschitz, .. } => lipschitz.given || stated_slope(child),
        _ => shape.children().iter().any(|s| stated_slope(s)),
    }
}

/// Each object's mesh figures, in scene order (none for an object that has no mesh).
fn mesh_estimates(
    scene: &Scene,
    opts: &MeasureOptions,
    loader: &dyn Loader,
) -> Result<Vec<Option<Estimated>>, Diagnostic> {
    let frame = Placement { up: Up::Y, scale: 1.0 };
    let export = crate::export::collect(scene, opts.detail, frame, opts.memory_limit, true, loader)?;
    Ok(scene
        .objects
        .iter()
        .map(|o| {
            let part = export.parts.iter().find(|p| p.span == o.span && p.name == o.name)?;
            let positions: Vec<DVec3> = part.mesh.positions.iter().map(|p| from_file(*p, Up::Y)).collect();
            let (min, max) =
                positions.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, z), p| (a.min(*p), z.max(*p)));
            let origin = 0.5 * (min + max);
            let (mut m, area) = Moments::of_mesh(&positions, &part.mesh.triangles, origin);
            // The file's frame is a reflection of the scene's: its triangles wind the
            // other way here.
            if m.volume() < 0.0 {
                m.0.iter_mut().for_each(|x| *x = -*x);
            }
            let centre = m.centre() + origin;
            Some(Estimated {
                volume: m.volume(),
                mass: m.volume(),
                area,
                centre,
                min,
                max,
                inertia: m.inertia(),
                triangles: part.mesh.triangles.len(),
            })
        })
        .collect())
}
