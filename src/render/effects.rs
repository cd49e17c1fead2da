//! The effect set: which parts of the shading model a scene calls for, derived from the
//! IR alone, so the tracer is built with those and no others.
//!
//! Derived facts: whether any light casts shadows (`shadows = false` opts a light out;
//! ambient light never casts), whether any material reflects or lets light through (and
//! how deep recursion can matter), whether any material has a specular highlight or a
//! pattern, the total ambient intensity, and the optional extras the scene asked for
//! (`render(samples = n)`).

use std::fmt;

use crate::ir::{self, Geometry, LightKind, Scene, ShapeKind};

/// The effects one scene needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Effects {
    /// Lights that cast shadows (indices into the scene's lights).
    pub shadow_lights: Vec<usize>,
    /// Point and directional lights that cast none.
    pub unshadowed_lights: Vec<usize>,
    /// Total ambient intensity.
    pub ambient: f64,
    /// Some material reflects and the depth allows a bounce.
    pub reflections: bool,
    /// Some material is transparent and the depth allows a bounce: refraction rays, the
    /// Fresnel reflections that go with them, and shadow rays through glass.
    pub refraction: bool,
    /// The deepest recursion that can change a pixel (≤ the scene's `depth`).
    pub useful_depth: u32,
    /// Some material is painted with a pattern (evaluated per shaded point of those
    /// materials only).
    pub patterns: bool,
    /// Some material has a Phong highlight.
    pub specular: bool,
    /// Samples per pixel (1 = no antialiasing).
    pub samples: u32,
    /// Casting point lights with a radius (soft shadows).
    pub soft_lights: Vec<usize>,
    /// Reach of ambient occlusion in world units, when asked for and there is ambient light.
    pub ambient_occlusion: Option<f64>,
}

impl Effects {
    /// Every effect on, as `--effects all` asks: the general tracer, for comparisons.
    pub fn all(scene: &Scene) -> Effects {
        let mut e = derive(scene);
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
}

fn materials_of_shape(shape: &ir::Shape, out: &mut Vec<ir::Material>) {
    if let ShapeKind::Paint { material, .. } = &shape.kind {
        out.push((**material).clone());
    }
    shape.children().iter().for_each(|c| materials_of_shape(c, out));
}

/// Every material an object can show, plus the default grey when some part has none.
fn materials_of(geometry: &Geometry) -> Vec<ir::Material> {
    let mut out = Vec::new();
    match geometry {
        Geometry::Shape(s) => {
            materials_of_shape(s, &mut out);
            if !painted_everywhere(s) {
                out.push(ir::Material::default_grey());
            }
        }
        Geometry::Mesh(m) => {
            out.push(m.material.as_deref().cloned().unwrap_or_else(ir::Material::default_grey));
            if let ir::MeshSource::Isosurface { shape, .. } = &m.source {
                materials_of_shape(shape, &mut out);
            }
        }
    }
    out
}

/// Whether every leaf of the tree has a material above it.
fn painted_everywhere(shape: &ir::Shape) -> bool {
    match &shape.kind {
        ShapeKind::Paint { .. } => true,
        // A field's surface is its own: the shapes its body measures paint nothing.
        ShapeKind::Primitive(_) | ShapeKind::Field { .. } => false,
        ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. }
        | ShapeKind::Csg { .. }
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Repeat { .. }
        | ShapeKind::Transform { .. } => shape.children().iter().all(|c| painted_everywhere(c)),
    }
}

/// Derives the effect set of a scene.
pub fn derive(scene: &Scene) -> Effects {
    let mut shadow_lights = Vec::new();
    let mut unshadowed_lights = Vec::new();
    let mut ambient = 0.0;
    for (i, l) in scene.lights.iter().enumerate() {
        match l.kind {
            LightKind::Ambient => ambient += l.intensity,
            LightKind::Point { .. } | LightKind::Directional { .. } if l.intensity == 0.0 => {}
            LightKind::Point { .. } | LightKind::Directional { .. } if l.shadows => shadow_lights.push(i),
            LightKind::Point { .. } | LightKind::Directional { .. } => unshadowed_lights.push(i),
        }
    }
    let per_object: Vec<Vec<ir::Material>> = scene.objects.iter().map(|o| materials_of(&o.geometry)).collect();
    let reflective_objects = per_object.iter().filter(|ms| ms.iter().any(|m| m.reflective > 0.0)).count();
    let reflections = reflective_objects > 0 && scene.settings.depth > 0;
    let refraction = per_object.iter().flatten().any(ir::Material::is_transparent) && scene.settings.depth > 0;
    // A single convex object sees nothing but the background in its reflection, so one
    // bounce is all that can show; otherwise every allowed bounce may matter. Light
    // through glass bounces inside it, so refraction keeps the whole depth.
    let useful_depth = if refraction {
        scene.settings.depth
    } else if !reflections {
        0
    } else if scene.objects.len() == 1 && scene.objects[0].geometry.is_convex() {
        1
    } else {
        scene.settings.depth
    };
    let specular = per_object.iter().flatten().any(|m| m.specular.is_some());
    let soft_lights = shadow_lights.iter().copied().filter(|&i| scene.lights[i].radius > 0.0).collect();
    Effects {
        shadow_lights,
        unshadowed_lights,
        ambient,
        reflections,
        refraction,
        useful_depth,
        patterns: per_object.iter().flatten().any(|m| m.color.is_pattern()),
        specular,
        samples: scene.settings.samples,
        soft_lights,
        // Occlusion only darkens ambient light; without any there is nothing to occlude.
        ambient_occlusion: (scene.settings.ambient_occlusion > 0.0 && ambient > 0.0)
            .then_some(scene.settings.ambient_occlusion),
    }
}

impl fmt::Display for Effects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let list = |v: &[usize]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.iter().map(|i| format!("#{i}")).collect::<Vec<_>>().join(", ")
            }
        };
        write!(
            f,
            "effects: ambient {}, shadow rays from {}, unshadowed lights {}, soft shadows from {}, specular {}, reflections {}, refraction {}, patterns {}, antialiasing {}, ambient occlusion {}",
            ir::dump_num(self.ambient),
            list(&self.shadow_lights),
            list(&self.unshadowed_lights),
            list(&self.soft_lights),
            if self.specular { "on" } else { "off" },
            if self.reflections { format!("up to depth {}", self.useful_depth) } else { "off".to_string() },
            if self.refraction { format!("up to depth {}", self.useful_depth) } else { "off".to_string() },
            if self.patterns { "on" } else { "off" },
            if self.samples > 1 { format!("{} samples", self.samples) } else { "off".to_string() },
            self.ambient_occlusion.map_or("off".to_string(), |d| format!("within {}", ir::dump_num(d))),
        )
    }
}
