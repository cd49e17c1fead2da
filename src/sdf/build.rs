//! Lowering a shape tree to closures. Transforms are pushed down to the leaves and
//! composed in f64 (render-from-local), so each primitive applies one f32 affine map
//! computed from exact f64 products; operators that work in local distance units
//! (smooth blends, round, shell, repeat) keep their own frame and are wrapped instead.

use std::sync::Arc;

use glam::{Affine3A, DAffine3, DMat3, Vec3A};

use super::field::{self, BoxCut};
use super::prim;
use super::surf::{Sdf, Surf, SurfSdf};
use super::union::{self, Fold, PartTree, RayParts};
use crate::accel::{padded_sphere, Aabb};
use crate::ir::{min_singular_value, similarity, CsgOp, Primitive, Shape, ShapeKind};
use crate::primitive::{Plane, Solid, Sphere, Visit};
use crate::trace::MaterialTable;

/// An object's lowered root: its closures, and what a ray can march by instead of the
/// closure (a union part by part, a field by segments).
pub struct Root {
    /// The distance bound.
    pub dist: Sdf,
    /// The surface closure.
    pub surf: SurfSdf,
    /// How a ray marches it.
    pub walk: Walk,
    /// How many times over the distance bound may understate the distance near the
    /// surface (`looseness`); above 1 its hits are confirmed by the gradient
    /// ([`super::march::refine`]) and its marches take that many times the steps.
    pub loose: f64,
}

/// How many times over a shape's distance bound may understate its distance near the
/// surface: the product, down any path of the tree, of the slopes it is divided by (a
/// field's or a warp's stated or estimated `L`, a displacement's `1 + L`). Above 1 the
/// bound alone takes a shell up to that many thresholds thick for the surface, and the
/// march crawls there by the bound: about that many times the steps.
pub fn looseness(shape: &Shape) -> f64 {
    let most = |shapes: &[Arc<Shape>]| shapes.iter().map(|s| looseness(s)).fold(1.0, f64::max);
    match &shape.kind {
        ShapeKind::Field { body, lipschitz, .. } => lipschitz.value.max(1.0) * most(&body.shapes()),
        // A twist or bend divides by its stretch where the point is, not by `L`.
        ShapeKind::Warp { child, domain_op: Some(op), .. } if super::domain::Map::new(*op).is_some() => {
            looseness(child)
        }
        ShapeKind::Warp { child, lipschitz, .. } => lipschitz.value.max(1.0) * looseness(child),
        ShapeKind::Displace { child, lipschitz, .. } => (1.0 + lipschitz.value) * looseness(child),
        _ => most(shape.children()),
    }
}

/// How an object's rays are marched, by what is at its root (under transforms and paint).
#[derive(Clone)]
pub enum Walk {
    /// Sphere traced on its distance closure.
    Plain,
    /// A union, part by part ([`RayParts`]).
    Parts(RayParts),
    /// A field, by segments (`field::RayField`); boxed, as most objects have none.
    Field(Box<field::RayField>),
    /// A twist or bend of a convex solid, by its bending (`sdf::warp::RayWarp`);
    /// boxed, as most objects have none.
    Warp(Box<super::warp::RayWarp>),
}

/// Builds closures and counts the bytes they capture.
pub struct Builder<'a> {
    /// Material interning.
    pub materials: &'a mut MaterialTable,
    /// Bytes of captured closure state and reference-counted headers.
    pub bytes: usize,
    /// Whether unions skip the parts their hierarchy rules out (always, but for the
    /// tests that compare against evaluating every part).
    pub prune: bool,
    /// The union built last through a hierarchy (its node's address, hierarchy, parts
    /// and blend radius), for [`build_root`](Self::build_root).
    last_union: Option<LastUnion>,
    /// The field built last (its node's address and body), for
    /// [`build_root`](Self::build_root).
    last_field: Option<(usize, field::CompiledBody)>,
    /// The twist or bend built last of a child with a convex distance (its node's
    /// address, the map, the child's closure, the cut and the closure's `1/L`), for
    /// [`build_root`](Self::build_root).
    last_warp: Option<(usize, super::domain::Map, Sdf, Option<BoxCut>, f32)>,
    /// Render space from the frame the node being built is in: operators that work in
    /// their own units restart `xf` at the identity, and a pattern still needs the
    /// whole map to its object's space.
    frame: DAffine3,
}

