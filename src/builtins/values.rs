//! Plain-value builtins: materials, colours and lights.

use std::sync::Arc;

use glam::DVec3;

use super::BoundArgs;
use super::{Host, Value};
use super::{LightFn, PatternFn};
use crate::diag::{codes, Diagnostic};
use crate::ir::{self, dump_vec, Material, Paint, Pattern, PatternKind};
use crate::sig::Range;

/// Highest index of refraction (germanium's is about 4; nothing in nature reaches 10).
pub const MAX_IOR: f64 = 10.0;
/// Highest `density`: far beyond any material's in any unit a scene is likely drawn in
/// (osmium is 22.6 g/cm³, 2.26e-5 g/mm³, 22,600 kg/m³).
pub const MAX_DENSITY: f64 = 1e12;

/// Highest `emission_strength`: far beyond any real source relative to a white surface,
/// still far from f32's overflow when shaded.
pub const MAX_EMISSION: f64 = 1e30;
/// Most patterns in one pattern, itself included: each is evaluated at every shaded
/// point, and a blend evaluates both of its paints.
pub const MAX_PATTERN_NODES: usize = 64;

crate::params! {
    /// `material(…)`.
    pub struct MaterialArgs {
        /// the surface's colour, or a pattern painting it
        color: Value as Paint = [200.0, 200.0, 200.0];
        /// the Phong exponent of its highlight (-1: none)
        specular: f64 as Num = (-1.0), Range::NONNEG.or(-1.0);
        /// the share of light it reflects as a mirror
        reflective: f64 as Num = 0.0, Range::UNIT;
        /// the share of light passing into it (0: opaque)
        transparency: f64 as Num = 0.0, Range::UNIT;
        /// the index of refraction of the medium inside (1: air)
        ior: f64 as Num = 1.0, Range::closed(1.0, MAX_IOR);
        /// how much of each channel the medium absorbs per unit of distance
        absorption: DVec3 as Vec3 = [0.0, 0.0, 0.0], Range::NONNEG;
        /// the colour of the light it glows with under light transport (black: none)
        emission: DVec3 as Color = [0.0, 0.0, 0.0];
        /// how brightly it glows: radiance = `emission` (255 is 1) times this
        emission_strength: f64 as Num = 1.0, Range::closed(0.0, MAX_EMISSION);
        /// mass per unit volume, for `scnc measure`'s mass and inertia
        density: f64 as Num = 1.0, Range::gt_le(0.0, MAX_DENSITY);
    }
}

crate::params! {
    /// `checker(a, b, size)`.
    pub struct CheckerArgs {
        /// the paint of the even cubes
        a: Value as Paint = required;
        /// the paint of the odd cubes
        b: Value as Paint = required;
        /// the cubes' edge
        size: f64 as Num = 1.0, Range::POSITIVE;
    }
}

crate::params! {
    /// `stripes(a, b, width, axis)`.
    pub struct StripesArgs {
        /// the paint of the even slabs
        a: Value as Paint = required;
        /// the paint of the odd slabs
        b: Value as Paint = required;
        /// each slab's thickness
        width: f64 as Num = 1.0, Range::POSITIVE;
        /// the direction the slabs alternate along
        axis: DVec3 as Vec3 = [1.0, 0.0, 0.0], Range::NONZERO;
    }
}

crate::params! {
    /// `gradient(a, b, from, to)`.
    pub struct GradientArgs {
        /// the paint at `from`
        a: Value as Paint = required;
        /// the paint at `to`
        b: Value as Paint = required;
        /// where the blend starts
        from: DVec3 as Vec3 = [0.0, 0.0, 0.0];
        /// where it ends, a point other than `from`
        to: DVec3 as Vec3 = [0.0, 1.0, 0.0];
    }
}

crate::params! {
    /// `noise(a, b, size, seed)`.
    pub struct NoiseArgs {
        /// the paint where the noise is lowest
        a: Value as Paint = required;
        /// the paint where it is highest
        b: Value as Paint = required;
        /// the size of its features
        size: f64 as Num = 1.0, Range::POSITIVE;
        /// which noise: another seed, another pattern
        seed: u32 as Int = 0, Range::closed(0.0, u32::MAX as f64);
    }
}

crate::params! {
    /// `rgb(r, g, b)`.
    pub struct RgbArgs {
        /// red
        r: f64 as Num = required, Range::closed(0.0, 255.0);
        /// green
        g: f64 as Num = required, Range::closed(0.0, 255.0);
        /// blue
        b: f64 as Num = required, Range::closed(0.0, 255.0);
    }
}

