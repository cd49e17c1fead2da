//! The renderable range: every object, transform and light of a checked scene must be
//! representable once lowered to camera-relative f32. A legal f64 such as `scale 1e200`
//! twice, `at [1e39, 0, 5]` or `light point(1e308)` would otherwise reach the tracer as
//! infinity or NaN and render a blank image with exit 0.
//!
//! The bounds keep squares of distances finite in f32 (1e15² = 1e30 < 3.4e38) and sizes
//! above the point where f32 normals and offsets underflow; inside them the stability
//! suite renders the same image at every scale it tries (1e-4 to 1e4).

use super::Ctx;
pub use crate::builtins::MAX_REACH;
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, Body, Camera, LightKind, Shape, ShapeKind};

/// Smallest object, across its bounds, in world units.
pub const MIN_SIZE: f64 = 1e-12;
/// Largest light intensity.
pub const MAX_INTENSITY: f64 = 1e6;
/// Widest range of one transform's scale.
const MAX_SCALE: f64 = 1e15;

/// `x` as people write it: exponent form when it is huge or tiny.
fn shown(x: f64) -> String {
    if x != 0.0 && !(1e-6..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        ir::dump_num(x)
    }
}

impl Ctx<'_> {
    /// Reports every object and light outside the renderable range as seen from `camera`.
    ///
    /// Long because it is one walk over the camera, the objects and the lights, each with
    /// its own message.
    pub(super) fn check_range(&mut self, camera: &Camera) {
        if !in_reach(camera.position) {
            let span = camera.span.unwrap_or_default();
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_REACH,
                    span,
                    "the camera is beyond the renderable range",
                    format!("it is {} units from the origin", shown(camera.position.length())),
                )
                .with_note(format!("positions must lie within {} units of the origin", shown(MAX_REACH))),
            );
            return;
        }
        for obj in &self.objects.clone() {
            let parts_ok = match &obj.geometry {
                Body::Shape(s) => self.parts_in_range(s),
                Body::Mesh(m) => {
                    let placed = self.transform_in_range(&m.xf, m.span);
                    let shape = match &m.source {
                        ir::MeshSource::Isosurface { shape, .. } => self.parts_in_range(shape),
                        _ => true,
                    };
                    placed && shape
                }
            };
            if !parts_ok {
                continue;
            }
            // The tight sphere: box bounds of a huge blend overflow to NaN, which would
            // look unbounded. Only a half-space (a `plane`) has none.
            let sphere = match &obj.geometry {
                Body::Shape(s) => ir::shape_sphere(s),
                Body::Mesh(_) => ir::bounding_sphere(&obj.geometry),
            };
            let Some((centre, radius)) = sphere else { continue };
            let reach = (centre - camera.position).length() + radius;
            if !reach.is_finite() || reach > MAX_REACH {
                self.report(
                    Diagnostic::error(
                        codes::OUT_OF_REACH,
                        obj.span,
                        "this object is beyond the renderable range",
                        match reach.is_finite() {
                            true => format!("it reaches {} units from the camera", shown(reach)),
                            false => "it reaches farther than any finite distance".to_string(),
                        },
                    )
                    .with_note(format!(
                        "every part of a scene must lie within {} units of the camera",
                        shown(MAX_REACH)
                    )),
                );
            } else if radius * 2.0 < MIN_SIZE {
                self.report(
                    Diagnostic::error(
                        codes::OUT_OF_REACH,
                        obj.span,
                        "this object is too small to render",
                        format!("it is {} units across", shown(radius * 2.0)),
                    )
                    .with_note(format!("an object must be at least {} units across", shown(MIN_SIZE)))
                    .with_hint("try scaling the whole scene up, camera included"),
                );
            }
        }
        for light in &self.lights.clone() {
            if light.intensity > MAX_INTENSITY {
                self.report(
                    Diagnostic::error(
                        codes::OUT_OF_REACH,
                        light.span,
                        "this light is too bright to render",
                        format!("its intensity is {}", shown(light.intensity)),
                    )
                    .with_note(format!("an intensity may be at most {}", shown(MAX_INTENSITY))),
                );
            }
            let far = match light.kind {
                LightKind::Point { position } => (position - camera.position).length() + light.radius,
                LightKind::Area { centre, u, v } => (centre - camera.position).length() + u.length() + v.length(),
                LightKind::Ambient | LightKind::Directional { .. } | LightKind::Environment => 0.0,
            };
            if !far.is_finite() || far > MAX_REACH {
                self.report(
                    Diagnostic::error(
                        codes::OUT_OF_REACH,
                        light.span,
                        "this light is beyond the renderable range",
                        format!("it is {} units from the camera", shown(far)),
                    )
                    .with_note(format!(
                        "every part of a scene must lie within {} units of the camera",
                        shown(MAX_REACH)
                    )),
                );
            }
        }
    }

    /// Every transform of the tree moves by at most [`MAX_REACH`] and scales by a finite
    /// amount within [`MAX_SCALE`] either way, and every plane's offset is within reach
    /// (a shared subtree is checked once). Whether all were.
    fn parts_in_range(&mut self, shape: &Shape) -> bool {
        let mut seen = std::collections::HashSet::new();
        let mut stack = vec![shape];
        let mut ok = true;
        while let Some(s) = stack.pop() {
            if !seen.insert(s as *const Shape) {
                continue;
            }
            match &s.kind {
                ShapeKind::Transform { xf, .. } => ok &= self.transform_in_range(xf, s.span),
                ShapeKind::Primitive(p) if p.half_space().is_some_and(|(_, offset)| offset.abs() > MAX_REACH) => {
                    ok = false;
                    let offset = p.half_space().map_or(0.0, |(_, offset)| offset);
                    self.report(
                        Diagnostic::error(
                            codes::OUT_OF_REACH,
                            s.span,
                            format!("this {} is beyond the renderable range", p.name()),
                            format!("its offset is {}", shown(offset)),
                        )
                        .with_note(format!("positions must lie within {} units of the origin", shown(MAX_REACH))),
                    );
                }
                _ => {}
            }
            stack.extend(s.children().iter().map(|c| &**c));
        }
        ok
    }

    /// A transform moves by at most [`MAX_REACH`] (f64 keeps about 16 digits: beyond it a
    /// unit object's position loses its fraction) and scales within [`MAX_SCALE`].
    fn transform_in_range(&mut self, xf: &glam::DAffine3, span: crate::span::Span) -> bool {
        if !in_reach(xf.translation) {
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_REACH,
                    span,
                    "this transform is beyond the renderable range",
                    format!("it moves by {}", shown(xf.translation.length())),
                )
                .with_note(format!("positions must lie within {} units of the origin", shown(MAX_REACH))),
            );
            return false;
        }
        self.scale_in_range(xf.matrix3, span)
    }

    /// A linear map is finite, and stretches and shrinks by at most [`MAX_SCALE`].
    fn scale_in_range(&mut self, m: glam::DMat3, span: crate::span::Span) -> bool {
        let most = ir::max_stretch(m);
        // σ_min ≥ |det| / σ_max², as det = σ₁σ₂σ₃: a bound that needs no eigenvalues.
        let least = if most > 0.0 { m.determinant().abs() / (most * most) } else { 0.0 };
        let finite = m.to_cols_array().iter().all(|x| x.is_finite()) && most.is_finite();
        if finite && most <= MAX_SCALE && least >= 1.0 / MAX_SCALE {
            return true;
        }
        let this = if !finite {
            "an infinite amount".to_string()
        } else if most > MAX_SCALE {
            shown(most)
        } else {
            shown(least)
        };
        self.report(
            Diagnostic::error(
                codes::OUT_OF_REACH,
                span,
                "this transform is beyond the renderable range",
                format!("it scales by {this}"),
            )
            .with_note(format!(
                "transforms may scale by between {} and {} (composed along the way)",
                shown(1.0 / MAX_SCALE),
                shown(MAX_SCALE)
            )),
        );
        false
    }
}

/// Whether a position is finite and within [`MAX_REACH`] of the origin.
fn in_reach(p: glam::DVec3) -> bool {
    p.is_finite() && p.length() <= MAX_REACH
}