/// A union built through a hierarchy: its node's address, the hierarchy, its parts'
/// closures and its blend radius.
struct LastUnion {
    node: usize,
    tree: Arc<PartTree>,
    parts: Arc<[Sdf]>,
    surfs: Arc<[SurfSdf]>,
    k: f32,
}

/// The closures of one primitive in its own frame, painted `mat`: its distance inlined
/// in the one, and with its analytic gradient in the other.
struct Leaf<'b, 'a> {
    builder: &'b mut Builder<'a>,
    mat: u32,
}

impl Visit for Leaf<'_, '_> {
    type Out = (Sdf, SurfSdf);

    fn visit<S: Solid>(self, s: &S) -> (Sdf, SurfSdf) {
        let (f, g, mat) = (s.distance(), s.gradient(), self.mat);
        let d = self.builder.leaf(f.clone());
        let m = self.builder.mat(move |p| {
            crate::trace::count_leaf();
            Surf { d: f(p), g: g(p), mat }
        });
        (d, m)
    }
}

/// Render space to the frame `acc` maps into render space, in f32, and the frame's
/// smallest stretch (1 for a translation): what a closure built in that frame reads
/// the point through and scales its value by.
fn frame_of(acc: DAffine3) -> (Affine3A, f64) {
    let inv = acc.inverse();
    let inv32 = Affine3A::from_mat3_translation(inv.matrix3.as_mat3(), inv.translation.as_vec3());
    let stretch = if acc.matrix3 == DMat3::IDENTITY { 1.0 } else { min_singular_value(acc.matrix3) };
    (inv32, stretch)
}

/// Arc header (two counts) that every closure allocation carries.
const ARC_HEADER: usize = 16;

impl<'a> Builder<'a> {
    /// A builder interning materials into `materials`.
    pub fn new(materials: &'a mut MaterialTable) -> Builder<'a> {
        Builder {
            materials,
            bytes: 0,
            prune: true,
            last_union: None,
            last_field: None,
            last_warp: None,
            frame: DAffine3::IDENTITY,
        }
    }

    /// [`build`](Self::build), and when the shape is a union of bounded parts (under
    /// transforms and paint) that a ray can march part by part, what it needs for that.
    pub fn build_root(&mut self, shape: &Shape, xf: DAffine3, mat: u32) -> Root {
        self.last_union = None;
        self.last_field = None;
        self.last_warp = None;
        let (d, m) = self.build(shape, xf, mat);
        let mut node = shape;
        let mut acc = xf;
        loop {
            match &node.kind {
                ShapeKind::Transform { child, xf: inner } => {
                    acc *= *inner;
                    node = child;
                }
                ShapeKind::Paint { child, .. } => node = child,
                _ => break,
            }
        }
        let at_root = |addr: usize| addr == node as *const Shape as usize;
        let union = self.last_union.take().filter(|u| at_root(u.node));
        let field = self.last_field.take().filter(|f| at_root(f.0));
        let warp = self.last_warp.take().filter(|w| at_root(w.0));
        let walk = if let Some(LastUnion { tree, parts, surfs, k, .. }) = union {
            // Sharp unions are built in render space; smooth ones in their own frame.
            let (inv, scale) = if k == 0.0 { (Affine3A::IDENTITY, 1.0) } else { frame_of(acc) };
            let scale = scale as f32;
            Walk::Parts(RayParts { inv, scale, tree, parts, surfs, k })
        } else if let (ShapeKind::Field { bounds, lipschitz, .. }, Some((_, body))) = (&node.kind, field) {
            let (inv, stretch) = frame_of(acc);
            Walk::Field(Box::new(field::RayField {
                inv,
                scale: (stretch / lipschitz.value) as f32,
                body,
                bounds: bounds.map(|b| (b.min.as_vec3a(), b.max.as_vec3a())),
                convex: node.is_convex(),
            }))
        } else if let Some((_, map, child, cut, k)) = warp {
            let (inv, stretch) = frame_of(acc);
            Walk::Warp(Box::new(super::warp::RayWarp { inv, scale: stretch as f32, map, child, cut, k }))
        } else {
            Walk::Plain
        };
        Root { dist: d, surf: m, walk, loose: looseness(shape) }
    }

    fn sdf<F: Fn(Vec3A) -> f32 + Send + Sync + 'static>(&mut self, f: F) -> Sdf {
        self.bytes += std::mem::size_of_val(&f) + ARC_HEADER;
        Arc::new(f)
    }

