//! `scnc export`: every object of a scene as a triangle mesh, in the output frame of a
//! mesh file, ready for the writers in [`crate::meshfile`].
//!
//! Objects are meshed exactly as `render --geometry mesh` meshes them (the same
//! generators and isosurfaces, at the same detail), but in world coordinates rather
//! than camera-relative ones, mapped into the file's right-handed frame by
//! [`crate::geom::axes`] (the mapping `mesh file(…)` reads back with): `--up y`:
//! `(x, y, −z)`; `--up z`: `(x, z, y)`, every triangle's winding reversed with them, so a
//! part keeps its shape (it is not mirrored in a slicer) and stays wound outward.

pub mod mend;
pub mod report;

use glam::{DAffine3, DVec3};

use crate::diag::{codes, Diagnostic};
use crate::ir::{self, Scene};
use crate::mesh::{self, Detail};
use crate::source::Loader;
use crate::span::Span;
use crate::trace::MaterialTable;

pub use crate::geom::axes::Up;
pub use crate::meshfile::{Colour, Export, Group, IsoFit, Part};

/// How scene coordinates become the file's.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    /// The up axis of the file.
    pub up: Up,
    /// File units per scene unit.
    pub scale: f64,
}

impl Placement {
    /// A scene point in the file's right-handed frame (a reflection of scnc's
    /// left-handed one, see the module's comment).
    pub fn place(&self, p: DVec3) -> DVec3 {
        crate::geom::axes::to_file(p, self.up) * self.scale
    }
}

/// How many times [`collect_refined`] refines an isosurface that lost volume (×1.3 each).
pub const REFINEMENTS: usize = 3;

/// [`collect`], refined where the mesh is not good enough to use: while an isosurface
/// lost volume (a sheet thinner than its cell, W0804), the detail grows 1.3× and
/// the scene is meshed again, [`REFINEMENTS`] times at most. A finer grid over the
/// cell limit keeps the coarser mesh and its warning. `refining(from, to)` is told each
/// step; the detail the result was made at comes back with it.
pub fn collect_refined(
    scene: &Scene,
    detail: Detail,
    frame: Placement,
    memory_limit: u64,
    skip_unbounded: bool,
    loader: &dyn Loader,
    refining: &mut dyn FnMut(Detail, Detail),
) -> (Result<Export, Diagnostic>, Detail) {
    let collect = |detail| collect(scene, detail, frame, memory_limit, skip_unbounded, loader);
    let (mut result, mut detail) = (collect(detail), detail);
    for _ in 0..REFINEMENTS {
        let Ok(e) = &result else { break };
        if !e.warnings.iter().any(|w| w.code == codes::LOST_VOLUME) {
            break;
        }
        let finer = detail.finer(1.3);
        refining(detail, finer);
        match collect(finer) {
            Err(_) => break,
            ok => (result, detail) = (ok, finer),
        }
    }
    (result, detail)
}

