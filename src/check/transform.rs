//! The transform operators `at`, `rotate`, `scale` and `with`: composed in f64 onto
//! shapes, meshes and lights.

use std::sync::Arc;

use glam::{DAffine3, DMat3, DVec3};

use super::{Ctx, Value};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_num};
use crate::span::Span;
use crate::syntax::ast::TransformOp;

impl Ctx<'_> {
    /// `target op argument` for a transform (`at`, `rotate`, `scale`, `with`) on a shape,
    /// mesh, light or profile. Long because it is one match over the operator and the
    /// operand's kind, each arm with the message for its misuse.
    #[allow(clippy::too_many_arguments, reason = "each span blames a different part of `a op b`")]
    pub(super) fn transform(
        &mut self,
        op: TransformOp,
        op_span: Span,
        target: Value,
        target_span: Span,
        arg: Value,
        arg_span: Span,
        span: Span,
    ) -> Value {
        if target.is_error() || arg.is_error() {
            return Value::Error;
        }
        let kw = op.keyword();
        if matches!(arg, Value::Sym(_)) {
            self.depends_on_point(arg_span, &format!("`{kw}`'s argument"));
            return Value::Error;
        }
        let bad_target = |this: &mut Self, note: &str| {
            this.report(
                Diagnostic::error(
                    codes::BAD_TRANSFORM,
                    op_span,
                    format!("cannot apply `{kw}` to a `{}`", target.ty_name()),
                    format!("`{kw}` needs a shape or a mesh"),
                )
                .with_label(target_span, target.this_is())
                .with_note(note.to_string()),
            );
            Value::Error
        };
        if let Value::Light(light) = &target {
            let placed = |kind: ir::LightKind| {
                let mut l = (**light).clone();
                l.kind = kind;
                l.span = span;
                Value::Light(Arc::new(l))
            };
            return match (op, &light.kind, &arg) {
                (TransformOp::At, ir::LightKind::Point { .. }, Value::Vec3(p)) => {
                    placed(ir::LightKind::Point { position: *p })
                }
                (TransformOp::At, ir::LightKind::Area { centre, u, v }, Value::Vec3(p)) => {
                    placed(ir::LightKind::Area { centre: *centre + *p, u: *u, v: *v })
                }
                // About the origin, as a shape turns: a placed rectangle swings with it.
                (TransformOp::Rotate, ir::LightKind::Area { centre, u, v }, Value::Vec3(deg)) => {
                    let r = rotation(*deg);
                    placed(ir::LightKind::Area { centre: r * *centre, u: r * *u, v: r * *v })
                }
                (TransformOp::At, ir::LightKind::Point { .. } | ir::LightKind::Area { .. }, other)
                | (TransformOp::Rotate, ir::LightKind::Area { .. }, other) => {
                    let label = if op == TransformOp::At { "a position is a `vec3`" } else { "angles are a `vec3` of degrees" };
                    self.report(Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        arg_span,
                        format!("expected `vec3`, found `{}`", other.ty_name()),
                        label,
                    ));
                    Value::Error
                }
                _ => bad_target(
                    self,
                    "point lights are placed with `at`, area lights with `at` and `rotate`; a directional light takes `towards = […]`",
                ),
            };
        }
        if let (Value::Profile(profile), false) = (&target, op == TransformOp::With) {
            return self.host().transform_profile(op, profile, &arg, arg_span);
        }
        if !matches!(target, Value::Shape(_) | Value::Mesh(_)) {
            return bad_target(self, "transforms apply to shapes and meshes (and `at`, `rotate`, `scale` to profiles)");
        }
        if op == TransformOp::With {
            let Value::Material(m) = arg else {
                let mut d = Diagnostic::error(
                    codes::TYPE_MISMATCH,
                    arg_span,
                    format!("expected `material`, found `{}`", arg.ty_name()),
                    arg.this_is(),
                )
                .with_note("`with` takes a material");
                if matches!(arg, Value::Color(_)) {
                    d = d.with_hint("try `with material(color = …)`");
                }
                self.report(d);
                return Value::Error;
            };
            return match target {
                Value::Shape(s) => self.host().shape_value(ir::ShapeKind::Paint { child: s, material: m }, span),
                Value::Mesh(mesh) => {
                    let mut mesh = (*mesh).clone();
                    // The innermost material wins, as for shapes.
                    mesh.material.get_or_insert(m);
                    Value::Mesh(Arc::new(mesh))
                }
                _ => Value::Error,
            };
        }
        let xf = match (op, &arg) {
            (TransformOp::At, Value::Vec3(v)) => DAffine3::from_translation(*v),
            (TransformOp::Rotate, Value::Vec3(deg)) => DAffine3::from_mat3(rotation(*deg)),
            (TransformOp::Scale, Value::Num(_) | Value::Vec3(_)) => {
                let k = match arg {
                    Value::Num(k) => DVec3::splat(k),
                    Value::Vec3(v) => v,
                    _ => DVec3::ONE,
                };
                if k.min_element() <= 0.0 {
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            arg_span,
                            "scale factors must be greater than 0",
                            format!("this is {}", ir::dump_vec(k)),
                        )
                        .with_note(
                            "a zero scale flattens the shape to nothing; mirroring (negative scale) is not supported",
                        ),
                    );
                    return Value::Error;
                }
                if k.max_element() / k.min_element() > 1e6 {
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            arg_span,
                            "scale factors differ too much",
                            "the largest is over a million times the smallest",
                        )
                        .with_note("such a stretch loses all precision in the distance bound"),
                    );
                    return Value::Error;
                }
                DAffine3::from_scale(k)
            }
            _ => {
                let expected = if op == TransformOp::Scale { "num` or `vec3" } else { "vec3" };
                let mut d = Diagnostic::error(
                    codes::TYPE_MISMATCH,
                    arg_span,
                    format!("expected `{expected}`, found `{}`", arg.ty_name()),
                    arg.this_is(),
                )
                .with_note(format!("`{kw}` takes a `{expected}`"));
                if let Value::Num(x) = arg {
                    d = d.with_hint(format!("try `{kw} [{}, 0, 0]`", dump_num(x)));
                }
                self.report(d);
                return Value::Error;
            }
        };
        match target {
            Value::Shape(s) => self.host().sized(apply_xf(s, xf, span)),
            Value::Mesh(m) => {
                let mut m = (*m).clone();
                m.xf = xf * m.xf;
                Value::Mesh(Arc::new(m))
            }
            _ => Value::Error,
        }
    }
}