    fn mat<F: Fn(Vec3A) -> Surf + Send + Sync + 'static>(&mut self, f: F) -> SurfSdf {
        // Material closures mirror the distance ones; their bytes count too.
        self.bytes += std::mem::size_of_val(&f) + ARC_HEADER;
        Arc::new(f)
    }

    /// Lowers `shape` seen through `xf` (render from local), painted `mat` where it has no material.
    pub fn build(&mut self, shape: &Shape, xf: DAffine3, mat: u32) -> (Sdf, SurfSdf) {
        match &shape.kind {
            ShapeKind::Transform { child, xf: inner } => self.build(child, xf * *inner, mat),
            ShapeKind::Paint { child, material } => {
                let id = self.materials.intern(material, self.frame * xf * child.placement());
                self.build(child, xf, id)
            }
            ShapeKind::Csg { op: CsgOp::Union, children, smooth } if *smooth == 0.0 && children.len() >= MANY => {
                let kids: Vec<(Sdf, SurfSdf)> = children.iter().map(|c| self.build(c, xf, mat)).collect();
                match part_bounds(children, xf) {
                    Some(bounds) => self.pruned_union(shape, kids, bounds, 0.0),
                    None => self.combine(kids, CsgOp::Union),
                }
            }
            ShapeKind::Csg { op: CsgOp::Subtract, children, smooth } if *smooth == 0.0 && children.len() > MANY => {
                let kids: Vec<(Sdf, SurfSdf)> = children.iter().map(|c| self.build(c, xf, mat)).collect();
                match part_bounds(&children[1..], xf) {
                    Some(bounds) => {
                        let (first, cutters) = (kids[0].clone(), kids[1..].to_vec());
                        self.pruned_subtract(first, cutters, bounds, 0.0)
                    }
                    None => self.combine(kids, CsgOp::Subtract),
                }
            }
            ShapeKind::Csg { op, children, smooth } if *smooth == 0.0 => {
                let kids: Vec<(Sdf, SurfSdf)> = children.iter().map(|c| self.build(c, xf, mat)).collect();
                self.combine(kids, *op)
            }
            ShapeKind::Primitive(p) => self.primitive(p, xf, mat),
            ShapeKind::Csg { .. }
            | ShapeKind::Round { .. }
            | ShapeKind::Shell { .. }
            | ShapeKind::Repeat { .. }
            | ShapeKind::Field { .. }
            | ShapeKind::Warp { .. }
            | ShapeKind::Displace { .. } => {
                // Smooth operators and modifiers work in their own units: build locally, then wrap.
                let outer = self.frame;
                self.frame = outer * xf;
                let (d, m) = self.local(shape, mat);
                self.frame = outer;
                self.wrap(d, m, xf)
            }
        }
    }

    fn primitive(&mut self, p: &Primitive, xf: DAffine3, mat: u32) -> (Sdf, SurfSdf) {
        // A sphere under a similarity is a sphere: no inverse map needed.
        if let (Primitive::Sphere(s), Some(scale)) = (p, similarity(xf.matrix3)) {
            let c = Vec3A::from(xf.translation.as_vec3());
            let sphere = Sphere { r: s.r * scale };
            let (f, g) = (sphere.distance(), sphere.gradient());
            let d = self.leaf({
                let f = f.clone();
                move |p| f(p - c)
            });
            let m = self.mat(move |p| {
                crate::trace::count_leaf();
                Surf { d: f(p - c), g: g(p - c), mat }
            });
            return (d, m);
        }
        match p {
            // Transform the plane itself (exact for any invertible map), in f64; the
            // checker refuses maps degenerate enough to fail (E0403).
            Primitive::Plane(plane) => {
                let (normal, offset) = crate::ir::transform_half_space((plane.normal, plane.offset), &xf)
                    .unwrap_or((plane.normal, plane.offset));
                let plane = Plane { normal, offset };
                let (f, g) = (plane.distance(), plane.gradient());
                let d = self.leaf(f.clone());
                let m = self.mat(move |p| {
                    crate::trace::count_leaf();
                    Surf { d: f(p), g: g(p), mat }
                });
                (d, m)
            }
            _ => {
                let (d, m) = p.visit(Leaf { builder: self, mat });
                self.wrap(d, m, xf)
            }
        }
    }

    /// A primitive's distance closure, counted in [`leaf_evals`](crate::trace::take_leaf_evals).
    fn leaf<F: Fn(Vec3A) -> f32 + Send + Sync + 'static>(&mut self, f: F) -> Sdf {
        self.sdf(move |p| {
            crate::trace::count_leaf();
            f(p)
        })
    }

    /// Applies `xf` (render from local) to a local-frame evaluator: the inverse maps the
    /// query point; the distance is scaled by the smallest singular value of the linear
    /// part, which keeps it a bound under any scale (exact under a similarity).
    fn wrap(&mut self, d: Sdf, m: SurfSdf, xf: DAffine3) -> (Sdf, SurfSdf) {
        if xf.matrix3 == DMat3::IDENTITY {
            if xf.translation == glam::DVec3::ZERO {
                return (d, m);
            }
            let t = Vec3A::from(xf.translation.as_vec3());
            let dd = self.sdf(move |p| d(p - t));
            let mm = self.mat(move |p| m(p - t));
            return (dd, mm);
        }
        let (inv32, k) = frame_of(xf);
        let k = k as f32;
        // The chain rule: the gradient of k·f(M⁻¹p) is k·M⁻ᵀ∇f.
        let to_world = inv32.matrix3.transpose() * k;
        let dd = self.sdf(move |p| d(inv32.transform_point3a(p)) * k);
        let mm = self.mat(move |p| {
            let s = m(inv32.transform_point3a(p));
            Surf { d: s.d * k, g: to_world * s.g, mat: s.mat }
        });
        (dd, mm)
    }

    /// Builds an operator or modifier node in its own frame.
    ///
    /// Long because it is one exhaustive match over the operator and modifier nodes, each
    /// arm the node's pair of closures; a new kind of node fails to compile until it has
    /// its arm here.
    fn local(&mut self, shape: &Shape, mat: u32) -> (Sdf, SurfSdf) {
        let id = DAffine3::IDENTITY;
        match &shape.kind {
            ShapeKind::Csg { op, children, smooth } => {
                let mut kids: Vec<(Sdf, SurfSdf)> = children.iter().map(|c| self.build(c, id, mat)).collect();
                let k = *smooth as f32;
                match op {
                    CsgOp::Union => match part_bounds(children, id) {
                        Some(bounds) => self.pruned_union(shape, kids, bounds, k),
                        None => self.smooth(kids, *op, k),
                    },
                    CsgOp::Subtract => match part_bounds(&children[1..], id) {
                        Some(bounds) if kids.len() > 1 => {
                            let cutters = kids.split_off(1);
                            self.pruned_subtract(kids.remove(0), cutters, bounds, k)
                        }
                        _ => self.smooth(kids, *op, k),
                    },
                    CsgOp::Intersect => self.smooth(kids, *op, k),
                }
            }
            ShapeKind::Round { child, radius } => {
                let (d, m) = self.build(child, id, mat);
                let r = *radius as f32;
                (
                    self.sdf(move |p| d(p) - r),
                    self.mat(move |p| {
                        let s = m(p);
                        Surf { d: s.d - r, ..s }
                    }),
                )
            }
            ShapeKind::Shell { child, thickness } => {
                let (d, m) = self.build(child, id, mat);
                let half = *thickness as f32 * 0.5;
                (
                    self.sdf(move |p| d(p).abs() - half),
                    self.mat(move |p| {
                        let s = m(p);
                        // Inside the original solid the wall's outside is the other way.
                        let g = if s.d < 0.0 { -s.g } else { s.g };
                        Surf { d: s.d.abs() - half, g, mat: s.mat }
                    }),
                )
            }
            ShapeKind::Repeat { child, period, count } => {
                let (d, m) = self.build(child, id, mat);
                let rep = Repeat::new(period.as_vec3a(), *count);
                let rep2 = rep.clone();
                (self.sdf(move |p| rep.eval(p, |q| d(q))), self.mat(move |p| rep2.eval_surf(p, |q| m(q))))
            }
            ShapeKind::Field { sweep: Some(sweep), bounds, .. } => {
                // Marched as the plain distance it is: no field march, no tape.
                let swept = std::sync::Arc::new(super::sweep::Swept::new(sweep));
                self.bytes += swept.bytes() + ARC_HEADER;
                let (cut, s) = (bounds.as_ref().map(BoxCut::new), swept.clone());
                (
                    self.sdf(move |p| {
                        crate::trace::count_leaf();
                        field::cut(&cut, p, s.distance(p))
                    }),
                    self.mat(move |p| {
                        crate::trace::count_leaf();
                        let (d, g) = swept.eval(p);
                        field::cut_surf(&cut, p, Surf { d, g, mat })
                    }),
                )
            }
            ShapeKind::Field { body, bounds, lipschitz, .. } => {
                let body = self.body(body, mat);
                self.last_field = Some((shape as *const Shape as usize, body.clone()));
                let (k, cut) = (1.0 / lipschitz.value as f32, bounds.as_ref().map(BoxCut::new));
                let b = body.clone();
                (
                    self.sdf(move |p| {
                        crate::trace::count_leaf();
                        field::cut(&cut, p, b.num(p) * k)
                    }),
                    self.mat(move |p| {
                        crate::trace::count_leaf();
                        let v = body.dual(p);
                        field::cut_surf(&cut, p, Surf { d: v.v * k, g: v.g * k, mat })
                    }),
                )
            }
            ShapeKind::Warp { child, map, bounds, lipschitz, domain_op } => {
                let (d, m) = self.build(child, id, mat);
                let (k, cut) = (1.0 / lipschitz.value as f32, bounds.as_ref().map(BoxCut::new));
                if let Some(map) = domain_op.and_then(super::domain::Map::new) {
                    if child.has_convex_distance() && map.is_smooth() {
                        self.last_warp = Some((shape as *const Shape as usize, map, d.clone(), cut, k));
                    }
                    return (
                        self.sdf(move |p| {
                            // A step of at most |v| stays within the ball where the
                            // local stretch holds.
                            let v = d(map.apply(p));
                            field::cut(&cut, p, map.bound(p, v, k))
                        }),
                        self.mat(move |p| {
                            let q = map.apply(p);
                            let s = m(q);
                            field::cut_surf(&cut, p, Surf { d: s.d * k, g: map.pull(p, q, s.g) * k, mat: s.mat })
                        }),
                    );
                }
                let map = self.body(map, mat);
                let q = map.clone();
                (
                    self.sdf(move |p| field::cut(&cut, p, d(q.vec(p)) * k)),
                    self.mat(move |p| {
                        let j = map.vec_dual(p);
                        let s = m(Vec3A::new(j[0].v, j[1].v, j[2].v));
                        // The chain rule: ∇(f∘q) = Jᵀ∇f.
                        let g = j[0].g * s.g.x + j[1].g * s.g.y + j[2].g * s.g.z;
                        field::cut_surf(&cut, p, Surf { d: s.d * k, g: g * k, mat: s.mat })
                    }),
                )
            }
            ShapeKind::Displace { child, by, bounds, lipschitz, .. } => {
                let (d, m) = self.build(child, id, mat);
                let by = self.body(by, mat);
                // The sum's slope is at most the shape's 1 plus the displacement's.
                let (k, cut) = (1.0 / (1.0 + lipschitz.value as f32), bounds.as_ref().map(BoxCut::new));
                let b = by.clone();
                (
                    self.sdf(move |p| field::cut(&cut, p, (d(p) + b.num(p)) * k)),
                    self.mat(move |p| {
                        let s = m(p);
                        let v = by.dual(p);
                        field::cut_surf(&cut, p, Surf { d: (s.d + v.v) * k, g: (s.g + v.g) * k, mat: s.mat })
                    }),
                )
            }
            ShapeKind::Primitive(_) | ShapeKind::Transform { .. } | ShapeKind::Paint { .. } => {
                self.build(shape, id, mat)
            }
        }
    }

    /// A field body compiled, the shapes its `dist` calls read lowered in its frame
    /// (their materials are not the field's: a field's surface is its own).
    fn body(&mut self, e: &Arc<crate::ir::field::FieldExpr>, mat: u32) -> field::CompiledBody {
        let tape = crate::field::Tape::new(e);
        let built: Vec<(Sdf, SurfSdf)> = tape.shapes.iter().map(|s| self.build(s, DAffine3::IDENTITY, mat)).collect();
        let (dist, surf): (Vec<Sdf>, Vec<SurfSdf>) = built.into_iter().unzip();
        let body = field::CompiledBody::new(tape, field::Shapes { dist: dist.into(), surf: surf.into() });
        self.bytes += body.bytes() + ARC_HEADER;
        body
    }

    fn combine(&mut self, kids: Vec<(Sdf, SurfSdf)>, op: CsgOp) -> (Sdf, SurfSdf) {
        let mut kids = kids;
        if kids.len() == 1 {
            if let Some(only) = kids.pop() {
                return only;
            }
        }
        let (ds, ms): (Vec<Sdf>, Vec<SurfSdf>) = kids.into_iter().unzip();
        self.bytes += ds.len() * 2 * std::mem::size_of::<Sdf>();
        match op {
            CsgOp::Union => (
                self.sdf(move |p| ds.iter().fold(f32::INFINITY, |a, f| a.min(f(p)))),
                self.mat(move |p| ms[1..].iter().fold(ms[0](p), |a, f| a.min(f(p)))),
            ),
            CsgOp::Intersect => (
                self.sdf(move |p| ds.iter().fold(f32::NEG_INFINITY, |a, f| a.max(f(p)))),
                self.mat(move |p| ms[1..].iter().fold(ms[0](p), |a, f| a.max(f(p)))),
            ),
            CsgOp::Subtract => (
                self.sdf(move |p| ds[1..].iter().fold(ds[0](p), |a, f| a.max(-f(p)))),
                // The cut faces take the material of the part cut away.
                self.mat(move |p| ms[1..].iter().fold(ms[0](p), |a, f| a.max(f(p).complement()))),
            ),
        }
    }

    /// A union of bounded parts, walked through a hierarchy of their boxes (see
    /// [`union`]); `k` is the blend radius, 0 for a sharp union.
    fn pruned_union(&mut self, node: &Shape, kids: Vec<(Sdf, SurfSdf)>, bounds: PartBounds, k: f32) -> (Sdf, SurfSdf) {
        let tree = Arc::new(PartTree::new(bounds.boxes, bounds.spheres, self.prune));
        let (ds, ms): (Vec<Sdf>, Vec<SurfSdf>) = kids.into_iter().unzip();
        let (ds, ms): (Arc<[Sdf]>, Arc<[SurfSdf]>) = (ds.into(), ms.into());
        self.bytes += ds.len() * 2 * std::mem::size_of::<Sdf>() + tree.bytes();
        self.last_union = Some(LastUnion {
            node: node as *const Shape as usize,
            tree: tree.clone(),
            parts: ds.clone(),
            surfs: ms.clone(),
            k,
        });
        let t = tree.clone();
        let d = self.sdf(move |p| {
            let mut fold = Fold::new(k);
            t.visit(p, f32::INFINITY, |i, bound| fold.push(union::clamp(ds[i](p), bound)));
            fold.finish()
        });
        let m = self.mat(move |p| tree.surface(&ms, k, p, f32::INFINITY));
        (d, m)
    }

    /// `subtract(a, cutters…)` with bounded cutters, walked through a hierarchy of their
    /// bounds. Sharp (`k` = 0): a cutter removes material only where its value is below
    /// minus the result so far, so where `p` is outside a node by at least that much (and
    /// outside it at all), nothing in it can change the result. Smooth: the cutters are
    /// folded nearest first onto the first shape turned inside out (see
    /// [`union::smooth_cut`]), and one `k` or more above the running value blends by
    /// nothing. Exact, cutters clamped to their bounds as a union's parts are.
    fn pruned_subtract(
        &mut self,
        (first, first_mat): (Sdf, SurfSdf),
        cutters: Vec<(Sdf, SurfSdf)>,
        bounds: PartBounds,
        k: f32,
    ) -> (Sdf, SurfSdf) {
        let tree = Arc::new(PartTree::new(bounds.boxes, bounds.spheres, self.prune));
        let (cs, ms): (Vec<Sdf>, Vec<SurfSdf>) = cutters.into_iter().unzip();
        self.bytes += (cs.len() + 1) * 2 * std::mem::size_of::<Sdf>() + tree.bytes();
        let t = tree.clone();
        if k > 0.0 {
            let d = self.sdf(move |p| {
                let mut fold = Fold::cut(-first(p), k);
                t.visit(p, fold.threshold(), |i, bound| fold.push(union::clamp(cs[i](p), bound)));
                -fold.finish()
            });
            let m = self.mat(move |p| tree.cut_surface(first_mat(p), &ms, k, p));
            return (d, m);
        }
        let d = self.sdf(move |p| {
            let mut acc = first(p);
            t.visit(p, -acc, |i, bound| {
                acc = acc.max(-union::clamp(cs[i](p), bound));
                -acc
            });
            acc
        });
        let m = self.mat(move |p| {
            let mut acc = first_mat(p);
            let mut cutter = usize::MAX;
            tree.visit(p, -acc.d, |i, _| {
                let cut = tree.clamped(i, ms[i](p), p).complement();
                // The cut faces take the material of the cutter; ties go to the first.
                if cut.d > acc.d || (cut.d == acc.d && cutter != usize::MAX && i < cutter) {
                    (acc, cutter) = (cut, i);
                }
                -acc.d
            });
            acc
        });
        (d, m)
    }

    fn smooth(&mut self, kids: Vec<(Sdf, SurfSdf)>, op: CsgOp, k: f32) -> (Sdf, SurfSdf) {
        let (ds, ms): (Vec<Sdf>, Vec<SurfSdf>) = kids.into_iter().unzip();
        self.bytes += ds.len() * 2 * std::mem::size_of::<Sdf>();
        // intersect = −smin(−a, −b); subtract(a, b) = −smin(−a, b).
        let fold = move |vals: &mut dyn Iterator<Item = f32>| -> f32 {
            match op {
                // Nearest first, like a union of bounded parts (see `union`).
                CsgOp::Union => {
                    let mut fold = Fold::new(k);
                    vals.for_each(|v| {
                        fold.push(v);
                    });
                    fold.finish()
                }
                CsgOp::Intersect => {
                    let first = vals.next().unwrap_or(f32::INFINITY);
                    -vals.fold(-first, |a, b| prim::smin(a, -b, k))
                }
                // Nearest first too, as with bounded cutters (see `pruned_subtract`).
                CsgOp::Subtract => {
                    let mut fold = Fold::cut(-vals.next().unwrap_or(f32::INFINITY), k);
                    vals.for_each(|v| {
                        fold.push(v);
                    });
                    -fold.finish()
                }
            }
        };
        let d = self.sdf(move |p| fold(&mut ds.iter().map(|f| f(p))));
        let m = self.mat(move |p| {
            let first = ms[0](p);
            let rest = ms[1..].iter().map(|f| f(p));
            match op {
                CsgOp::Union => union::smooth_surf(std::iter::once(first).chain(rest), k),
                CsgOp::Intersect => rest.fold(first.complement(), |a, b| a.smin(b.complement(), k)).complement(),
                CsgOp::Subtract => union::smooth_cut(first, rest.collect(), k),
            }
        });
        (d, m)
    }
}

