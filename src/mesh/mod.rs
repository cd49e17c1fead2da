//! The mesh back-end: triangle meshes (generated, read from OBJ or STL, or extracted from any
//! shape as an isosurface), each with its own binned-SAH BVH, traced with a watertight
//! ray/triangle test. Vertices are stored in render space (camera-relative f32),
//! transformed once at lowering from f64.
//!
//! Supported IR subset: every shape (primitives by their generators at the chosen detail,
//! everything else and primitives without a generator by `isosurface`) and every mesh.
//! A plane shape becomes a finite square reaching `max_distance` around the camera.

pub mod contour;
pub mod cube;
mod detail;
pub mod deviation;
pub mod dual;
mod iso_job;
mod lattice;
pub(crate) use iso_job::approx;
pub mod isosurface;
pub mod lower;
pub mod octree;
pub mod parts;
pub mod pinch;
mod qef;
pub mod samples;
pub mod tree;
pub mod triangle;
pub mod twist;
pub mod unfold;

use glam::{DAffine3, DVec3, Vec3A, Vec4};
use rayon::prelude::*;

pub use detail::Detail;

/// Whether a lowering is still wanted: in the studio a newer request makes an older
/// one's not, and its isosurfaces and BVH builds then end early (what they made is thrown away).
pub type Wanted = std::sync::Arc<dyn Fn() -> bool + Send + Sync>;

use crate::geom::TriMesh;

use crate::accel::{Aabb, Bvh, Rays4};
use crate::trace::{Counters, Hit, Ray, NO_OBJECT};

/// How a mesh's hits get their shading normal.
#[derive(Clone, Debug, PartialEq)]
pub enum Normals {
    /// Each triangle's own: flat shading.
    Flat,
    /// Area-weighted vertex normals, interpolated (`smooth = true`).
    Vertex,
    /// One unit normal per triangle corner, in the mesh's frame, interpolated: a
    /// tessellated primitive's analytic normals, each taken on its triangle's side of a
    /// crease (a cylinder's rim has one for the cap and one for the side).
    Corners(Vec<[DVec3; 3]>),
}

/// What a mesh object is made from. Lowering makes these in scene order (interning
/// materials and spending the triangle budget as it goes); the world then builds them
/// into [`MeshObject`]s in parallel, where the time goes (vertices to render space, BVH).
pub struct MeshJob {
    /// The triangles, in the frame `xf` maps from.
    pub mesh: TriMesh,
    /// Render space from the mesh's frame.
    pub xf: DAffine3,
    /// The material of every triangle, unless `per_triangle` gives one each.
    pub material: u32,
    /// One material per triangle of `mesh`.
    pub per_triangle: Option<Vec<u32>>,
    /// How hits get their shading normal.
    pub normals: Normals,
    /// Whether the triangles bound a convex polytope (or lie in one plane), as the
    /// generator guarantees: secondary rays leaving a face outward may then skip the mesh.
    pub convex: bool,
    /// What making the mesh found wrong but survivable (parts an isosurface lost).
    pub warnings: Vec<crate::diag::Diagnostic>,
    /// For an isosurface, its cell and how far its vertices lie from the surface.
    pub isosurface: Option<IsoAccuracy>,
}

/// An isosurface's cells and measured accuracy, all in the units of the frame it was
/// sampled in (the shape's own for `mesh isosurface(…)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoAccuracy {
    /// The smallest leaf's side that holds a vertex.
    pub cell: f64,
    /// The largest leaf's side that holds a vertex.
    pub coarsest: f64,
    /// The largest `|f|` at a vertex: the farthest a vertex lies from the surface where
    /// the distance function is exact, a lower bound on it elsewhere.
    pub farthest: f64,
    /// Its deviation from the surface measured on every triangle (under a tolerance).
    pub deviation: Option<deviation::MeasuredDeviation>,
}

impl MeshJob {
    /// The mesh object, ready for tracing.
    pub fn build(self) -> MeshObject {
        self.build_until(&|| false)
    }

    /// [`build`](Self::build) whose BVH build ends early once `stop` says so (see
    /// [`Bvh::build_until`]): the object is then for the caller to drop.
    pub fn build_until(self, stop: &(dyn Fn() -> bool + Sync)) -> MeshObject {
        let object = MeshObject::new_until(&self.mesh, self.xf, self.material, self.per_triangle, self.normals, stop);
        MeshObject { convex: self.convex, isosurface: self.isosurface, ..object }
    }
}

