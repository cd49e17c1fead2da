//! Builtin constructors: turn bound, type-checked arguments into values, checking ranges.

use std::sync::Arc;

use glam::{DAffine3, DVec3};

use super::builtins::{self, Builtin, Kind};
use super::expr::{vec3, BoundArgs};
use super::{direction, Ctx, Value};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_num, dump_vec, Camera, Material, MeshSource, Settings, ShapeKind};
use crate::span::Span;
use crate::syntax::ast;

/// Largest rings/segments/sides of a mesh generator.
pub const MAX_MESH_RESOLUTION: u32 = 16_384;
/// Most triangles one mesh generator may make.
pub const MAX_GENERATED_TRIANGLES: u64 = 50_000_000;
/// Largest image side in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16_384;
/// Most pixels in an image.
pub const MAX_PIXELS: u64 = 100_000_000;
/// Deepest reflection recursion.
pub const MAX_DEPTH: u32 = 64;
/// Most samples per pixel.
pub const MAX_SAMPLES: u32 = 256;
/// Largest sphere-tracing step budget.
pub const MAX_STEPS: u32 = 1_000_000;
/// Most copies per axis of `repeat`.
pub const MAX_REPEAT: u32 = 1_000;

impl BoundArgs {
    fn value(&self, b: &Builtin, i: usize) -> Value {
        match &self.vals[i] {
            Some((v, _)) => v.clone(),
            None => match b.params[i].default {
                builtins::Default::Num(x) => Value::Num(x),
                builtins::Default::Vec3(v) => Value::Vec3(DVec3::from(v)),
                builtins::Default::Bool(x) => Value::Bool(x),
                builtins::Default::Color(c) => Value::Color(DVec3::from(c)),
                builtins::Default::Required | builtins::Default::Derived => Value::Error,
            },
        }
    }

    fn num(&self, b: &Builtin, i: usize) -> f64 {
        match self.value(b, i) {
            Value::Num(x) => x,
            _ => 0.0,
        }
    }

    fn vec(&self, b: &Builtin, i: usize) -> DVec3 {
        vec3(&self.value(b, i))
    }

    fn flag(&self, b: &Builtin, i: usize) -> bool {
        matches!(self.value(b, i), Value::Bool(true))
    }

    fn given(&self, i: usize) -> bool {
        self.vals[i].is_some()
    }

    /// The span to blame for parameter `i`: its argument, or the whole call for a default.
    fn span(&self, i: usize) -> Span {
        self.vals[i].as_ref().map_or(self.call, |(_, s)| *s)
    }
}

/// One range rule violated.
struct Range<'a> {
    name: &'a str,
    rule: &'a str,
}

