//! Builtin constructors: turn bound, type-checked arguments into values, checking ranges.
//! One exhaustive match per family over the builtin's [`Ctor`]: shapes, meshes, and
//! plain values (materials, colours, lights, numbers).

mod maths;
mod meshes;
mod shapes;
mod values;

use std::sync::Arc;

use glam::DVec3;

use super::builtins::{self, Builtin, Ctor, Kind, Ty};
use super::expr::{vec3, BoundArgs};
use super::{direction, Ctx, Value};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_num, dump_vec, Camera, Settings, ShapeKind};
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
/// The smallest relative hit threshold: a few f32 ulps (2⁻²³ ≈ 1.2e-7) of the distance
/// travelled, below which a march cannot get that close to a surface and ends as a miss.
pub const MIN_EPSILON: f64 = 1e-6;
/// How a bad `epsilon` is explained, in the scene and on the command line.
pub const EPSILON_RULE: &str = "at least 1e-6 (f32 cannot resolve less) and less than 1";
/// Most frames of an animation: an hour at 24 frames a second is 86,400.
pub const MAX_FRAMES: u32 = 1_000_000;
/// Highest frame rate.
pub const MAX_FPS: f64 = 1000.0;
/// Most copies per axis of `repeat`.
pub const MAX_REPEAT: u32 = 1_000;
/// Most nodes of one shape, shared parts counted each time they are used.
pub const MAX_SHAPE_NODES: u64 = 1_000_000;

/// The rule of sizes, radii and intensities that must be positive.
const POS: &str = "greater than 0";
/// The rule of quantities that may be zero.
const NONNEG: &str = "at least 0";

impl BoundArgs {
    fn value(&self, b: &Builtin, i: usize) -> Value {
        match &self.vals[i] {
            Some((v, _)) => v.clone(),
            None => match b.params[i].default {
                // A size's number default means a cube, as a number argument does.
                builtins::Default::Num(x) if b.params[i].ty == Ty::Size => Value::Vec3(DVec3::splat(x)),
                builtins::Default::Num(x) => Value::Num(x),
                builtins::Default::Vec3(v) => Value::Vec3(DVec3::from(v)),
                builtins::Default::Bool(x) => Value::Bool(x),
                builtins::Default::Color(c) => Value::Color(DVec3::from(c)),
                builtins::Default::Str(s) => Value::Str(s.into()),
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

    /// The shape value of a node made by a constructor, or `Value::Error` if it reported.
    fn shape(&mut self, kind: Option<ShapeKind>, span: Span) -> Value {
        kind.map_or(Value::Error, |kind| self.shape_value(kind, span))
    }

    /// The shape value of a new node, if its tree is not too large.
    pub(in crate::check) fn shape_value(&mut self, kind: ShapeKind, span: Span) -> Value {
        self.sized(Arc::new(ir::Shape::new(kind, span)))
    }

    /// `shape` as a value, or an error at its span when its tree, with shared parts
    /// counted each time they are used, has more than [`MAX_SHAPE_NODES`] nodes: every
    /// later stage walks the expanded tree, so a doubling `let` chain would otherwise
    /// build a small value that takes hours to lower.
    pub(in crate::check) fn sized(&mut self, shape: Arc<ir::Shape>) -> Value {
        if shape.nodes <= MAX_SHAPE_NODES {
            return Value::Shape(shape);
        }
        self.report(
            Diagnostic::error(
                codes::SHAPE_TOO_LARGE,
                shape.span,
                "this shape is too large",
                format!("it expands to {} nodes", shape.nodes),
            )
            .with_note(format!(
                "a shape may have at most {MAX_SHAPE_NODES} nodes, counting a shared part each time it is used"
            )),
        );
        Value::Error
    }

    /// Builds the value of a builtin call whose arguments are bound and well typed.
    pub(super) fn construct(&mut self, b: &Builtin, a: BoundArgs) -> Value {
        match b.ctor {
            Ctor::Primitive(p) => {
                let kind = self.primitive(b, p, &a).map(ShapeKind::Primitive);
                self.shape(kind, a.call)
            }
            Ctor::Csg(op) => {
                let kind = self.csg(b, op, &a);
                self.shape(kind, a.call)
            }
            Ctor::Modifier(m) => {
                let kind = self.modifier(b, m, &a);
                self.shape(kind, a.call)
            }
            Ctor::Material => self.material(b, &a),
            Ctor::Rgb => self.rgb(b, &a),
            Ctor::Pattern(f) => self.pattern(b, f, &a),
            Ctor::Light(l) => self.light(b, l, &a),
            Ctor::Math(f) => self.math(b, f, a.num(b, 0), a.span(0), a.call),
            Ctor::Numeric(f) => self.numeric(b, f, &a),
            Ctor::Vector(f) => self.vector(b, f, &a),
            Ctor::Extreme(e) => self.extreme(b, e, &a),
            Ctor::Len => match a.value(b, 0) {
                Value::List(items) => Value::Num(items.len() as f64),
                _ => Value::Error,
            },
            Ctor::Generator(g) => self.mesh(b, g, a),
            Ctor::Camera | Ctor::Render => {
                // Statement argument lists are bound by `camera_stmt` and `render_stmt`;
                // no expression can name them, but say so rather than lose the value.
                self.report(Diagnostic::error(
                    codes::UNKNOWN_FUNCTION,
                    a.call,
                    format!("`{}(…)` is a statement, not an expression", b.name),
                    "used as a value here",
                ));
                Value::Error
            }
        }
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
        let ok_eps = self.check_num(&a, b, 4, |e| (MIN_EPSILON..1.0).contains(&e), EPSILON_RULE);
        let steps = self.check_int(&a, b, 5, 1, MAX_STEPS);
        let ok_dist = self.check_num(&a, b, 6, |d| d > 0.0 && d <= super::MAX_REACH, "greater than 0 and at most 1e15");
        let samples = self.check_int(&a, b, 7, 1, MAX_SAMPLES);
        let ok_ao = self.check_num(&a, b, 8, |d| d >= 0.0, "at least 0 (0 turns it off)");
        let frames = self.check_int(&a, b, 9, 1, MAX_FRAMES);
        let ok_fps = self.check_num(&a, b, 10, |f| f > 0.0 && f <= MAX_FPS, "greater than 0 and at most 1000");
        let (Some(width), Some(height), Some(depth), true, Some(max_steps), true, Some(samples), Some(frames)) =
            (width, height, depth, ok_eps && ok_ao && ok_fps, steps, ok_dist, samples, frames)
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
        let color = match a.value(b, 12) {
            Value::Str(s) if &*s == "linear" => ir::ColorSpace::Linear,
            Value::Str(s) if &*s == "srgb" => ir::ColorSpace::Srgb,
            Value::Str(s) => {
                self.report(
                    Diagnostic::error(
                        codes::OUT_OF_RANGE,
                        a.span(12),
                        "`color` must be \"linear\" or \"srgb\"",
                        format!("this is {:?}", &*s),
                    )
                    .with_note("\"linear\" shades colours as written (the study's); \"srgb\" reads them as sRGB and shades in linear light"),
                );
                return None;
            }
            _ => return None,
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
            frames,
            fps: a.num(b, 10),
            cyclic: a.flag(b, 11),
            color,
            span: Some(span),
        })
    }
}