/// Where a mesh object's shading normals come from.
enum Shading {
    /// The faces'.
    Flat,
    /// Per vertex, unit, render space.
    Vertex(Vec<Vec3A>),
    /// Per triangle corner, octahedral-coded ([`octahedral`]), render space.
    Corners(Vec<[u32; 3]>),
}

/// A unit vector in 32 bits: its octahedral projection (Meyer et al., *On floating-point
/// normal vectors*, 2010), 16 bits per coordinate; decoded to within about 3e-5 rad.
fn octahedral(n: Vec3A) -> u32 {
    let p = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let (x, y) =
        if p.z >= 0.0 { (p.x, p.y) } else { ((1.0 - p.y.abs()) * p.x.signum(), (1.0 - p.x.abs()) * p.y.signum()) };
    let q = |c: f32| ((c.clamp(-1.0, 1.0) * 0.5 + 0.5) * 65535.0).round() as u32;
    q(x) | q(y) << 16
}

/// The unit vector [`octahedral`] coded.
fn from_octahedral(code: u32) -> Vec3A {
    let f = |c: u32| (c & 0xffff) as f32 / 65535.0 * 2.0 - 1.0;
    let (x, y) = (f(code), f(code >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z >= 0.0 { (x, y) } else { ((1.0 - y.abs()) * x.signum(), (1.0 - x.abs()) * y.signum()) };
    Vec3A::new(x, y, z).normalize_or(Vec3A::Y)
}

/// A mesh object ready for tracing.
pub struct MeshObject {
    positions: Vec<Vec3A>,
    triangles: Vec<[u32; 3]>,
    /// Where shading normals come from.
    shading: Shading,
    /// Per-triangle material ids, or one for the whole mesh.
    materials: Materials,
    bvh: Bvh,
    /// The triangles' corners in place, four across lanes, one entry per block of the
    /// BVH's leaves ([`Bvh::blocks`]), when the BVH is widened for incoherent rays
    /// ([`MeshObject::widen`]); empty otherwise.
    blocks: Vec<triangle::Block>,
    bounds: Aabb,
    /// Whether the triangles bound a convex polytope (or lie in one plane).
    convex: bool,
    isosurface: Option<IsoAccuracy>,
}

enum Materials {
    One(u32),
    PerTriangle(Vec<u32>),
}

/// Memory of one mesh object, by structure.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshMemory {
    /// Triangles.
    pub triangles: usize,
    /// Bytes of vertex positions (and normals, if smooth).
    pub vertex_bytes: usize,
    /// Bytes of triangle indices (and per-triangle materials).
    pub index_bytes: usize,
    /// Bytes of BVH nodes and primitive indices.
    pub bvh_bytes: usize,
    /// BVH nodes.
    pub bvh_nodes: usize,
    /// BVH depth.
    pub bvh_depth: usize,
    /// For an isosurface, its cell and accuracy.
    pub isosurface: Option<IsoAccuracy>,
}

impl MeshObject {
    /// Builds from a mesh in local space, mapped by `xf` (render from local), with one
    /// material or one per triangle, shaded with `normals`. Degenerate (zero-area)
    /// triangles are dropped: they can never be hit.
    pub fn new(
        mesh: &TriMesh,
        xf: DAffine3,
        material: u32,
        per_triangle: Option<Vec<u32>>,
        normals: Normals,
    ) -> MeshObject {
        MeshObject::new_until(mesh, xf, material, per_triangle, normals, &|| false)
    }

    /// [`new`](Self::new) whose BVH build (most of the time of a large mesh) ends early
    /// once `stop` says so.
    pub fn new_until(
        mesh: &TriMesh,
        xf: DAffine3,
        material: u32,
        per_triangle: Option<Vec<u32>>,
        normals: Normals,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> MeshObject {
        let positions: Vec<Vec3A> = mesh.positions.par_iter().map(|p| xf.transform_point3(*p).as_vec3a()).collect();
        // A mirroring map would turn the winding, and so every face normal, inward.
        let mirrored = xf.matrix3.determinant() < 0.0;
        let mut triangles: Vec<[u32; 3]> =
            mesh.triangles.par_iter().map(|t| if mirrored { [t[0], t[2], t[1]] } else { *t }).collect();
        let mut per_triangle = per_triangle;
        // Normals map by the inverse transpose, corners swapped as their triangles are.
        let mut corners: Option<Vec<[u32; 3]>> = match &normals {
            Normals::Corners(n) => {
                let m = xf.matrix3.inverse().transpose();
                let map = |v: DVec3| octahedral((m * v).normalize_or(DVec3::Y).as_vec3a());
                Some(n.par_iter().map(|c| if mirrored { [c[0], c[2], c[1]] } else { *c }.map(map)).collect())
            }
            Normals::Flat | Normals::Vertex => None,
        };
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|k| positions[k as usize]);
            (b - a).cross(c - a).length_squared() > 0.0
        };
        // Most meshes have no degenerate triangle: one parallel check, and the filtering
        // pass only for those that do (`degenerate_input_is_an_error_or_defined` has one).
        if !triangles.par_iter().all(area) {
            let keep: Vec<bool> = triangles.par_iter().map(area).collect();
            fn kept<T>(items: Vec<T>, keep: &[bool]) -> Vec<T> {
                items.into_iter().zip(keep).filter_map(|(t, &k)| k.then_some(t)).collect()
            }
            triangles = kept(triangles, &keep);
            per_triangle = per_triangle.map(|m| kept(m, &keep));
            corners = corners.map(|c| kept(c, &keep));
        }
        let vertex = (normals == Normals::Vertex).then(|| {
            let mut n = vec![Vec3A::ZERO; positions.len()];
            for t in &triangles {
                let [a, b, c] = t.map(|k| positions[k as usize]);
                let face = (b - a).cross(c - a);
                for k in t {
                    n[*k as usize] += face;
                }
            }
            n.into_par_iter().map(|v| v.try_normalize().unwrap_or(Vec3A::Y)).collect()
        });
        let bounds = |i: usize| {
            let [a, b, c] = triangles[i].map(|k| positions[k as usize]);
            Aabb { min: a.min(b).min(c), max: a.max(b).max(c) }
        };
        let (bvh, order) = Bvh::build_ordered(triangles.len(), bounds, 4, stop);
        let triangles: Vec<[u32; 3]> = order.par_iter().map(|&k| triangles[k as usize]).collect();
        let shading = match (vertex, corners) {
            (Some(v), _) => Shading::Vertex(v),
            (None, Some(c)) => Shading::Corners(order.par_iter().map(|&k| c[k as usize]).collect()),
            (None, None) => Shading::Flat,
        };
        let mats: Vec<u32> = match &per_triangle {
            Some(m) => order.par_iter().map(|&k| m[k as usize]).collect(),
            None => Vec::new(),
        };
        let bounds = bvh.bounds();
        let materials = match per_triangle {
            Some(_) if mats.iter().any(|&m| m != mats[0]) => Materials::PerTriangle(mats),
            Some(_) => Materials::One(mats.first().copied().unwrap_or(material)),
            None => Materials::One(material),
        };
        MeshObject {
            positions,
            triangles,
            shading,
            materials,
            bvh,
            blocks: Vec::new(),
            bounds,
            convex: false,
            isosurface: None,
        }
    }

    /// Whether the triangles bound a convex polytope (or lie in one plane): then every
    /// hit lies in a face whose plane the whole mesh is behind, whatever its shading.
    pub fn is_convex(&self) -> bool {
        self.convex
    }

    /// Render-space bounds (empty for a mesh without triangles).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Memory by structure.
    pub fn memory(&self) -> MeshMemory {
        let vertex = std::mem::size_of::<Vec3A>();
        let normal_bytes = match &self.shading {
            Shading::Flat => 0,
            Shading::Vertex(n) => n.len() * vertex,
            Shading::Corners(c) => c.len() * 12,
        };
        let vertex_bytes = self.positions.len() * vertex + normal_bytes;
        let index_bytes =
            self.triangles.len() * 12 + if let Materials::PerTriangle(m) = &self.materials { m.len() * 4 } else { 0 };
        MeshMemory {
            triangles: self.triangles.len(),
            vertex_bytes,
            index_bytes,
            bvh_bytes: self.bvh.bytes() + self.blocks.len() * std::mem::size_of::<triangle::Block>(),
            bvh_nodes: self.bvh.node_count(),
            bvh_depth: self.bvh.depth(),
            isosurface: self.isosurface,
        }
    }

    #[inline]
    fn tri(&self, i: u32) -> (Vec3A, Vec3A, Vec3A) {
        let t = self.triangles[i as usize];
        (self.positions[t[0] as usize], self.positions[t[1] as usize], self.positions[t[2] as usize])
    }

    /// The closest triangle within `(ray.t_min, t_max)` and where on it the ray hits;
    /// `shear` is `Shear::new(ray.dir)`, computed once per ray by the caller.
    pub fn closest(
        &self,
        ray: &Ray,
        shear: &triangle::Shear,
        t_max: f32,
        c: &mut Counters,
    ) -> Option<(TriRef, triangle::TriHit)> {
        if !self.blocks.is_empty() {
            return self.closest_in_blocks(ray, shear, t_max, c);
        }
        let mut best = None;
        let mut tests = 0u64;
        self.bvh.closest(ray.origin, ray.inv_dir, ray.t_min, t_max, &mut c.node_visits, |i, t_max| {
            tests += 1;
            let (a, b, cc) = self.tri(i);
            let hit = triangle::intersect(ray.origin, shear, a, b, cc, ray.t_min, t_max)?;
            best = Some((TriRef::plain(i), hit));
            Some(hit.t)
        });
        c.triangle_tests += tests;
        best
    }

    /// Walks the widened BVH's leaves front to back along the ray, handing `block(b,
    /// t_max)` each of a leaf's blocks in turn until it returns true, which stops the
    /// walk; counts a leaf's triangles as tested.
    #[inline]
    fn each_block(&self, ray: &Ray, t_max: &mut f32, c: &mut Counters, mut block: impl FnMut(u32, &mut f32) -> bool) {
        let mut tests = 0u64;
        self.bvh.block_leaves(ray.origin, ray.inv_dir, ray.t_min, t_max, &mut c.node_visits, |blocks, n, t_max| {
            tests += u64::from(n);
            blocks.into_iter().any(|b| block(b, t_max))
        });
        c.triangle_tests += tests;
    }

    /// [`closest`](Self::closest) over the widened BVH, a block of four triangles a test:
    /// the same hit, since a block's test is four single tests in slot order.
    fn closest_in_blocks(
        &self,
        ray: &Ray,
        shear: &triangle::Shear,
        mut t_max: f32,
        c: &mut Counters,
    ) -> Option<(TriRef, triangle::TriHit)> {
        let mut best = None;
        self.each_block(ray, &mut t_max, c, |b, t_max| {
            if let Some((lane, hit)) = shear.intersect_block(ray.origin, &self.blocks[b as usize], ray.t_min, *t_max) {
                *t_max = hit.t;
                best = Some((b, lane, hit));
            }
            false
        });
        // The build ordered the triangles by their slots (`Bvh::build_ordered`).
        best.map(|(b, lane, hit)| {
            (TriRef { id: self.bvh.blocks()[b as usize].first + lane as u32, block: b * 4 + lane as u32 }, hit)
        })
    }

    /// [`closest`](Self::closest) for the rays of a packet in `lanes` (groups of four,
    /// as [`Bvh::each_packet`] numbers them), each with its own `t_max`: per ray the same
    /// closest hit up to rounding, found in one walk of the BVH. Each hit nearer than the
    /// lane's `t_max` so far lowers it and goes to `hit(group, lane, triangle, hit)`; the
    /// last one a lane gets is its closest.
    pub fn closest_packet<const N: usize>(
        &self,
        rays: &[Rays4; N],
        shear: &triangle::PacketShear<N>,
        lanes: u32,
        t_max: &mut [Vec4; N],
        c: &mut Counters,
        mut hit: impl FnMut(usize, usize, TriRef, triangle::TriHit),
    ) {
        let mut tests = 0u64;
        self.bvh.each_packet(rays, lanes, t_max, &mut c.node_visits, |i, lanes, t_max| {
            tests += u64::from(lanes.count_ones());
            let (a, b, cc) = self.tri(i);
            let tri = shear.triangle(a, b, cc);
            for g in 0..N {
                let lanes = crate::accel::bvh::group_lanes(lanes, g);
                if lanes == 0 {
                    continue;
                }
                let Some(found) = shear.intersect4(g, &tri, rays[g].t_min, t_max[g], lanes) else {
                    continue;
                };
                // Four fixed lanes, unrolled: walking the set bits (`render::lanes`) here
                // cost 19 instructions per ray of the frame-filling sphere (callgrind of
                // bench `primary rays/blocks mesh-high/full-frame-sphere 1000`).
                for l in (0..4).filter(|l| found.mask & (1 << l) != 0) {
                    t_max[g][l] = found.t[l];
                    hit(g, l, TriRef::plain(i), found.lane(l));
                }
            }
        });
        c.triangle_tests += tests;
    }

    /// The surface at a hit found by [`closest`](Self::closest): point, normal (interpolated
    /// when smooth, else the face's), material and error, numbered `object`. Done once per
    /// ray, for the winner.
    pub fn surface(&self, tri: TriRef, hit: triangle::TriHit, object: u32, dir: Vec3A) -> Hit {
        let i = tri.id;
        // A block's corners are where the test just read them; the index array and the
        // positions would be two more waits on memory.
        let (a, b, cc) = match self.blocks.get((tri.block / 4) as usize) {
            Some(block) => block.corners((tri.block % 4) as usize).into(),
            None => self.tri(i),
        };
        let geometric = (b - a).cross(cc - a);
        let point = a * hit.bary[0] + b * hit.bary[1] + cc * hit.bary[2];
        let [u, v, w] = hit.bary;
        let face = geometric.normalize();
        let shading = match &self.shading {
            Shading::Vertex(n) => {
                let t = self.triangles[i as usize];
                (n[t[0] as usize] * u + n[t[1] as usize] * v + n[t[2] as usize] * w).try_normalize()
            }
            Shading::Corners(c) => {
                let [a, b, d] = c[i as usize].map(from_octahedral);
                (a * u + b * v + d * w).try_normalize()
            }
            Shading::Flat => None,
        };
        // An interpolated normal can face away from the ray near a silhouette where the
        // face does not; the face's is then the better guess of which side is seen.
        let normal = shading.filter(|n| n.dot(dir).signum() == face.dot(dir).signum()).unwrap_or(face);
        let material = match &self.materials {
            Materials::One(m) => *m,
            Materials::PerTriangle(m) => m[i as usize],
        };
        // The interpolated point lies within a few ulps of the true plane.
        let error = point.abs().max_element() * 8.0 * f32::EPSILON;
        let from_inside = geometric.dot(dir) > 0.0;
        let behind = self.convex.then_some(face);
        Hit { t: hit.t, point, normal, material, error, object, behind, from_inside }
    }

    /// Gives the BVH its four-wide copy, which single rays then walk ([`Bvh::widen`]),
    /// and keeps each triangle's corners in leaf order for their tests: worth the memory
    /// (half the binary nodes' again, and 36 bytes a triangle) where most rays are
    /// incoherent, as under light transport; camera rays go in packets over the binary
    /// nodes either way.
    pub fn widen(&mut self) {
        self.bvh.widen();
        let blocks = self.bvh.blocks().iter().map(|b| {
            triangle::Block::new((b.first..b.first + b.count).map(|i| {
                let (a, b, c) = self.tri(i);
                [a, b, c]
            }))
        });
        self.blocks = blocks.collect();
    }

    /// The closest hit within `(ray.t_min, t_max)`, with its surface.
    pub fn intersect(&self, ray: &Ray, shear: &triangle::Shear, t_max: f32, c: &mut Counters) -> Option<Hit> {
        self.closest(ray, shear, t_max, c).map(|(i, hit)| self.surface(i, hit, NO_OBJECT, ray.dir))
    }

    /// Whether any triangle lies along the ray within `(ray.t_min, t_max)`.
    pub fn occluded(&self, ray: &Ray, shear: &triangle::Shear, mut t_max: f32, c: &mut Counters) -> bool {
        if !self.blocks.is_empty() {
            let mut hit = false;
            self.each_block(ray, &mut t_max, c, |b, t_max| {
                hit = shear.intersect_block(ray.origin, &self.blocks[b as usize], ray.t_min, *t_max).is_some();
                hit
            });
            return hit;
        }
        let mut tests = 0u64;
        let hit = self.bvh.any(ray.origin, ray.inv_dir, ray.t_min, t_max, &mut c.node_visits, |i, t_max| {
            tests += 1;
            let (a, b, cc) = self.tri(i);
            triangle::intersect(ray.origin, shear, a, b, cc, ray.t_min, t_max).is_some()
        });
        c.triangle_tests += tests;
        hit
    }
}

/// A triangle a ray hit: its number and, when the test read it from a block of
/// [`MeshObject::widen`], the block and lane (`4·block + lane`) holding its corners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriRef {
    /// The triangle's number.
    pub id: u32,
    /// `4·block + lane`, or `u32::MAX` when not found in a block.
    block: u32,
}

impl TriRef {
    /// Triangle `id`, found outside the blocks.
    fn plain(id: u32) -> TriRef {
        TriRef { id, block: u32::MAX }
    }
}

/// A bounding sphere of a set of points (centre of the box, farthest point).
pub fn points_sphere(points: &[Vec3A]) -> Option<(Vec3A, f32)> {
    let b = points.iter().fold(Aabb::EMPTY, |b, p| b.union(Aabb { min: *p, max: *p }));
    if points.is_empty() {
        return None;
    }
    let c = b.centre();
    let r = points.iter().map(|p| (*p - c).length()).fold(0.0, f32::max);
    Some((c, r))
}

impl MeshObject {
    /// A bounding sphere in render space.
    pub fn sphere(&self) -> Option<(Vec3A, f32)> {
        points_sphere(&self.positions).map(|(c, r)| (c, r * (1.0 + 1e-6) + c.abs().max_element() * 1e-6))
    }
}