/// Meshes every object of `scene` at `detail` into `frame`, within `memory_limit`
/// bytes of meshes (as `render` counts them). An unbounded shape (a `plane`) cannot be
/// a mesh file's solid: with `skip_unbounded` it is left out with a warning, otherwise
/// it is an error at its object.
pub fn collect(
    scene: &Scene,
    detail: Detail,
    frame: Placement,
    memory_limit: u64,
    skip_unbounded: bool,
    loader: &dyn Loader,
) -> Result<Export, Diagnostic> {
    let mut materials = MaterialTable::default();
    let mut budget = mesh::lower::Budget::new(memory_limit);
    // As the world lowers: every object's mesh made in scene order (materials interned
    // and the budget spent as they come), the memory confirmed once, then converted.
    let mut jobs = Vec::with_capacity(scene.objects.len());
    let mut skipped = Vec::new();
    for obj in &scene.objects {
        let job = match &obj.geometry {
            ir::Body::Shape(shape) => {
                if ir::shape_bounds(shape).is_none() {
                    if !skip_unbounded {
                        return Err(unbounded(obj.span));
                    }
                    skipped.push(
                        Diagnostic::warning(
                            codes::SKIPPED_UNBOUNDED,
                            obj.span,
                            "this unbounded object is left out of the export",
                            "it has no finite surface",
                        )
                        .with_note("a mesh file holds closed solids; a `plane` or a `field` without `bounds` has no finite surface to write"),
                    );
                    continue;
                }
                // Only planes use the far limit, and they were refused above.
                mesh::lower::tessellate(shape, DAffine3::IDENTITY, detail, 0.0, &mut budget, &mut materials)?
            }
            ir::Body::Mesh(m) => mesh::lower::explicit(m, DAffine3::IDENTITY, &mut budget, &mut materials, loader)?,
        };
        jobs.push((job, obj.span, &obj.name));
    }
    budget.confirm()?;
    let warnings =
        skipped.into_iter().chain(jobs.iter_mut().flat_map(|(job, ..)| std::mem::take(&mut job.warnings))).collect();
    let mut warnings: Vec<Diagnostic> = warnings;
    let mut parts = Vec::with_capacity(jobs.len());
    for (job, span, name) in jobs {
        let p = part(name.clone(), job, span, frame).map_err(|coarse| collapsed(span, coarse))?;
        if !p.mesh.triangles.is_empty() {
            parts.push(p);
        } else if p.rounded_away > 0 {
            return Err(collapsed(
                span,
                format!("all {} of its triangles have no area in 32-bit coordinates", p.degenerate),
            ));
        } else {
            // An empty object is an invalid object to lib3mf and PrusaSlicer.
            warnings.push(
                Diagnostic::warning(
                    codes::SKIPPED_EMPTY,
                    span,
                    "this object has no triangles and is left out",
                    "an empty mesh",
                )
                .with_note("a mesh file's objects must have triangles: validators and slicers refuse empty ones"),
            );
        }
    }
    let colours = materials.materials.iter().map(|m| Colour(m.color.as_dvec3().to_array())).collect();
    let material_names = material_names(scene, &materials.spans);
    Ok(Export { parts, colours, material_names, warnings })
}

/// The interned materials' names: the `let` that named each (`scene.material_names`),
/// else `material_N`; a name taken already gets `_2`, `_3`, ….
fn material_names(scene: &Scene, spans: &[Span]) -> Vec<String> {
    let mut taken = std::collections::HashSet::new();
    spans
        .iter()
        .enumerate()
        .map(|(m, span)| {
            let base = match scene.material_names.binary_search_by(|(s, _)| s.cmp(span)) {
                Ok(k) => scene.material_names[k].1.clone(),
                Err(_) if m == 0 => "default_grey".to_string(),
                Err(_) => format!("material_{m}"),
            };
            let (mut name, mut n) = (base.clone(), 1);
            while !taken.insert(name.clone()) {
                n += 1;
                name = format!("{base}_{n}");
            }
            name
        })
        .collect()
}

