//! 2D profiles and the sweeps that make solids of them: `circle`, `rect` and `polygon`
//! (exact signed distances in the `[u, v]` plane), `extrude` (POV-Ray's `prism`: `u`, `v`
//! are the solid's `x` and `z`, extruded along `y`) and `revolve` (POV-Ray's `lathe`: `u`,
//! `v` are the radius and the height, revolved about `y`). A profile is a field
//! expression of the point `[u, v, 0]`; a sweep substitutes the solid's point into it
//! and is a `field` with bound 1, exact where the profile is.

use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::domain::{bin, un};
use super::shapes::CsgArgs;
use super::BoundArgs;
use super::Profile;
use super::ProfileFn;
use super::{Host, Value};
use crate::diag::{codes, Diagnostic};
use crate::geom::region::{Combine, Region};
use crate::geom::DAabb;
use crate::ir::dump_num;
use crate::ir::field::{Binary, FieldExpr, FieldKind, FieldTy, Unary};
use crate::ir::{CsgOp, ExactMesh, Lipschitz, ShapeKind, Sweep};
use crate::sig::Range;
use crate::span::Span;
use crate::syntax::ast::TransformOp;

crate::params! {
    /// `circle(r)`.
    pub struct CircleArgs {
        /// the radius
        r: f64 as Num = required, Range::POSITIVE;
    }
}

crate::params! {
    /// `rect(half_u, half_v)`.
    pub struct RectArgs {
        /// half the width along `u`
        half_u: f64 as Num = required, Range::POSITIVE;
        /// half the height along `v`
        half_v: f64 as Num = required, Range::POSITIVE;
    }
}

crate::params! {
    /// `polygon(points)`.
    pub struct PolygonArgs {
        /// the corners `[[u, v], …]` in order, either winding; the last joins the first
        points: Value as List = required;
    }
}

crate::params! {
    /// `extrude(profile, half_height)`.
    pub struct ExtrudeArgs {
        /// the profile: its `u` and `v` are the solid's `x` and `z`
        profile: Value as Profile = required;
        /// the solid runs from `y = -half_height` to `y = half_height`
        half_height: f64 as Num = required, Range::POSITIVE;
    }
}

crate::params! {
    /// `revolve(profile)`.
    pub struct RevolveArgs {
        /// the profile: its `u` is the distance from the `y` axis, its `v` the height
        profile: Value as Profile = required;
    }
}

crate::params! {
    /// `round(profile, r)`.
    pub struct RoundProfileArgs {
        /// the profile to round
        profile: Value as Profile = required;
        /// how far the profile grows, rounding its corners by as much
        r: f64 as Num = required, Range::NONNEG;
    }
}

crate::params! {
    /// `shell(profile, thickness)`.
    pub struct ShellProfileArgs {
        /// the profile to hollow into an outline
        profile: Value as Profile = required;
        /// the outline's thickness, centred on the edge
        thickness: f64 as Num = required, Range::POSITIVE;
    }
}

/// Most corners of one polygon (its distance takes a few operations per edge).
pub const MAX_POLYGON_POINTS: usize = 1000;

fn vec2(a: Arc<FieldExpr>, b: Arc<FieldExpr>) -> Arc<FieldExpr> {
    FieldExpr::vector([a, b, FieldExpr::num(0.0)])
}

fn num(x: f64) -> Arc<FieldExpr> {
    FieldExpr::num(x)
}

/// `min(max(a, b), 0) + |[max(a, 0), max(b, 0)]|`: the exact distance of the
/// intersection of two slabs' distances `a` and `b` taken along orthogonal directions.
fn corner(a: &Arc<FieldExpr>, b: &Arc<FieldExpr>) -> Arc<FieldExpr> {
    let zero = num(0.0);
    let inside = bin(Binary::Min, &bin(Binary::Max, a, b), &zero);
    let outside = un(Unary::Length, &vec2(bin(Binary::Max, a, &zero), bin(Binary::Max, b, &zero)));
    bin(Binary::Add, &inside, &outside)
}