/// Unions of at least this many sharp parts are walked through a hierarchy of their
/// boxes; below it a plain loop is as fast. Every bounded smooth union is (its blend
/// is defined by the nearest-first fold of [`union`]).
const MANY: usize = 8;

/// Each child's box and bounding sphere seen through `xf`, padded to f32; `None` if one
/// is unbounded.
fn part_bounds(children: &[Arc<Shape>], xf: DAffine3) -> Option<PartBounds> {
    let stretch = crate::ir::max_stretch(xf.matrix3);
    let mut out = PartBounds { boxes: Vec::with_capacity(children.len()), spheres: Vec::with_capacity(children.len()) };
    for c in children {
        let b = crate::ir::shape_bounds(c)?.transform(&xf);
        // An empty intersection has no box to walk to; it takes the plain path.
        if !b.min.cmple(b.max).all() {
            return None;
        }
        out.boxes.push(Aabb::padded(b));
        let (centre, radius) = match crate::ir::shape_sphere(c) {
            Some((centre, r)) => (xf.transform_point3(centre), r * stretch),
            None => (b.centre(), (b.max - b.min).length() * 0.5),
        };
        out.spheres.push(padded_sphere(centre, radius));
    }
    Some(out)
}

/// The bounds of a union's parts, by part.
struct PartBounds {
    boxes: Vec<Aabb>,
    spheres: Vec<(Vec3A, f32)>,
}