crate::params! {
    /// `ambient(intensity)`.
    pub struct AmbientArgs {
        /// how bright
        intensity: f64 as Num = required, Range::NONNEG;
    }
}

crate::params! {
    /// `point(intensity, shadows, radius)`.
    pub struct PointArgs {
        /// how bright
        intensity: f64 as Num = required, Range::NONNEG;
        /// whether it casts shadows
        shadows: bool as Bool = true;
        /// the light's radius, for soft shadows (0: hard)
        radius: f64 as Num = 0.0, Range::NONNEG;
    }
}

crate::params! {
    /// `area(intensity, size)`.
    pub struct AreaArgs {
        /// its radiance (1: as bright as a white surface at full light)
        intensity: f64 as Num = required, Range::NONNEG;
        /// its width and height `[w, h]` (default `[1, 1]`)
        size: Option<Value> as List = derived;
    }
}

crate::params! {
    /// `environment(intensity)`.
    pub struct EnvironmentArgs {
        /// the radiance arriving from every direction
        intensity: f64 as Num = required, Range::NONNEG;
    }
}

crate::params! {
    /// `directional(intensity, towards, shadows)`.
    pub struct DirectionalArgs {
        /// how bright
        intensity: f64 as Num = required, Range::NONNEG;
        /// the direction towards the light
        towards: DVec3 as Vec3 = required, Range::NONZERO;
        /// whether it casts shadows
        shadows: bool as Bool = true;
    }
}

/// A colour or pattern value as a material's paint (`None` for poison).
fn paint(v: &Value) -> Option<Paint> {
    match v {
        Value::Color(c) => Some(Paint::Solid(*c)),
        Value::Pattern(p) => Some(Paint::Pattern(p.clone())),
        _ => None,
    }
}

/// Patterns in a pattern, itself included.
fn pattern_nodes(p: &Pattern) -> usize {
    let inner = |paint: &Paint| match paint {
        Paint::Solid(_) => 0,
        Paint::Pattern(q) => pattern_nodes(q),
    };
    1 + inner(&p.a) + inner(&p.b)
}

