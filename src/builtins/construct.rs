//! Builtin constructors: turn bound, type-checked, range-checked arguments into values.
//! One exhaustive match per family over the builtin's [`Ctor`]: shapes, meshes, and
//! plain values (materials, colours, lights, numbers). Each family declares its
//! builtins' parameters with [`params!`](crate::params) and reads them as typed fields.

use std::sync::Arc;

use glam::DVec3;

use super::{direction, maths, BoundArgs, Builtin, Ctor, FieldFn, Host, Ty, Value};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_num, dump_vec, Camera, Settings, ShapeKind};
use crate::sig::{self, Args, FromArg, Param, Range};
use crate::span::Span;

/// Most objects in a scene.
pub const MAX_OBJECTS: usize = 100_000;
/// Longest list.
pub const MAX_LIST: usize = 100_000;
/// Farthest any part of the scene may reach from the camera, in world units.
pub const MAX_REACH: f64 = 1e15;
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
/// Most bounces of a light-transport path (Russian roulette ends most far sooner).
pub const MAX_BOUNCES: u32 = 1024;
/// Most samples per pixel: enough for light transport's converged references (a
/// render is interruptible, and each sample a pure function of its index).
pub const MAX_SAMPLES: u32 = 1 << 20;
/// Largest sphere-tracing step budget.
pub const MAX_STEPS: u32 = 1_000_000;
/// The smallest relative hit threshold: a few f32 ulps (2⁻²³ ≈ 1.2e-7) of the distance
/// travelled, below which a march cannot get that close to a surface and ends as a miss.
pub const MIN_EPSILON: f64 = 1e-6;
/// The values `epsilon` takes, in the scene and on the command line.
pub const EPSILON_RANGE: Range = Range::ge_lt(MIN_EPSILON, 1.0);
/// Most frames of an animation: an hour at 24 frames a second is 86,400.
pub const MAX_FRAMES: u32 = 1_000_000;
/// Highest frame rate.
pub const MAX_FPS: f64 = 1000.0;
/// Most copies per axis of `repeat`.
pub const MAX_REPEAT: u32 = 1_000;
/// Most nodes of one shape, shared parts counted each time they are used.
pub const MAX_SHAPE_NODES: u64 = 1_000_000;

impl BoundArgs {
    /// The value of slot `i`: the argument given, or the parameter's default (poison for
    /// one that has none: a required argument's absence was reported when binding).
    pub(crate) fn value(&self, i: usize) -> Value {
        match &self.vals[i] {
            Some((v, _)) => v.clone(),
            None => match self.params[i].default {
                // A size's number default means a cube, as a number argument does.
                sig::Default::Num(x) if self.params[i].ty == Ty::Size => Value::Vec3(DVec3::splat(x)),
                sig::Default::Num(x) => Value::Num(x),
                sig::Default::Vec3(v) => Value::Vec3(DVec3::from(v)),
                sig::Default::Bool(x) => Value::Bool(x),
                sig::Default::Color(c) => Value::Color(DVec3::from(c)),
                sig::Default::Str(s) => Value::Str(s.into()),
                sig::Default::Required | sig::Default::Derived => Value::Error,
            },
        }
    }

    /// The slot of the parameter `name` (a name of the builtin's own declaration).
    pub(crate) fn slot(&self, name: &str) -> Option<usize> {
        let slot = self.params.iter().position(|p| p.name == name);
        debug_assert!(slot.is_some(), "no parameter `{name}`");
        slot
    }

    /// The span to blame for parameter `name`: its argument, or the whole call for a default.
    pub(crate) fn span_of(&self, name: &str) -> Span {
        self.slot(name).and_then(|i| self.vals[i].as_ref()).map_or(self.call, |(_, s)| *s)
    }

    /// Whether parameter `name` was given.
    pub(crate) fn was_given(&self, name: &str) -> bool {
        self.slot(name).is_some_and(|i| self.vals[i].is_some())
    }
}

impl Args for BoundArgs {
    fn num(&self, i: usize) -> f64 {
        match self.value(i) {
            Value::Num(x) => x,
            _ => 0.0,
        }
    }