impl Ctx<'_> {
    fn range_error(&mut self, span: Span, r: Range<'_>, shown: String) {
        self.report(Diagnostic::error(
            codes::OUT_OF_RANGE,
            span,
            format!("`{}` must be {}", r.name, r.rule),
            format!("this is {shown}"),
        ));
    }

    /// Checks `ok` for parameter `i`; reports and returns false otherwise.
    fn check_num(&mut self, bound: &BoundArgs, b: &Builtin, i: usize, ok: impl Fn(f64) -> bool, rule: &str) -> bool {
        let x = bound.num(b, i);
        if ok(x) {
            return true;
        }
        self.range_error(bound.span(i), Range { name: b.params[i].name, rule }, dump_num(x));
        false
    }

    fn check_vec(&mut self, bound: &BoundArgs, b: &Builtin, i: usize, ok: impl Fn(f64) -> bool, rule: &str) -> bool {
        let v = bound.vec(b, i);
        if ok(v.x) && ok(v.y) && ok(v.z) {
            return true;
        }
        self.range_error(bound.span(i), Range { name: b.params[i].name, rule }, dump_vec(v));
        false
    }

    fn check_int(&mut self, bound: &BoundArgs, b: &Builtin, i: usize, lo: u32, hi: u32) -> Option<u32> {
        let rule = format!("between {lo} and {hi}");
        self.check_num(bound, b, i, |x| x >= lo as f64 && x <= hi as f64, &rule).then(|| bound.num(b, i) as u32)
    }

    fn shape(kind: ShapeKind, span: Span) -> Value {
        Value::Shape(Arc::new(ir::Shape { kind, span }))
    }

    /// Builds the value of a builtin call whose arguments are bound and well typed.
    pub(super) fn construct(&mut self, b: &Builtin, a: BoundArgs) -> Value {
        let span = a.call;
        let pos = |x: f64| x > 0.0;
        let nonneg = |x: f64| x >= 0.0;
        const POS: &str = "greater than 0";
        const NONNEG: &str = "at least 0";
        if b.kind == Kind::MeshGenerator {
            return self.mesh(b, a);
        }
        match b.name {
            "sphere" => {
                if !self.check_num(&a, b, 0, pos, POS) {
                    return Value::Error;
                }
                Self::shape(ShapeKind::Sphere { radius: a.num(b, 0) }, span)
            }
            "box" => {
                if !self.check_vec(&a, b, 0, pos, POS) {
                    return Value::Error;
                }
                Self::shape(ShapeKind::Box { half: a.vec(b, 0) }, span)
            }
            "cylinder" | "capsule" | "cone" | "torus" => {
                let ok0 = self.check_num(&a, b, 0, pos, POS);
                let ok1 = self.check_num(&a, b, 1, pos, POS);
                if !(ok0 && ok1) {
                    return Value::Error;
                }
                let (x, y) = (a.num(b, 0), a.num(b, 1));
                let kind = match b.name {
                    "cylinder" => ShapeKind::Cylinder { radius: x, half_height: y },
                    "capsule" => ShapeKind::Capsule { radius: x, half_height: y },
                    "cone" => ShapeKind::Cone { radius: x, half_height: y },
                    _ => ShapeKind::Torus { major: x, minor: y },
                };
                Self::shape(kind, span)
            }
            "plane" => {
                let Some(normal) = direction(a.vec(b, 0)) else {
                    self.range_error(
                        a.span(0),
                        Range { name: "normal", rule: "a non-zero vector" },
                        dump_vec(a.vec(b, 0)),
                    );
                    return Value::Error;
                };
                Self::shape(ShapeKind::Plane { normal, offset: a.num(b, 1) }, span)
            }
            "union" | "intersect" | "subtract" => {
                if a.rest.is_empty() {
                    self.report(
                        Diagnostic::error(
                            codes::ARITY,
                            span,
                            format!("`{}` needs at least one shape", b.name),
                            "no shapes given",
                        )
                        .with_hint(format!("try `{}(sphere(1), box(1))`", b.name)),
                    );
                    return Value::Error;
                }
                if !self.check_num(&a, b, 0, nonneg, NONNEG) {
                    return Value::Error;
                }
                let children = a
                    .rest
                    .iter()
                    .filter_map(|(v, _)| if let Value::Shape(s) = v { Some(s.clone()) } else { None })
                    .collect();
                let smooth = a.num(b, 0);
                let kind = match b.name {
                    "union" => ShapeKind::Union { children, smooth },
                    "intersect" => ShapeKind::Intersect { children, smooth },
                    _ => ShapeKind::Subtract { children, smooth },
                };
                Self::shape(kind, span)
            }
            "round" | "shell" => {
                let Value::Shape(child) = a.value(b, 0) else {
                    return Value::Error;
                };
                if b.name == "round" {
                    if !self.check_num(&a, b, 1, nonneg, NONNEG) {
                        return Value::Error;
                    }
                    Self::shape(ShapeKind::Round { child, radius: a.num(b, 1) }, span)
                } else {
                    if !self.check_num(&a, b, 1, pos, POS) {
                        return Value::Error;
                    }
                    Self::shape(ShapeKind::Shell { child, thickness: a.num(b, 1) }, span)
                }
            }
            "repeat" => {
                let Value::Shape(child) = a.value(b, 0) else {
                    return Value::Error;
                };
                let ok_period = self.check_vec(&a, b, 1, pos, POS);
                let rule = format!("whole numbers between 1 and {MAX_REPEAT}");
                let ok_count =
                    self.check_vec(&a, b, 2, |x| x.fract() == 0.0 && (1.0..=MAX_REPEAT as f64).contains(&x), &rule);
                if !(ok_period && ok_count) {
                    return Value::Error;
                }
                let c = a.vec(b, 2);
                let count = [c.x as u32, c.y as u32, c.z as u32];
                Self::shape(ShapeKind::Repeat { child, period: a.vec(b, 1), count }, span)
            }
            "material" => {
                let spec = a.num(b, 1);
                let ok_spec = self.check_num(&a, b, 1, |s| s == -1.0 || s >= 0.0, "-1 (no highlight) or at least 0");
                let ok_refl = self.check_num(&a, b, 2, |r| (0.0..=1.0).contains(&r), "between 0 and 1");
                if !(ok_spec && ok_refl) {
                    return Value::Error;
                }
                let Value::Color(color) = a.value(b, 0) else {
                    return Value::Error;
                };
                Value::Material(Arc::new(Material {
                    color,
                    specular: (spec >= 0.0).then_some(spec),
                    reflective: a.num(b, 2),
                    span,
                }))
            }
            "rgb" => {
                let mut ok = true;
                for i in 0..3 {
                    ok &= self.check_num(&a, b, i, |x| (0.0..=255.0).contains(&x), "between 0 and 255");
                }
                if !ok {
                    return Value::Error;
                }
                Value::Color(DVec3::new(a.num(b, 0), a.num(b, 1), a.num(b, 2)))
            }
            "ambient" | "point" | "directional" => {
                if !self.check_num(&a, b, 0, nonneg, NONNEG) {
                    return Value::Error;
                }
                let intensity = a.num(b, 0);
                let (kind, shadows, radius) = match b.name {
                    "ambient" => (ir::LightKind::Ambient, false, 0.0),
                    "point" => {
                        if !self.check_num(&a, b, 2, nonneg, NONNEG) {
                            return Value::Error;
                        }
                        (ir::LightKind::Point { position: DVec3::ZERO }, a.flag(b, 1), a.num(b, 2))
                    }
                    _ => {
                        let towards = a.vec(b, 1);
                        if direction(towards).is_none() {
                            self.range_error(
                                a.span(1),
                                Range { name: "towards", rule: "a non-zero vector" },
                                dump_vec(towards),
                            );
                            return Value::Error;
                        }
                        (ir::LightKind::Directional { towards }, a.flag(b, 2), 0.0)
                    }
                };
                Value::Light(Arc::new(ir::Light { kind, intensity, shadows, radius, span }))
            }
            "sin" | "cos" | "tan" | "sqrt" | "abs" | "floor" => {
                let x = a.num(b, 0);
                let r = x.to_radians();
                let y = match b.name {
                    "sin" => r.sin(),
                    "cos" => r.cos(),
                    "tan" => r.tan(),
                    "sqrt" => {
                        if !self.check_num(&a, b, 0, nonneg, NONNEG) {
                            return Value::Error;
                        }
                        x.sqrt()
                    }
                    "abs" => x.abs(),
                    _ => x.floor(),
                };
                Value::Num(y)
            }
            "min" | "max" => {
                if a.rest.is_empty() {
                    self.report(Diagnostic::error(
                        codes::ARITY,
                        span,
                        format!("`{}` needs at least one number", b.name),
                        "no numbers given",
                    ));
                    return Value::Error;
                }
                let nums = a.rest.iter().map(|(v, _)| if let Value::Num(x) = v { *x } else { 0.0 });
                Value::Num(if b.name == "min" {
                    nums.fold(f64::INFINITY, f64::min)
                } else {
                    nums.fold(f64::NEG_INFINITY, f64::max)
                })
            }
            "len" => match a.value(b, 0) {
                Value::List(items) => Value::Num(items.len() as f64),
                _ => Value::Error,
            },
            _ => Value::Error,
        }
    }

    fn mesh(&mut self, b: &Builtin, a: BoundArgs) -> Value {
        let pos = |x: f64| x > 0.0;
        const POS: &str = "greater than 0";
        let smooth_idx = b.params.iter().position(|p| p.name == "smooth").unwrap_or(0);
        let res = MAX_MESH_RESOLUTION;
        let source = match b.name {
            "uvsphere" => {
                let ok_r = self.check_num(&a, b, 0, pos, POS);
                let rings = self.check_int(&a, b, 1, 3, res);
                let segments = if a.given(2) { self.check_int(&a, b, 2, 3, res) } else { rings.map(|r| 2 * r) };
                let (true, Some(rings), Some(segments)) = (ok_r, rings, segments) else {
                    return Value::Error;
                };
                if !self.triangle_budget(2 * rings as u64 * segments as u64, a.call) {
                    return Value::Error;
                }
                MeshSource::UvSphere { radius: a.num(b, 0), rings, segments }
            }
            "icosphere" => {
                let ok_r = self.check_num(&a, b, 0, pos, POS);
                let (true, Some(subdivisions)) = (ok_r, self.check_int(&a, b, 1, 0, 10)) else {
                    return Value::Error;
                };
                MeshSource::IcoSphere { radius: a.num(b, 0), subdivisions }
            }
            "box" => {
                if !self.check_vec(&a, b, 0, pos, POS) {
                    return Value::Error;
                }
                MeshSource::Box { half: a.vec(b, 0) }
            }
            "cylinder" => {
                let ok = self.check_num(&a, b, 0, pos, POS) & self.check_num(&a, b, 1, pos, POS);
                let (true, Some(segments)) = (ok, self.check_int(&a, b, 2, 3, res)) else {
                    return Value::Error;
                };
                MeshSource::Cylinder { radius: a.num(b, 0), half_height: a.num(b, 1), segments }
            }
            "torus" => {
                let ok = self.check_num(&a, b, 0, pos, POS) & self.check_num(&a, b, 1, pos, POS);
                let segments = self.check_int(&a, b, 2, 3, res);
                let sides = self.check_int(&a, b, 3, 3, res);
                let (true, Some(segments), Some(sides)) = (ok, segments, sides) else {
                    return Value::Error;
                };
                if !self.triangle_budget(2 * segments as u64 * sides as u64, a.call) {
                    return Value::Error;
                }
                MeshSource::Torus { major: a.num(b, 0), minor: a.num(b, 1), segments, sides }
            }
            "plane" => {
                if !self.check_num(&a, b, 0, pos, POS) {
                    return Value::Error;
                }
                MeshSource::Plane { size: a.num(b, 0) }
            }
            "isosurface" => {
                let Value::Shape(shape) = a.value(b, 0) else {
                    return Value::Error;
                };
                if !self.check_num(&a, b, 1, pos, POS) {
                    return Value::Error;
                }
                MeshSource::Isosurface { shape, cell: a.num(b, 1) }
            }
            "file" => {
                let Value::Str(written) = a.value(b, 0) else {
                    return Value::Error;
                };
                MeshSource::File { path: self.dir.join(&*written), written: written.to_string() }
            }
            _ => return Value::Error,
        };
        Value::Mesh(Arc::new(ir::Mesh {
            source,
            xf: DAffine3::IDENTITY,
            material: None,
            smooth: a.flag(b, smooth_idx),
            span: a.call,
        }))
    }

    fn triangle_budget(&mut self, triangles: u64, span: Span) -> bool {
        if triangles <= MAX_GENERATED_TRIANGLES {
            return true;
        }
        self.report(
            Diagnostic::error(
                codes::TOO_LARGE,
                span,
                "mesh has too many triangles",
                format!("this makes {triangles} triangles"),
            )
            .with_note(format!("one mesh may have at most {MAX_GENERATED_TRIANGLES} triangles")),
        );
        false
    }

    fn statement_args(&mut self, name: &str, args: &[ast::Arg], span: Span) -> Option<(&'static Builtin, BoundArgs)> {
        let kind = if name == "camera" { Kind::Camera } else { Kind::Render };
        let b = builtins::lookup(name, kind)?;
        let vals = args
            .iter()
            .map(|arg| super::expr::ArgVal {
                name: arg.name.clone(),
                value: self.expr(&arg.value),
                span: arg.name.as_ref().map_or(arg.value.span, |n| n.span.to(arg.value.span)),
            })
            .collect();
        let bound = self.bind_builtin(b, vals, span)?;
        Some((b, bound))
    }

    pub(super) fn camera_stmt(&mut self, args: &[ast::Arg], span: Span) -> Option<Camera> {
        let (b, a) = self.statement_args("camera", args, span)?;
        let (position, look_at, up) = (a.vec(b, 0), a.vec(b, 1), a.vec(b, 2));
        let mut ok = self.check_num(&a, b, 3, |f| f > 0.0 && f < 180.0, "between 0 and 180 (exclusive)");
        let view = direction(look_at - position);
        if view.is_none() {
            self.report(
                Diagnostic::error(
                    codes::BAD_CAMERA,
                    a.span(1),
                    "the camera looks at its own position",
                    "`look_at` equals `position`",
                )
                .with_label(a.span(0), "the camera is here")
                .with_hint("try moving `look_at` away from `position`"),
            );
            ok = false;
        }
        match (view, direction(up)) {
            (_, None) => {
                self.range_error(a.span(2), Range { name: "up", rule: "a non-zero vector" }, dump_vec(up));
                ok = false;
            }
            (Some(v), Some(u)) if v.cross(u).length() < 1e-9 => {
                self.report(
                    Diagnostic::error(
                        codes::BAD_CAMERA,
                        a.span(2),
                        "`up` is parallel to the view direction",
                        "this points along the view",
                    )
                    .with_note("the camera cannot tell which way is up")
                    .with_hint("try `up = [0, 1, 0]`, or `[0, 0, 1]` when looking straight up or down"),
                );
                ok = false;
            }
            _ => {}
        }
        ok.then(|| Camera { position, look_at, up, fov: a.num(b, 3), span: Some(span) })
    }

    pub(super) fn render_stmt(&mut self, args: &[ast::Arg], span: Span) -> Option<Settings> {
        let (b, a) = self.statement_args("render", args, span)?;
        let width = self.check_int(&a, b, 0, 1, MAX_IMAGE_SIDE);
        let height = self.check_int(&a, b, 1, 1, MAX_IMAGE_SIDE);
        let depth = self.check_int(&a, b, 2, 0, MAX_DEPTH);
        let ok_eps = self.check_num(&a, b, 4, |e| e > 0.0 && e < 1.0, "between 0 and 1 (exclusive)");
        let steps = self.check_int(&a, b, 5, 1, MAX_STEPS);
        let ok_dist = self.check_num(&a, b, 6, |d| d > 0.0, "greater than 0");
        let samples = self.check_int(&a, b, 7, 1, MAX_SAMPLES);
        let ok_ao = self.check_num(&a, b, 8, |d| d >= 0.0, "at least 0 (0 turns it off)");
        let (Some(width), Some(height), Some(depth), true, Some(max_steps), true, Some(samples)) =
            (width, height, depth, ok_eps && ok_ao, steps, ok_dist, samples)
        else {
            return None;
        };
        if width as u64 * height as u64 > MAX_PIXELS {
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    span,
                    "image is too large",
                    format!("{width}×{height} is {} pixels", width as u64 * height as u64),
                )
                .with_note(format!("an image may have at most {MAX_PIXELS} pixels")),
            );
            return None;
        }
        let Value::Color(background) = a.value(b, 3) else {
            return None;
        };
        Some(Settings {
            width,
            height,
            depth,
            background,
            epsilon: a.num(b, 4),
            max_steps,
            max_distance: a.num(b, 6),
            samples,
            ambient_occlusion: a.num(b, 8),
            span: Some(span),
        })
    }
}