/// The region of `profile`, if it has one, moved by `f` (scaling by `k`).
fn moved_region(profile: &Profile, f: impl Fn(DVec2) -> DVec2, k: f64) -> Option<Arc<Region>> {
    profile.region.as_ref().map(|r| Arc::new(r.moved(&f, k)))
}

/// A disc's region.
fn disc(r: f64) -> Option<Arc<Region>> {
    Some(Arc::new(Region::Circle { centre: DVec2::ZERO, r }))
}

impl dyn Host + '_ {
    /// A profile builtin's value (a profile, or a sweep's shape), or poison after reporting.
    pub(crate) fn profile(&mut self, f: ProfileFn, a: &BoundArgs) -> Value {
        let p = FieldExpr::point();
        let (u, v) = (FieldExpr::component(&p, 0), FieldExpr::component(&p, 1));
        let made = match f {
            ProfileFn::Csg(op) => self.profile_csg(op, a),
            ProfileFn::Circle => {
                let CircleArgs { r } = CircleArgs::from_args(a);
                let body = bin(Binary::Sub, &un(Unary::Length, &p), &num(r));
                Some(Profile { body, region: disc(r), min: DVec2::splat(-r), max: DVec2::splat(r) })
            }
            ProfileFn::Rect => {
                let RectArgs { half_u, half_v } = RectArgs::from_args(a);
                let qu = bin(Binary::Sub, &un(Unary::Abs, &u), &num(half_u));
                let qv = bin(Binary::Sub, &un(Unary::Abs, &v), &num(half_v));
                let h = DVec2::new(half_u, half_v);
                let region = Some(Arc::new(Region::Polygon(vec![-h, DVec2::new(h.x, -h.y), h, DVec2::new(-h.x, h.y)])));
                Some(Profile { body: corner(&qu, &qv), region, min: -h, max: h })
            }
            ProfileFn::Polygon => {
                let PolygonArgs { points } = PolygonArgs::from_args(a);
                self.polygon(&points, a.span_of("points")).map(|(body, corners, min, max)| Profile {
                    body,
                    region: Some(Arc::new(Region::Polygon(corners))),
                    min,
                    max,
                })
            }
            ProfileFn::Round => {
                let RoundProfileArgs { profile: Value::Profile(inner), r } = RoundProfileArgs::from_args(a) else {
                    return Value::Error;
                };
                let body = bin(Binary::Sub, &inner.body, &num(r));
                // A grown disc is a disc; a grown polygon has arcs at its corners.
                let region = match inner.region.as_deref() {
                    Some(&Region::Circle { centre, r: rc }) => Some(Arc::new(Region::Circle { centre, r: rc + r })),
                    _ => None,
                };
                Some(Profile { body, region, min: inner.min - r, max: inner.max + r })
            }
            ProfileFn::Shell => {
                let ShellProfileArgs { profile: Value::Profile(inner), thickness: t } = ShellProfileArgs::from_args(a)
                else {
                    return Value::Error;
                };
                let body = bin(Binary::Sub, &un(Unary::Abs, &inner.body), &num(t / 2.0));
                // A disc's outline is a ring (a disc, when the hole closes up).
                let region = match inner.region.as_deref() {
                    Some(&Region::Circle { centre, r }) => {
                        let outer = Region::Circle { centre, r: r + t / 2.0 };
                        Some(Arc::new(if r > t / 2.0 {
                            Region::Csg(Combine::Subtract, vec![outer, Region::Circle { centre, r: r - t / 2.0 }])
                        } else {
                            outer
                        }))
                    }
                    _ => None,
                };
                Some(Profile { body, region, min: inner.min - t / 2.0, max: inner.max + t / 2.0 })
            }
            ProfileFn::Text => self.text(a),
            ProfileFn::Extrude | ProfileFn::Revolve => {
                return match self.sweep(f, a) {
                    Some(kind) => self.shape(Some(kind), a.call),
                    None => Value::Error,
                };
            }
        };
        made.map_or(Value::Error, |p| Value::Profile(Arc::new(p)))
    }

    /// A profile moved in its plane: `at [u, v]`, `rotate degrees` (counter-clockwise,
    /// from `u` towards `v`) or `scale k` (uniform, so the distance stays exact).
    ///
    /// Long because it is one match over the three moves, each with its checks, its
    /// distance and its region.
    pub(crate) fn transform_profile(
        &mut self,
        op: TransformOp,
        profile: &Profile,
        arg: &Value,
        arg_span: Span,
    ) -> Value {
        let p = FieldExpr::point();
        let (u, v) = (FieldExpr::component(&p, 0), FieldExpr::component(&p, 1));
        let two = match arg {
            Value::List(items) if items.len() == 2 => match (&items[0], &items[1]) {
                (Value::Num(a), Value::Num(b)) if a.is_finite() && b.is_finite() => Some(DVec2::new(*a, *b)),
                _ => None,
            },
            _ => None,
        };
        let made = match (op, arg, two) {
            (TransformOp::At, _, Some(d)) => {
                let moved = vec2(bin(Binary::Sub, &u, &num(d.x)), bin(Binary::Sub, &v, &num(d.y)));
                let region = moved_region(profile, |c| c + d, 1.0);
                Some(Profile {
                    body: profile.body.substitute(&moved),
                    region,
                    min: profile.min + d,
                    max: profile.max + d,
                })
            }
            (TransformOp::Rotate, Value::Num(deg), _) => {
                let (sin, cos) = deg.to_radians().sin_cos();
                // The point turned back by the angle, into the profile's own frame.
                let back = vec2(
                    bin(Binary::Add, &bin(Binary::Mul, &u, &num(cos)), &bin(Binary::Mul, &v, &num(sin))),
                    bin(Binary::Sub, &bin(Binary::Mul, &v, &num(cos)), &bin(Binary::Mul, &u, &num(sin))),
                );
                let turn = |c: DVec2| DVec2::new(c.x * cos - c.y * sin, c.x * sin + c.y * cos);
                let (lo, hi) = (profile.min, profile.max);
                let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)].map(turn);
                let min = corners.iter().fold(DVec2::INFINITY, |m, c| m.min(*c));
                let max = corners.iter().fold(DVec2::NEG_INFINITY, |m, c| m.max(*c));
                let region = moved_region(profile, turn, 1.0);
                Some(Profile { body: profile.body.substitute(&back), region, min, max })
            }
            (TransformOp::Scale, Value::Num(k), _) if *k > 0.0 && k.is_finite() => {
                let shrunk = vec2(bin(Binary::Div, &u, &num(*k)), bin(Binary::Div, &v, &num(*k)));
                let body = bin(Binary::Mul, &num(*k), &profile.body.substitute(&shrunk));
                let region = moved_region(profile, |c| c * *k, *k);
                Some(Profile { body, region, min: profile.min * *k, max: profile.max * *k })
            }
            _ => None,
        };
        if let Some(made) = made {
            return Value::Profile(Arc::new(made));
        }
        if let (TransformOp::Scale, Value::Num(k)) = (op, arg) {
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    arg_span,
                    "a profile's scale must be greater than 0",
                    format!("this is {}", crate::sig::short(*k)),
                )
                .with_note("a zero scale shrinks the profile to nothing; mirroring is not supported"),
            );
            return Value::Error;
        }
        let (expected, note) = match op {
            TransformOp::At => ("`[u, v]`", "a profile is placed in its plane by two numbers"),
            TransformOp::Rotate => ("`num`", "a profile turns in its plane by one angle, in degrees"),
            _ => ("`num`", "a profile scales uniformly, by one number, so its distance stays exact"),
        };
        self.report(
            Diagnostic::error(
                codes::TYPE_MISMATCH,
                arg_span,
                format!("expected {expected}, found `{}`", arg.ty_name()),
                arg.this_is(),
            )
            .with_note(note),
        );
        Value::Error
    }

    /// `union`, `intersect` or `subtract` of profiles: the min or max of their distances
    /// (Quilez's quadratic blend with `smooth`), a bound that is exact outside a union
    /// and inside an intersection; `None` after reporting.
    ///
    /// Long because it is one match over the three operations, sharp and smooth, each with
    /// its checks and its distance and region.
    fn profile_csg(&mut self, op: CsgOp, a: &BoundArgs) -> Option<Profile> {
        let name = op.name();
        let parts: Vec<Arc<Profile>> =
            a.rest.iter().filter_map(|(v, _)| if let Value::Profile(p) = v { Some(p.clone()) } else { None }).collect();
        if parts.len() != a.rest.len() {
            return None;
        }
        let Some((first, rest)) = parts.split_first() else {
            self.report(
                Diagnostic::error(codes::ARITY, a.call, format!("`{name}` needs at least one profile"), "none given")
                    .with_hint(format!("try `{name}(circle(1), rect(0.5, 2))`")),
            );
            return None;
        };
        if parts.len() > MAX_POLYGON_POINTS {
            self.report(
                Diagnostic::error(codes::TOO_LARGE, a.call, format!("`{name}` of too many profiles"), "here")
                    .with_note(format!("one operation may combine at most {MAX_POLYGON_POINTS} profiles")),
            );
            return None;
        }
        let CsgArgs { smooth: k } = CsgArgs::from_args(a);
        // max(k − |a − b|, 0)² / 4k: how far the blend moves the seam (at most k/4).
        let blend = |x: &Arc<FieldExpr>, y: &Arc<FieldExpr>| {
            let gap = bin(Binary::Sub, &num(k), &un(Unary::Abs, &bin(Binary::Sub, x, y)));
            let h = bin(Binary::Max, &gap, &num(0.0));
            bin(Binary::Div, &bin(Binary::Mul, &h, &h), &num(4.0 * k))
        };
        let combine = |x: &Arc<FieldExpr>, y: &Arc<FieldExpr>, outer: Binary| {
            let sharp = bin(outer, x, y);
            match (k > 0.0, outer) {
                (false, _) => sharp,
                (true, Binary::Min) => bin(Binary::Sub, &sharp, &blend(x, y)),
                (true, _) => bin(Binary::Add, &sharp, &blend(x, y)),
            }
        };
        let (mut body, mut min, mut max) = (first.body.clone(), first.min, first.max);
        for p in rest {
            match op {
                CsgOp::Union => {
                    body = combine(&body, &p.body, Binary::Min);
                    (min, max) = (min.min(p.min), max.max(p.max));
                }
                CsgOp::Intersect => {
                    body = combine(&body, &p.body, Binary::Max);
                    (min, max) = (min.max(p.min), max.min(p.max));
                }
                CsgOp::Subtract => body = combine(&body, &un(Unary::Neg, &p.body), Binary::Max),
            }
        }
        if op == CsgOp::Union {
            (min, max) = (min - k / 4.0, max + k / 4.0);
        }
        if min.cmpge(max).any() {
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    a.call,
                    "this intersection of profiles is empty",
                    "their boxes do not overlap",
                )
                .with_note("`intersect` keeps only what is inside every profile"),
            );
            return None;
        }
        // Boxes that overlap still leave nothing when the rest covers the first profile
        // (`subtract(rect(1, 1), circle(1.5))`) or the profiles miss each other inside
        // the shared box: interval arithmetic over the box proves it, or finds a place
        // that may be inside and lets the profile be.
        if op != CsgOp::Union && provably_empty(&body, min, max) {
            let (what, label, note) = match op {
                CsgOp::Subtract => (
                    "difference",
                    "the others cover the first profile",
                    "`subtract` keeps what is inside the first profile and outside the others",
                ),
                _ => (
                    "intersection",
                    "no point is inside every profile",
                    "`intersect` keeps only what is inside every profile",
                ),
            };
            self.report(
                Diagnostic::error(codes::OUT_OF_RANGE, a.call, format!("this {what} of profiles is empty"), label)
                    .with_note(note),
            );
            return None;
        }
        // A sharp combination of regions is the region of their combination.
        let regions: Option<Vec<Region>> = parts.iter().map(|p| p.region.as_deref().cloned()).collect();
        let region = regions.filter(|_| k == 0.0).map(|r| {
            let combine = match op {
                CsgOp::Union => Combine::Union,
                CsgOp::Intersect => Combine::Intersect,
                CsgOp::Subtract => Combine::Subtract,
            };
            Arc::new(Region::Csg(combine, r))
        });
        Some(Profile { body, region, min, max })
    }

    /// `extrude` or `revolve` as a field of the solid's point, or `None` after reporting.
    fn sweep(&mut self, f: ProfileFn, a: &BoundArgs) -> Option<ShapeKind> {
        let p = FieldExpr::point();
        let (x, y, z) = (FieldExpr::component(&p, 0), FieldExpr::component(&p, 1), FieldExpr::component(&p, 2));
        let exact = Lipschitz { value: 1.0, given: false };
        match f {
            ProfileFn::Extrude => {
                let ExtrudeArgs { profile: Value::Profile(profile), half_height: h } = ExtrudeArgs::from_args(a) else {
                    return None;
                };
                let d2 = profile.body.substitute(&vec2(x, z));
                let dy = bin(Binary::Sub, &un(Unary::Abs, &y), &num(h));
                let bounds = DAabb {
                    min: DVec3::new(profile.min.x, -h, profile.min.y),
                    max: DVec3::new(profile.max.x, h, profile.max.y),
                };
                // A polygon's prism is made once, here; any other region's at the detail
                // its circles are tessellated at.
                let mesh = profile.region.as_deref().map(|region| match region {
                    Region::Polygon(corners) => ExactMesh::Faces(Arc::new(crate::geom::polygon::prism(corners, h))),
                    _ => ExactMesh::Extrusion { region: Arc::new(region.clone()), half_height: h },
                });
                let sweep = profile.region.clone().map(|region| Sweep::Extrude { region, half_height: h });
                Some(ShapeKind::Field {
                    body: corner(&d2, &dy),
                    bounds: Some(bounds),
                    lipschitz: exact,
                    exact: mesh,
                    sweep,
                })
            }
            ProfileFn::Revolve => {
                let RevolveArgs { profile: Value::Profile(profile) } = RevolveArgs::from_args(a) else {
                    return None;
                };
                if profile.max.x <= 0.0 {
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            a.span_of("profile"),
                            "this profile has nothing to revolve",
                            format!("it lies at u ≤ 0 (up to u = {})", crate::sig::short(profile.max.x)),
                        )
                        .with_note("`revolve` turns the part of a profile at u > 0 (the radius) about the y axis")
                        .with_hint("move the profile to positive u"),
                    );
                    return None;
                }
                // The radius is never negative: a part of the profile at u < 0 is never
                // reached (it is clipped), and the distance stays a bound.
                let radius = un(Unary::Length, &FieldExpr::vector([x, num(0.0), z]));
                let body = profile.body.substitute(&vec2(radius, y));
                let r = profile.max.x;
                let bounds = DAabb { min: DVec3::new(-r, profile.min.y, -r), max: DVec3::new(r, profile.max.y, r) };
                // A polygon wholly at u ≥ 0 is tessellated as a lathe here.
                let lathe = match profile.region.as_deref() {
                    Some(Region::Polygon(corners)) if crate::geom::polygon::lathe_ok(corners) => {
                        Some(ExactMesh::Lathe(Arc::new(corners.clone())))
                    }
                    // A circle, a polygon cut by the axis, a region with holes: revolved at
                    // lowering, each outline clipped to u ≥ 0.
                    Some(region) => Some(ExactMesh::Revolution { region: Arc::new(region.clone()), radius: r }),
                    None => None,
                };
                let sweep = profile.region.clone().map(|region| Sweep::Revolve { region });
                Some(ShapeKind::Field { body, bounds: Some(bounds), lipschitz: exact, exact: lathe, sweep })
            }
            ProfileFn::Csg(_)
            | ProfileFn::Circle
            | ProfileFn::Rect
            | ProfileFn::Polygon
            | ProfileFn::Round
            | ProfileFn::Shell
            | ProfileFn::Text => None,
        }
    }

    /// A simple polygon's exact signed distance (Quilez's: the nearest edge, the sign by
    /// the crossing count), corners and box, or `None` after reporting a bad polygon.
    ///
    /// Long because it is the polygon's checks in the order they are reported (count,
    /// finiteness, repeated corners, crossings, each naming the corners) before its
    /// distance expression.
    fn polygon(&mut self, points: &Value, span: Span) -> Option<(Arc<FieldExpr>, Vec<DVec2>, DVec2, DVec2)> {
        let bad = |this: &mut Self, what: String, label: &str| {
            this.report(
                Diagnostic::error(codes::OUT_OF_RANGE, span, what, label)
                    .with_note("a polygon is three or more corners `[u, v]`, its edges meeting only at their ends"),
            );
            None
        };
        let Value::List(items) = points else { return None };
        let mut corners = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let xy = match item {
                Value::List(c) if c.len() == 2 => match (&c[0], &c[1]) {
                    (Value::Num(u), Value::Num(v)) if u.is_finite() && v.is_finite() => Some(DVec2::new(*u, *v)),
                    _ => None,
                },
                Value::Error => return None,
                _ => None,
            };
            let Some(xy) = xy else {
                return bad(self, format!("corner {} is not a point `[u, v]`", i + 1), "every corner is two numbers");
            };
            corners.push(xy);
        }
        let n = corners.len();
        if n < 3 {
            return bad(self, format!("a polygon needs 3 corners, this has {n}"), "too few corners");
        }
        if n > MAX_POLYGON_POINTS {
            return bad(self, format!("a polygon may have at most {MAX_POLYGON_POINTS} corners"), "too many corners");
        }
        let edge = |i: usize| (corners[i], corners[(i + 1) % n]);
        if let Some(i) = (0..n).find(|&i| edge(i).0 == edge(i).1) {
            let what = format!("edge {} has no length: corners {} and {} are equal", i + 1, i + 1, (i + 1) % n + 1);
            return bad(self, what, "a repeated corner");
        }
        for i in 0..n {
            let (a0, a1) = edge(i);
            for j in i + 1..n {
                // Neighbouring edges share a corner; they may only meet there.
                let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                let (b0, b1) = edge(j);
                let meet = if adjacent {
                    let shared = if j == i + 1 { a1 } else { a0 };
                    let (other_a, other_b) = if j == i + 1 { (a0, b1) } else { (a1, b0) };
                    // Folded back on itself: the two edges overlap beyond the shared corner.
                    (other_a - shared).perp_dot(other_b - shared) == 0.0
                        && (other_a - shared).dot(other_b - shared) > 0.0
                } else {
                    crate::geom::polygon::segments_meet(a0, a1, b0, b1)
                };
                if meet {
                    // Name each edge by its corners, index and place, so the crossing can be
                    // found in a list a comprehension made.
                    // Four decimals: enough to find the corner, short enough to read.
                    let c = |x: f64| dump_num((x * 1e4).round() / 1e4 + 0.0);
                    let corner = |k: usize| format!("{} [{}, {}]", k + 1, c(corners[k].x), c(corners[k].y));
                    let what = format!(
                        "edges {} and {} of the polygon cross: corners {} → {} and {} → {}",
                        i + 1,
                        j + 1,
                        corner(i),
                        corner((i + 1) % n),
                        corner(j),
                        corner((j + 1) % n)
                    );
                    return bad(self, what, "a polygon's edges may meet only at shared corners");
                }
            }
        }
        let area: f64 = (0..n).map(|i| corners[i].perp_dot(corners[(i + 1) % n])).sum::<f64>() / 2.0;
        if area == 0.0 {
            return bad(self, "the polygon has no area".into(), "its corners lie on a line");
        }
        let p = FieldExpr::point();
        let (u, v) = (FieldExpr::component(&p, 0), FieldExpr::component(&p, 1));
        let zero = num(0.0);
        let (mut d2, mut sign): (Option<Arc<FieldExpr>>, Arc<FieldExpr>) = (None, num(1.0));
        for i in 0..n {
            let (vi, vj) = (corners[i], corners[(i + n - 1) % n]);
            let e = vj - vi;
            // w = p − vi; b = w − e·clamp(w·e / e·e, 0, 1); the squared distance b·b.
            let (wu, wv) = (bin(Binary::Sub, &u, &num(vi.x)), bin(Binary::Sub, &v, &num(vi.y)));
            let t = bin(
                Binary::Div,
                &bin(Binary::Add, &bin(Binary::Mul, &wu, &num(e.x)), &bin(Binary::Mul, &wv, &num(e.y))),
                &num(e.dot(e)),
            );
            let t = bin(Binary::Min, &bin(Binary::Max, &t, &zero), &num(1.0));
            let (bu, bv) = (
                bin(Binary::Sub, &wu, &bin(Binary::Mul, &t, &num(e.x))),
                bin(Binary::Sub, &wv, &bin(Binary::Mul, &t, &num(e.y))),
            );
            let bb = bin(Binary::Add, &bin(Binary::Mul, &bu, &bu), &bin(Binary::Mul, &bv, &bv));
            d2 = Some(match d2 {
                Some(d) => bin(Binary::Min, &d, &bb),
                None => bb,
            });
            // The edge crosses the horizontal ray from p: the sign flips.
            let c1 = bin(Binary::Ge, &v, &num(vi.y));
            let c2 = bin(Binary::Lt, &v, &num(vj.y));
            let c3 = bin(Binary::Gt, &bin(Binary::Mul, &num(e.x), &wv), &bin(Binary::Mul, &num(e.y), &wu));
            let all = bin(Binary::And, &bin(Binary::And, &c1, &c2), &c3);
            let none =
                bin(Binary::And, &bin(Binary::And, &un(Unary::Not, &c1), &un(Unary::Not, &c2)), &un(Unary::Not, &c3));
            let flip = bin(Binary::Or, &all, &none);
            let factor = FieldExpr::new(FieldKind::Select(flip, num(-1.0), num(1.0)), FieldTy::Num);
            sign = bin(Binary::Mul, &sign, &factor);
        }
        let d = un(Unary::Sqrt, &d2.unwrap_or_else(|| num(0.0)));
        let body = bin(Binary::Mul, &sign, &d);
        let min = corners.iter().fold(DVec2::INFINITY, |m, c| m.min(*c));
        let max = corners.iter().fold(DVec2::NEG_INFINITY, |m, c| m.max(*c));
        Some((body, corners, min, max))
    }
}

/// Whether no point of the box `min`..`max` can be inside the profile `body`: the
/// branch-and-bound search that bounds fields' support rules out every box of it.
fn provably_empty(body: &Arc<FieldExpr>, min: DVec2, max: DVec2) -> bool {
    // A profile's body reads a point of its plane, z = 0: give it [x, y, 0], and the
    // box depth for the search's sake.
    let p = FieldExpr::point();
    let flat = body.substitute(&vec2(FieldExpr::component(&p, 0), FieldExpr::component(&p, 1)));
    let tape = crate::field::Tape::new(&flat);
    let b = DAabb { min: DVec3::new(min.x, min.y, -1.0), max: DVec3::new(max.x, max.y, 1.0) };
    crate::field::support_radius(&tape, b, 0.0, b.centre(), &crate::field::NoDistances).is_none()
}