    fn vec3(&self, i: usize) -> DVec3 {
        match self.value(i) {
            Value::Vec3(v) | Value::Color(v) => v,
            Value::Num(x) => DVec3::splat(x),
            _ => DVec3::ZERO,
        }
    }

    fn flag(&self, i: usize) -> bool {
        matches!(self.value(i), Value::Bool(true))
    }

    fn text(&self, i: usize) -> String {
        match self.value(i) {
            Value::Str(s) => s.to_string(),
            _ => String::new(),
        }
    }

    fn given(&self, i: usize) -> bool {
        self.vals[i].is_some()
    }
}

/// A parameter whose value stays a language value: a shape, a paint, a list, or one of
/// several types (`mix`'s operands). Its type was checked when binding.
impl FromArg<BoundArgs> for Value {
    fn from_arg(a: &BoundArgs, i: usize) -> Value {
        a.value(i)
    }
}

impl dyn Host + '_ {
    /// `v`, or poison after reporting at `span` that a number in it overflowed (E0401);
    /// `message` is formatted only then.
    pub(crate) fn finite(&mut self, v: Value, span: Span, message: impl FnOnce() -> String) -> Value {
        if v.is_finite() {
            return v;
        }
        self.report(Diagnostic::error(codes::NOT_FINITE, span, message(), "the result is not a finite number"));
        Value::Error
    }

    /// Reports a list over [`MAX_LIST`] elements at `span`, `label` saying how long.
    pub(crate) fn list_too_long(&mut self, span: Span, label: String) {
        self.report(
            Diagnostic::error(codes::TOO_LARGE, span, "list is too long", label)
                .with_note(format!("lists may hold at most {MAX_LIST} elements")),
        );
    }

    /// Reports that parameter `name`, at `span`, breaks `rule`; `shown` is its value.
    pub(super) fn range_error(&mut self, span: Span, name: &str, rule: &str, shown: String) {
        self.report(Diagnostic::error(
            codes::OUT_OF_RANGE,
            span,
            format!("`{name}` must be {rule}"),
            format!("this is {shown}"),
        ));
    }

    /// Whether the value given for `p` at `span` is in its declared range; reports it
    /// when not.
    pub(crate) fn in_range(&mut self, p: &Param, v: &Value, span: Span) -> bool {
        let (ok, shown) = match v {
            Value::Num(x) => (p.range.admits(*x), dump_num(*x)),
            Value::Vec3(v) | Value::Color(v) => (p.range.admits_vec(*v), dump_vec(*v)),
            _ => return true,
        };
        if !ok {
            self.range_error(span, p.name, &p.range.rule(p.is_vector()), shown);
        }
        ok
    }

    /// The shape value of a node made by a constructor, or `Value::Error` if it reported.
    pub(super) fn shape(&mut self, kind: Option<ShapeKind>, span: Span) -> Value {
        kind.map_or(Value::Error, |kind| self.shape_value(kind, span))
    }

    /// The shape value of a new node, if its tree is not too large.
    pub(crate) fn shape_value(&mut self, kind: ShapeKind, span: Span) -> Value {
        self.sized(Arc::new(ir::Shape::new(kind, span)))
    }

    /// `shape` as a value, or an error at its span when its tree, with shared parts
    /// counted each time they are used, has more than [`MAX_SHAPE_NODES`] nodes: every
    /// later stage walks the expanded tree, so a doubling `let` chain would otherwise
    /// build a small value that takes hours to lower.
    pub(crate) fn sized(&mut self, shape: Arc<ir::Shape>) -> Value {
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
    pub(crate) fn construct(&mut self, b: &Builtin, a: BoundArgs) -> Value {
        match b.ctor {
            Ctor::Primitive(p) => {
                let kind = self.primitive(p, &a).map(ShapeKind::Primitive);
                self.shape(kind, a.call)
            }
            Ctor::Csg(op) => {
                let kind = self.csg(b, op, &a);
                self.shape(kind, a.call)
            }
            Ctor::Modifier(m) => {
                let kind = self.modifier(m, &a);
                self.shape(kind, a.call)
            }
            Ctor::Field(f @ (FieldFn::Field | FieldFn::Warp | FieldFn::Displace)) => {
                let kind = self.field_shape(f, &a);
                self.shape(kind, a.call)
            }
            Ctor::Field(f) => {
                let kind = self.domain_shape(f, &a, a.call);
                self.shape(kind, a.call)
            }
            Ctor::Profile(f) => self.profile(f, &a),
            Ctor::Dist => self.dist(&a),
            Ctor::Noise3 => self.noise3(&a),
            Ctor::Material => self.material(&a),
            Ctor::Rgb => self.rgb(&a),
            Ctor::Pattern(f) => self.pattern(f, &a),
            Ctor::Light(l) => self.light(l, &a),
            Ctor::Math(f) => {
                // A function of one number, whatever its parameter is called.
                let x = maths::OneNumber::from_args(&a).x;
                let span = a.vals[0].as_ref().map_or(a.call, |(_, s)| *s);
                self.math(b, f, x, span, a.call)
            }
            Ctor::Numeric(f) => self.numeric(b, f, &a),
            Ctor::Vector(f) => self.vector(b, f, &a),
            Ctor::Extreme(e) => self.extreme(b, e, &a),
            Ctor::Len => match maths::ListArgs::from_args(&a).list {
                Value::List(items) => Value::Num(items.len() as f64),
                _ => Value::Error,
            },
            Ctor::Generator(g) => self.mesh(g, a),
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

    pub(super) fn triangle_budget(&mut self, triangles: u64, span: Span) -> bool {
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

    /// The camera of a `camera` statement whose arguments are bound.
    pub(crate) fn camera(&mut self, a: &BoundArgs, span: Span) -> Option<Camera> {
        let CameraArgs { position, look_at, up, fov, aperture, focus_distance } = CameraArgs::from_args(a);
        let mut ok = true;
        let view = direction(look_at - position);
        if view.is_none() {
            self.report(
                Diagnostic::error(
                    codes::BAD_CAMERA,
                    a.span_of("look_at"),
                    "the camera looks at its own position",
                    "`look_at` equals `position`",
                )
                .with_label(a.span_of("position"), "the camera is here")
                .with_hint("try moving `look_at` away from `position`"),
            );
            ok = false;
        }
        if let (Some(v), Some(u)) = (view, direction(up)) {
            if v.cross(u).length() < 1e-9 {
                self.report(
                    Diagnostic::error(
                        codes::BAD_CAMERA,
                        a.span_of("up"),
                        "`up` is parallel to the view direction",
                        "this points along the view",
                    )
                    .with_note("the camera cannot tell which way is up")
                    .with_hint("try `up = [0, 1, 0]`, or `[0, 0, 1]` when looking straight up or down"),
                );
                ok = false;
            }
        }
        ok.then_some(Camera { position, look_at, up, fov, aperture, focus_distance, span: Some(span) })
    }

    /// The settings of a `render` statement whose arguments are bound.
    pub(crate) fn settings(&mut self, a: &BoundArgs, span: Span) -> Option<Settings> {
        let r = RenderStatementArgs::from_args(a);
        if r.width as u64 * r.height as u64 > MAX_PIXELS {
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    span,
                    "image is too large",
                    format!("{}×{} is {} pixels", r.width, r.height, r.width as u64 * r.height as u64),
                )
                .with_note(format!("an image may have at most {MAX_PIXELS} pixels")),
            );
            return None;
        }
        let color = match &*r.color {
            "linear" => ir::ColorSpace::Linear,
            "srgb" => ir::ColorSpace::Srgb,
            other => {
                self.report(
                    Diagnostic::error(
                        codes::OUT_OF_RANGE,
                        a.span_of("color"),
                        "`color` must be \"linear\" or \"srgb\"",
                        format!("this is {other:?}"),
                    )
                    .with_note("\"linear\" shades colours as written (the study's); \"srgb\" reads them as sRGB and shades in linear light"),
                );
                return None;
            }
        };
        Some(Settings {
            width: r.width,
            height: r.height,
            depth: r.depth,
            background: r.background,
            epsilon: r.epsilon,
            max_steps: r.max_steps,
            max_distance: r.max_distance,
            samples: r.samples,
            ambient_occlusion: r.ambient_occlusion,
            frames: r.frames,
            fps: r.fps,
            cyclic: r.cyclic,
            bounces: r.bounces,
            exposure: r.exposure,
            noise: r.noise,
            clamp: r.clamp,
            color,
            span: Some(span),
        })
    }
}

crate::params! {
    /// The `camera` statement's arguments.
    pub struct CameraArgs {
        /// where the eye is
        position: DVec3 as Vec3 = [0.0, 0.0, 0.0];
        /// a point the camera looks at, other than `position`
        look_at: DVec3 as Vec3 = [0.0, 0.0, 1.0];
        /// which way is up in the image, not along the view
        up: DVec3 as Vec3 = [0.0, 1.0, 0.0], Range::NONZERO;
        /// the vertical field of view in degrees
        fov: f64 as Num = (ir::SEED_FOV), Range::open(0.0, 180.0);
        /// the lens's diameter for depth of field under light transport (0: a pinhole)
        aperture: f64 as Num = 0.0, Range::closed(0.0, MAX_REACH);
        /// how far along the view the lens focuses (default: at `look_at`)
        focus_distance: Option<f64> as Num = derived, Range::gt_le(0.0, MAX_REACH);
    }
}

crate::params! {
    /// The `render` statement's arguments.
    pub struct RenderStatementArgs {
        /// image width in pixels
        width: u32 as Int = 500, Range::closed(1.0, MAX_IMAGE_SIDE as f64);
        /// image height in pixels
        height: u32 as Int = 500, Range::closed(1.0, MAX_IMAGE_SIDE as f64);
        /// how many reflections and refractions deep rays are traced (0: none)
        depth: u32 as Int = 5, Range::closed(0.0, MAX_DEPTH as f64);
        /// the colour where rays meet nothing
        background: DVec3 as Color = [245.0, 245.0, 245.0];
        /// the sphere-tracing hit threshold, relative to the distance from the camera (f32 cannot resolve less than 1e-6)
        epsilon: f64 as Num = 1e-4, EPSILON_RANGE;
        /// the most sphere-tracing steps one ray may take
        max_steps: u32 as Int = 512, Range::closed(1.0, MAX_STEPS as f64);
        /// the farthest any ray reaches
        max_distance: f64 as Num = 1000.0, Range::gt_le(0.0, MAX_REACH);
        /// samples per pixel (antialiasing)
        samples: u32 as Int = 1, Range::closed(1.0, MAX_SAMPLES as f64);
        /// how far ambient occlusion looks (0 turns it off)
        ambient_occlusion: f64 as Num = 0.0, Range::NONNEG;
        /// frames of the animation (1: a still)
        frames: u32 as Int = 1, Range::closed(1.0, MAX_FRAMES as f64);
        /// frames per second, for `scnc encode`
        fps: f64 as Num = 24.0, Range::gt_le(0.0, MAX_FPS);
        /// whether the animation loops (then `clock` stops a frame short of 1)
        cyclic: bool as Bool = false;
        /// how colours are read and pixels written: "linear" (the study's) or "srgb"
        color: String as Str = "linear";
        /// a light-transport path's surface interactions after the camera ray (1: direct light only; 8 when not given)
        bounces: Option<u32> as Int = derived, Range::closed(1.0, MAX_BOUNCES as f64);
        /// light-transport pixels are scaled by 2^exposure before the tone map
        exposure: f64 as Num = 0.0, Range::closed(-64.0, 64.0);
        /// light transport samples each pixel until its estimated relative error is below this (`samples` the most)
        noise: Option<f64> as Num = derived, Range::gt_le(0.0, 1.0);
        /// light transport scales a sample down until no channel brings more than this radiance (biased: fireflies lose their light; none when not given)
        clamp: Option<f64> as Num = derived, Range::gt_le(0.0, MAX_REACH);
    }
}
