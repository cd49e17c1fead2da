//! The effect set: which parts of the shading model a scene calls for, derived from the
//! IR alone, so the tracer is built with those and no others.
//!
//! Every effect is one row of `effect_table!`'s invocation below: its field of
//! [`Effects`], the rule that derives it from a `Survey` of the IR, whether it is on,
//! its word in `--stats` and `scnc ir`, the counters only it (or another row naming the
//! same counter) can raise, and — for an effect the tracer is specialised on — its bit
//! of the tracer's `FX` parameter. The struct, [`derive()`], the `Display` line, the
//! [`fx`] flags, the [`TABLE`] the tests walk, and the dispatch to the tracer variant
//! built for a set of flags (`specialise`) are all generated from those rows, so a new
//! effect is a row here and its code in the tracer.

use std::fmt;

use crate::ir::{self, LightKind, Scene};
use crate::trace::Counters;

/// A counter by name, and how to read it.
pub type Counter = (&'static str, fn(&Counters) -> u64);

/// One effect as the tests and tools see it.
pub struct Effect {
    /// Its word in `--stats` and `scnc ir`.
    pub word: &'static str,
    /// Its bit of the tracer's `FX` parameter; 0 for an effect the tracer is not
    /// specialised on (its cost is data: an empty list, one sample).
    pub flag: u8,
    /// Whether a derived set has it on.
    pub on: fn(&Effects) -> bool,
    /// How it shows in the effects line.
    pub show: fn(&Effects) -> String,
    /// The counters it raises, by name: with every effect that names a counter off, a
    /// render's count of it is 0.
    pub counters: &'static [Counter],
}

/// Generates the effect set's types and functions from one row per effect (see the
/// module's doc).
macro_rules! effect_table {
    ($(
        $(#[doc = $doc:literal])*
        $field:ident: $ty:ty, $word:literal $(, tracer $flag:ident = $bit:literal)? {
            derive: $derive:expr,
            on: $on:expr,
            show: $show:expr,
            counts: [$($counter:ident),*] $(,)?
        }
    )*) => {
        /// The effects one scene needs.
        #[derive(Clone, Debug, PartialEq)]
        pub struct Effects {
            $($(#[doc = $doc])* pub $field: $ty,)*
        }

        /// The effect flags a tracer variant is built with (bits of its `FX` parameter).
        pub mod fx {
            $($(#[doc = concat!("The `", $word, "` effect.")] pub const $flag: u8 = $bit;)?)*
        }

        /// Every effect, in the order of the effects line.
        pub const TABLE: &[Effect] = &[$(Effect {
            word: $word,
            flag: 0 $(| fx::$flag)?,
            on: $on,
            show: $show,
            counters: &[$((stringify!($counter), |c: &Counters| c.$counter)),*],
        }),*];

        /// Derives the effect set of a scene.
        pub fn derive(scene: &Scene) -> Effects {
            let survey = Survey::of(scene);
            let s = &survey;
            Effects { $($field: ($derive)(s),)* }
        }

        /// Runs `variant` built for the tracer flags of `effects`: one of the
        /// `2^flags` monomorphised variants, chosen once, before the first ray.
        pub(crate) fn specialise<V: Variant>(effects: &Effects, variant: V) -> V::Out {
            let wanted = effects.flags();
            branches!(wanted, variant, [], [$($(fx::$flag;)?)*])
        }
    };
}

/// Expands to a tree of `if`s over the flags, one leaf per subset of them, each calling
/// the variant built with exactly the flags set on its path.
macro_rules! branches {
    ($wanted:ident, $v:ident, [$($acc:path),*], []) => {
        $v.run::<{ 0 $(| $acc)* }>()
    };
    ($wanted:ident, $v:ident, [$($acc:path),*], [$bit:path; $($rest:path;)*]) => {
        if $wanted & $bit != 0 {
            branches!($wanted, $v, [$($acc,)* $bit], [$($rest;)*])
        } else {
            branches!($wanted, $v, [$($acc),*], [$($rest;)*])
        }
    };
}

/// Something built per set of tracer flags: [`specialise`] calls `run` with the set.
pub(crate) trait Variant {
    /// What running it gives.
    type Out;
    /// Runs the variant built for the flags `FX`.
    fn run<const FX: u8>(self) -> Self::Out;
}

/// `#0, #2`, or `none`.
fn lights(v: &[usize]) -> String {
    if v.is_empty() {
        "none".to_string()
    } else {
        v.iter().map(|i| format!("#{i}")).collect::<Vec<_>>().join(", ")
    }
}

fn on_off(on: bool) -> String {
    if on { "on" } else { "off" }.to_string()
}

effect_table! {
    /// Total ambient intensity.
    ambient: f64, "ambient" {
        // Light transport has no ambient term: an environment light is its counterpart.
        derive: |s: &Survey| if s.transport { 0.0 } else { s.ambient },
        on: |e: &Effects| e.ambient > 0.0,
        show: |e: &Effects| ir::dump_num(e.ambient),
        counts: [],
    }
    /// Lights that cast shadows (indices into the scene's lights).
    shadow_lights: Vec<usize>, "shadow rays from", tracer SHADOWS = 1 {
        derive: |s: &Survey| s.shadow_lights.clone(),
        on: |e: &Effects| !e.shadow_lights.is_empty(),
        show: |e: &Effects| lights(&e.shadow_lights),
        counts: [shadow_rays],
    }
    /// Point and directional lights that cast none.
    unshadowed_lights: Vec<usize>, "unshadowed lights" {
        derive: |s: &Survey| s.unshadowed_lights.clone(),
        on: |e: &Effects| !e.unshadowed_lights.is_empty(),
        show: |e: &Effects| lights(&e.unshadowed_lights),
        counts: [],
    }
    /// Casting point lights with a radius (soft shadows).
    soft_lights: Vec<usize>, "soft shadows from" {
        derive: |s: &Survey| {
            s.shadow_lights.iter().copied().filter(|&i| s.scene.lights[i].radius > 0.0).collect()
        },
        on: |e: &Effects| !e.soft_lights.is_empty(),
        show: |e: &Effects| lights(&e.soft_lights),
        counts: [shadow_rays],
    }
    /// Some material has a Phong highlight.
    specular: bool, "specular", tracer SPECULAR = 4 {
        derive: |s: &Survey| !s.transport && s.any_material(|m| m.specular.is_some()),
        on: |e: &Effects| e.specular,
        show: |e: &Effects| on_off(e.specular),
        counts: [],
    }
    /// Some material reflects and the depth allows a bounce.
    reflections: bool, "reflections", tracer REFLECT = 2 {
        derive: |s: &Survey| s.reflections(),
        on: |e: &Effects| e.reflections,
        show: |e: &Effects| on_off(e.reflections),
        counts: [reflection_rays],
    }
    /// Some material is transparent and the depth allows a bounce: refraction rays, the
    /// Fresnel reflections that go with them, and shadow rays through glass.
    refraction: bool, "refraction", tracer REFRACT = 16 {
        derive: |s: &Survey| s.refraction(),
        on: |e: &Effects| e.refraction,
        show: |e: &Effects| on_off(e.refraction),
        counts: [refraction_rays, reflection_rays],
    }
    /// The deepest recursion that can change a pixel (≤ the scene's `depth`).
    useful_depth: u32, "depth" {
        derive: |s: &Survey| s.useful_depth(),
        on: |e: &Effects| e.useful_depth > 0,
        show: |e: &Effects| e.useful_depth.to_string(),
        counts: [],
    }
    /// Some material is painted with a pattern (evaluated per shaded point of those
    /// materials only).
    patterns: bool, "patterns" {
        derive: |s: &Survey| s.any_material(|m| m.color.is_pattern()),
        on: |e: &Effects| e.patterns,
        show: |e: &Effects| on_off(e.patterns),
        counts: [],
    }
    /// Samples per pixel (1 = no antialiasing).
    samples: u32, "antialiasing" {
        derive: |s: &Survey| s.scene.settings.samples,
        on: |e: &Effects| e.samples > 1,
        show: |e: &Effects| if e.samples > 1 { format!("{} samples", e.samples) } else { "off".to_string() },
        counts: [],
    }
    /// Reach of ambient occlusion in world units, when asked for and there is ambient light.
    ambient_occlusion: Option<f64>, "ambient occlusion", tracer AO = 8 {
        // Occlusion only darkens ambient light; without any there is nothing to occlude.
        derive: |s: &Survey| {
            let reach = s.scene.settings.ambient_occlusion;
            (reach > 0.0 && s.ambient > 0.0 && !s.transport).then_some(reach)
        },
        on: |e: &Effects| e.ambient_occlusion.is_some(),
        show: |e: &Effects| e.ambient_occlusion.map_or("off".to_string(), |d| format!("within {}", ir::dump_num(d))),
        counts: [occlusion_rays],
    }
    /// Light transport (path tracing) and its bounces, when the scene asks for it: then
    /// the rows above that belong to Whitted shading (ambient, highlights, reflections,
    /// refraction, depth, occlusion) are off, and materials and lights are read by the
    /// physically based model instead (`render::path`).
    light_transport: Option<u32>, "light transport" {
        derive: |s: &Survey| s.transport.then(|| s.scene.settings.bounces.unwrap_or(ir::DEFAULT_BOUNCES)),
        on: |e: &Effects| e.light_transport.is_some(),
        show: |e: &Effects| e.light_transport.map_or("off".to_string(), |b| format!("{b} bounces")),
        counts: [paths, light_rays, bounce_rays],
    }
    /// Area and environment lights (light transport's own).
    transport_lights: Vec<usize>, "area and environment lights" {
        derive: |s: &Survey| s.transport_lights.clone(),
        on: |e: &Effects| !e.transport_lights.is_empty(),
        show: |e: &Effects| lights(&e.transport_lights),
        counts: [],
    }
    /// Objects that glow (indices into the scene's objects): lights under light transport.
    glowing: Vec<usize>, "glowing objects" {
        derive: |s: &Survey| s.glowing.clone(),
        on: |e: &Effects| !e.glowing.is_empty(),
        show: |e: &Effects| lights(&e.glowing),
        counts: [],
    }
}

impl Effects {
    /// Every effect on, as `--effects all` asks: the general tracer, for comparisons.
    pub fn all(scene: &Scene) -> Effects {
        let mut e = derive(scene);
        if e.light_transport.is_some() {
            // The path tracer has no effect flags: it is one integrator.
            return e;
        }
        e.reflections = scene.settings.depth > 0;
        e.refraction = scene.settings.depth > 0;
        e.useful_depth = scene.settings.depth;
        e.specular = true;
        e
    }

    /// Whether any shadow rays will be cast.
    pub fn shadows(&self) -> bool {
        !self.shadow_lights.is_empty()
    }

    /// The tracer flags of the effects that are on.
    pub fn flags(&self) -> u8 {
        TABLE.iter().filter(|e| (e.on)(self)).fold(0, |bits, e| bits | e.flag)
    }
}

impl fmt::Display for Effects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("effects: ")?;
        for (i, e) in TABLE.iter().enumerate() {
            write!(f, "{}{} {}", if i > 0 { ", " } else { "" }, e.word, (e.show)(self))?;
        }
        Ok(())
    }
}

/// What the effects are derived from: the scene, its lights sorted by what they cost,
/// and every material each object can show.
struct Survey<'a> {
    scene: &'a Scene,
    ambient: f64,
    shadow_lights: Vec<usize>,
    unshadowed_lights: Vec<usize>,
    /// Area and environment lights: only light transport shows them.
    transport_lights: Vec<usize>,
    /// By object.
    materials: Vec<Vec<ir::Material>>,
    /// Objects some part of which glows.
    glowing: Vec<usize>,
    /// Whether the scene asks for light transport: something glows, an area or
    /// environment light, or `render(bounces = …)`.
    transport: bool,
}

impl<'a> Survey<'a> {
    fn of(scene: &'a Scene) -> Survey<'a> {
        let mut shadow_lights = Vec::new();
        let mut unshadowed_lights = Vec::new();
        let mut transport_lights = Vec::new();
        let mut ambient = 0.0;
        for (i, l) in scene.lights.iter().enumerate() {
            match l.kind {
                LightKind::Ambient => ambient += l.intensity,
                LightKind::Point { .. } | LightKind::Directional { .. } if l.intensity == 0.0 => {}
                LightKind::Point { .. } | LightKind::Directional { .. } if l.shadows => shadow_lights.push(i),
                LightKind::Point { .. } | LightKind::Directional { .. } => unshadowed_lights.push(i),
                LightKind::Area { .. } | LightKind::Environment => transport_lights.push(i),
            }
        }
        let materials: Vec<Vec<ir::Material>> = scene.objects.iter().map(|o| ir::materials_of(&o.geometry)).collect();
        let glowing: Vec<usize> =
            (0..materials.len()).filter(|&i| materials[i].iter().any(ir::Material::emits)).collect();
        let transport = !transport_lights.is_empty() || !glowing.is_empty() || scene.settings.bounces.is_some();
        Survey { scene, ambient, shadow_lights, unshadowed_lights, transport_lights, materials, glowing, transport }
    }

    fn any_material(&self, test: impl Fn(&ir::Material) -> bool) -> bool {
        self.materials.iter().flatten().any(test)
    }

    fn reflections(&self) -> bool {
        !self.transport && self.scene.settings.depth > 0 && self.any_material(|m| m.reflective > 0.0)
    }

    fn refraction(&self) -> bool {
        !self.transport && self.scene.settings.depth > 0 && self.any_material(ir::Material::is_transparent)
    }

    /// A single convex object sees nothing but the background in its reflection, so one
    /// bounce is all that can show; otherwise every allowed bounce may matter. Light
    /// through glass bounces inside it, so refraction keeps the whole depth.
    fn useful_depth(&self) -> u32 {
        let objects = &self.scene.objects;
        if self.refraction() {
            self.scene.settings.depth
        } else if !self.reflections() {
            0
        } else if objects.len() == 1 && objects[0].geometry.is_convex() {
            1
        } else {
            self.scene.settings.depth
        }
    }
}