/// Object `name`'s mesh in the file's frame, without its zero-area triangles.
fn part(name: String, job: mesh::MeshJob, span: Span, frame: Placement) -> Result<Part, String> {
    let positions: Vec<DVec3> = job.mesh.positions.iter().map(|&p| frame.place(job.xf.transform_point3(p))).collect();
    // Judged before mending, which would weld such an object away to nothing.
    if let Some(coarse) = too_coarse_for_f32(&positions) {
        return Err(coarse);
    }
    // The reflection into the file's frame turns every triangle inside out; a transform
    // that mirrors (negative determinant) turns it back.
    let mirrored = job.xf.matrix3.determinant() < 0.0;
    let (mut triangles, mut materials, mut rounded_away) = (Vec::new(), Vec::new(), 0);
    for (t, &[a, b, c]) in job.mesh.triangles.iter().enumerate() {
        // Judged on the f32 corners every format writes (a triangle with area in f64
        // can lose it in f32 far from the origin); repeated corners give a zero cross
        // product too.
        let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize].as_vec3());
        if (pb - pa).cross(pc - pa).length_squared() == 0.0 {
            let [qa, qb, qc] = [a, b, c].map(|i| positions[i as usize]);
            rounded_away += usize::from((qb - qa).cross(qc - qa).length_squared() > 0.0);
        }
        triangles.push(crate::geom::axes::wound([a, b, c], mirrored));
        materials.push(job.per_triangle.as_ref().map_or(job.material, |m| m[t]));
    }
    let written: Vec<glam::Vec3> = positions.iter().map(|p| p.as_vec3()).collect();
    let mended = mend::mend(&written, &mut triangles, &mut materials);
    let degenerate = mended.removed + mended.dropped;
    // Collapsed corners leave vertices no triangle uses: the file lists only used ones,
    // in their order.
    let mut new_index = vec![u32::MAX; positions.len()];
    triangles.iter().flatten().for_each(|&i| new_index[i as usize] = 0);
    let mut kept = Vec::with_capacity(positions.len());
    for (i, p) in positions.iter().enumerate() {
        if new_index[i] == 0 {
            new_index[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    triangles.iter_mut().flatten().for_each(|i| *i = new_index[*i as usize]);
    let positions = kept;
    // Measured in the frame the mesh was made in: lengths scale by the placement's
    // stretch (a transform and the file's scale; turns and the up axis keep them).
    let stretch = job.xf.matrix3.determinant().abs().cbrt() * frame.scale;
    let fit = job.isosurface.and_then(|iso| iso.deviation).map(|d| IsoFit {
        max: d.max * stretch,
        mean: d.mean * stretch,
        samples: d.samples,
        proved: d.proved,
        unresolved: d.unresolved,
    });
    Ok(Part {
        name,
        span,
        mesh: crate::geom::TriMesh { positions, triangles },
        materials,
        smooth: job.normals != mesh::Normals::Flat,
        degenerate,
        rounded_away,
        fit,
    })
}

/// How many f32 steps an object must span on every axis: rounding then moves a vertex
/// by at most a hundredth of the object's extent.
const MIN_F32_STEPS: f64 = 50.0;

/// Why f32 coordinates cannot hold an object at `positions`, if they cannot: an axis
/// along which it spans fewer than [`MIN_F32_STEPS`] steps of f32 at its coordinates
/// (a 0.01 sphere at 1e6, where f32 steps by 0.0625, is written as a flat disk).
fn too_coarse_for_f32(positions: &[DVec3]) -> Option<String> {
    let (lo, hi) = positions.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (0..3).find_map(|k| {
        let extent = hi[k] - lo[k];
        let step = lo[k].abs().max(hi[k].abs()) * f64::from(f32::EPSILON);
        (extent > 0.0 && extent < MIN_F32_STEPS * step).then(|| {
            format!(
                "it is {} across its {} axis in the file, where 32-bit coordinates step by {}",
                mesh::approx(extent),
                ["x", "y", "z"][k],
                mesh::approx(step)
            )
        })
    })
}

/// An object f32 coordinates cannot hold where it stands, for `why`.
fn collapsed(span: Span, why: String) -> Diagnostic {
    Diagnostic::error(codes::LOWERING, span, "this object cannot be written where it stands", why)
        .with_note("mesh files store positions as 32-bit floats, whose step grows with the distance from the origin")
        .with_hint("move the scene nearer the origin, or scale the object up")
}

fn unbounded(span: Span) -> Diagnostic {
    Diagnostic::error(codes::LOWERING, span, "cannot export an unbounded shape", "this object has no finite extent")
        .with_note("a mesh file holds closed solids; a `plane` or an infinite `repeat` has no finite surface")
        .with_hint("intersect it with a `box` to bound it, or pass `--skip-unbounded` to leave it out")
}