/// The study's rotation: about X, then Y, then Z, angles in degrees.
pub(crate) fn rotation(deg: DVec3) -> DMat3 {
    let r = deg * (std::f64::consts::PI / 180.0);
    DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x)
}

/// Applies `xf` on top of `shape`, merging consecutive transforms and keeping materials outside them.
fn apply_xf(shape: Arc<ir::Shape>, xf: DAffine3, span: Span) -> Arc<ir::Shape> {
    match &shape.kind {
        ir::ShapeKind::Transform { child, xf: inner } => {
            Arc::new(ir::Shape::new(ir::ShapeKind::Transform { child: child.clone(), xf: xf * *inner }, span))
        }
        ir::ShapeKind::Paint { child, material } => Arc::new(ir::Shape::new(
            ir::ShapeKind::Paint { child: apply_xf(child.clone(), xf, span), material: material.clone() },
            shape.span,
        )),
        ir::ShapeKind::Primitive(_)
        | ir::ShapeKind::Csg { .. }
        | ir::ShapeKind::Round { .. }
        | ir::ShapeKind::Shell { .. }
        | ir::ShapeKind::Repeat { .. }
        | ir::ShapeKind::Field { .. }
        | ir::ShapeKind::Warp { .. }
        | ir::ShapeKind::Displace { .. } => {
            Arc::new(ir::Shape::new(ir::ShapeKind::Transform { child: shape, xf }, span))
        }
    }
}