/// Finite repetition: `count` copies per axis, `period` apart, centred at the origin.
/// The nearest copy and its neighbours on each repeated axis are evaluated, so the
/// result stays a bound as long as a copy reaches no further than one period beyond its cell.
#[derive(Clone)]
struct Repeat {
    period: Vec3A,
    n: [i32; 3],
    shift: Vec3A,
}

impl Repeat {
    fn new(period: Vec3A, count: [u32; 3]) -> Repeat {
        let n = [count[0] as i32, count[1] as i32, count[2] as i32];
        let shift = period * Vec3A::new(n[0] as f32 - 1.0, n[1] as f32 - 1.0, n[2] as f32 - 1.0) * 0.5;
        Repeat { period, n, shift }
    }

    fn cells(&self, p: Vec3A) -> impl Iterator<Item = Vec3A> + '_ {
        let q = p + self.shift;
        let mut centre = [0i32; 3];
        for a in 0..3 {
            centre[a] = ((q[a] / self.period[a]).round() as i32).clamp(0, self.n[a] - 1);
        }
        let range = |a: usize| {
            let lo = (centre[a] - 1).max(0);
            let hi = (centre[a] + 1).min(self.n[a] - 1);
            lo..=hi
        };
        let (rx, ry, rz) = (range(0), range(1), range(2));
        rx.flat_map(move |i| {
            let rz = rz.clone();
            ry.clone().flat_map(move |j| rz.clone().map(move |k| [i, j, k]))
        })
        .map(move |[i, j, k]| q - self.period * Vec3A::new(i as f32, j as f32, k as f32))
    }

    fn eval(&self, p: Vec3A, f: impl Fn(Vec3A) -> f32) -> f32 {
        self.cells(p).fold(f32::INFINITY, |a, q| a.min(f(q)))
    }

    fn eval_surf(&self, p: Vec3A, f: impl Fn(Vec3A) -> Surf) -> Surf {
        self.cells(p).map(f).fold(Surf { d: f32::INFINITY, g: Vec3A::Y, mat: 0 }, Surf::min)
    }
}