impl dyn Host + '_ {
    /// `material(color, specular, reflective, transparency, ior, absorption)`.
    pub(super) fn material(&mut self, a: &BoundArgs) -> Value {
        let m = MaterialArgs::from_args(a);
        let Some(color) = paint(&m.color) else {
            return Value::Error;
        };
        let m = Material {
            color,
            specular: (m.specular >= 0.0).then_some(m.specular),
            reflective: m.reflective,
            transparency: m.transparency,
            ior: m.ior,
            absorption: m.absorption,
            emission: m.emission,
            emission_strength: m.emission_strength,
            density: m.density,
            span: a.call,
        };
        if !m.is_transparent() {
            let idle: Vec<&str> = [("ior", m.ior != 1.0), ("absorption", m.absorption != DVec3::ZERO)]
                .into_iter()
                .filter_map(|(name, set)| (set && a.was_given(name)).then_some(name))
                .collect();
            if let Some(&first) = idle.first() {
                let names: Vec<String> = idle.iter().map(|name| format!("`{name}`")).collect();
                self.report(
                    Diagnostic::warning(
                        codes::NO_EFFECT,
                        a.span_of(first),
                        format!(
                            "{} {} no effect on an opaque material",
                            names.join(" and "),
                            if idle.len() > 1 { "have" } else { "has" }
                        ),
                        "the material has no `transparency`",
                    )
                    .with_hint("give it `transparency = 1` for clear glass, or less to mix in its surface colour"),
                );
            }
        }
        Value::Material(Arc::new(m))
    }

    /// `checker`, `stripes`, `gradient` and `noise`: two paints and where each goes.
    pub(super) fn pattern(&mut self, f: PatternFn, a: &BoundArgs) -> Value {
        let (kind, pa, pb) = match f {
            PatternFn::Checker => {
                let CheckerArgs { a: pa, b: pb, size } = CheckerArgs::from_args(a);
                (Some(PatternKind::Checker { size }), pa, pb)
            }
            PatternFn::Stripes => {
                let StripesArgs { a: pa, b: pb, width, axis } = StripesArgs::from_args(a);
                (Some(PatternKind::Stripes { width, axis }), pa, pb)
            }
            PatternFn::Gradient => {
                let GradientArgs { a: pa, b: pb, from, to } = GradientArgs::from_args(a);
                let kind = if !(to - from).is_finite() {
                    self.range_error(a.span_of("to"), "to", "a point within 1e308 of `from`", dump_vec(to));
                    None
                } else if super::direction(to - from).is_none() {
                    self.range_error(a.span_of("to"), "to", "a point other than `from`", dump_vec(to));
                    None
                } else {
                    Some(PatternKind::Gradient { from, to })
                };
                (kind, pa, pb)
            }
            PatternFn::Noise => {
                let NoiseArgs { a: pa, b: pb, size, seed } = NoiseArgs::from_args(a);
                (Some(PatternKind::Noise { size, seed }), pa, pb)
            }
        };
        let (Some(kind), Some(pa), Some(pb)) = (kind, paint(&pa), paint(&pb)) else {
            return Value::Error;
        };
        let pattern = Pattern { kind, a: pa, b: pb, span: a.call };
        let nodes = pattern_nodes(&pattern);
        if nodes > MAX_PATTERN_NODES {
            self.report(
                Diagnostic::error(
                    codes::SHAPE_TOO_LARGE,
                    a.call,
                    "a pattern with too many patterns inside",
                    format!("this pattern holds {nodes} patterns"),
                )
                .with_note(format!(
                    "a pattern may hold at most {MAX_PATTERN_NODES}, itself included: every one is evaluated at each shaded point"
                )),
            );
            return Value::Error;
        }
        Value::Pattern(Arc::new(pattern))
    }

    /// `rgb(r, g, b)` in 0–255.
    pub(super) fn rgb(&mut self, a: &BoundArgs) -> Value {
        let RgbArgs { r, g, b } = RgbArgs::from_args(a);
        Value::Color(DVec3::new(r, g, b))
    }

    /// An area light's `size`: two finite numbers, neither negative (a zero side makes
    /// a light that emits nothing).
    fn size(&mut self, size: Option<&Value>, a: &BoundArgs) -> Option<[f64; 2]> {
        let Some(v) = size else { return Some([1.0, 1.0]) };
        if let Value::List(items) = v {
            if let [Value::Num(w), Value::Num(h)] = items.as_slice() {
                if w.is_finite() && h.is_finite() && *w >= 0.0 && *h >= 0.0 && w.max(*h) <= super::MAX_REACH {
                    return Some([*w, *h]);
                }
            }
        }
        if !v.is_error() {
            let shown = match v {
                Value::List(items) => {
                    let parts: Vec<String> = items
                        .iter()
                        .map(|x| if let Value::Num(n) = x { ir::dump_num(*n) } else { format!("a `{}`", x.ty_name()) })
                        .collect();
                    format!("[{}]", parts.join(", "))
                }
                other => format!("a `{}`", other.ty_name()),
            };
            self.range_error(a.span_of("size"), "size", "a width and height `[w, h]`, neither negative", shown);
        }
        None
    }

    /// A light (placed later by `at`).
    pub(super) fn light(&mut self, l: LightFn, a: &BoundArgs) -> Value {
        let (kind, intensity, shadows, radius) = match l {
            LightFn::Ambient => (ir::LightKind::Ambient, AmbientArgs::from_args(a).intensity, false, 0.0),
            LightFn::Point => {
                let PointArgs { intensity, shadows, radius } = PointArgs::from_args(a);
                (ir::LightKind::Point { position: DVec3::ZERO }, intensity, shadows, radius)
            }
            LightFn::Directional => {
                let DirectionalArgs { intensity, towards, shadows } = DirectionalArgs::from_args(a);
                (ir::LightKind::Directional { towards }, intensity, shadows, 0.0)
            }
            LightFn::Area => {
                let AreaArgs { intensity, size } = AreaArgs::from_args(a);
                let Some([w, h]) = self.size(size.as_ref(), a) else {
                    return Value::Error;
                };
                let kind = ir::LightKind::Area {
                    centre: DVec3::ZERO,
                    u: DVec3::new(w / 2.0, 0.0, 0.0),
                    v: DVec3::new(0.0, 0.0, h / 2.0),
                };
                (kind, intensity, true, 0.0)
            }
            LightFn::Environment => (ir::LightKind::Environment, EnvironmentArgs::from_args(a).intensity, true, 0.0),
        };
        Value::Light(Arc::new(ir::Light { kind, intensity, shadows, radius, span: a.call }))
    }
}
