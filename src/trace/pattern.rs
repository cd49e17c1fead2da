//! Patterns ready for shading: the IR's pattern trees, each with the map from render
//! space into the space of the object it paints (the noise is `geom::noise`).
//!
//! Patterns are evaluated in f64. An object's space can be world-sized (a floor is
//! painted in world coordinates), and there f32 keeps too few digits: 1e4 from the
//! origin its step is 1e-3, and a floor lying on a checker boundary would take either
//! side's colour by the last bit of the point read just inside it.

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3A};

use crate::geom::noise;
use crate::ir::{self, ColorSpace, Paint, PatternKind};

/// A pattern as one material shows it: where render-space points go, then the tree.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadePattern {
    /// Render space to the painted object's space.
    pub to_local: DAffine3,
    /// The pattern.
    pub texture: Texture,
}

impl ShadePattern {
    /// The colour at the render-space point `p` (linear, 0–255).
    pub fn color_at(&self, p: Vec3A) -> Vec3A {
        self.texture.at(self.to_local.transform_point3(p.as_dvec3())).as_vec3a()
    }
}

/// A paint ready to evaluate, colours already in linear light (0–255).
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// One colour.
    Solid(DVec3),
    /// Two paints laid out by a pattern.
    Pattern(Arc<(TextureKind, Texture, Texture)>),
}

/// [`PatternKind`] with the divisions done once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TextureKind {
    /// `1 / size`.
    Checker(f64),
    /// The axis, unit, divided by the width.
    Stripes(DVec3),
    /// `from`, and `(to − from) / |to − from|²`.
    Gradient(DVec3, DVec3),
    /// `1 / size` and the seed.
    Noise(f64, u32),
}

impl Texture {
    /// The texture of a paint, its colours read in `space`.
    pub fn new(paint: &Paint, space: ColorSpace) -> Texture {
        match paint {
            Paint::Solid(c) => Texture::Solid(linear(c.as_vec3a(), space).as_dvec3()),
            Paint::Pattern(p) => {
                let kind = match p.kind {
                    PatternKind::Checker { size } => TextureKind::Checker(1.0 / size),
                    PatternKind::Stripes { width, axis } => TextureKind::Stripes(axis.normalize() / width),
                    PatternKind::Gradient { from, to } => {
                        let d = to - from;
                        TextureKind::Gradient(from, d / d.length_squared())
                    }
                    PatternKind::Noise { size, seed } => TextureKind::Noise(1.0 / size, seed),
                };
                Texture::Pattern(Arc::new((kind, Texture::new(&p.a, space), Texture::new(&p.b, space))))
            }
        }
    }

    /// The colour at `p` in the painted object's space.
    pub fn at(&self, p: DVec3) -> DVec3 {
        let (kind, a, b) = match self {
            Texture::Solid(c) => return *c,
            Texture::Pattern(node) => &**node,
        };
        let pick = |second: bool| if second { b.at(p) } else { a.at(p) };
        match *kind {
            TextureKind::Checker(inv) => {
                let c = (p * inv).floor();
                // Saturating casts: a point beyond i64's cells stays in one cell, not UB.
                pick((c.x as i64).wrapping_add(c.y as i64).wrapping_add(c.z as i64) & 1 != 0)
            }
            TextureKind::Stripes(axis) => pick((p.dot(axis).floor() as i64) & 1 != 0),
            TextureKind::Gradient(from, d) => {
                let t = (p - from).dot(d).clamp(0.0, 1.0);
                a.at(p) * (1.0 - t) + b.at(p) * t
            }
            TextureKind::Noise(inv, seed) => {
                let t = (0.5 + 0.5 * noise(p * inv, seed)).clamp(0.0, 1.0);
                a.at(p) * (1.0 - t) + b.at(p) * t
            }
        }
    }
}

/// A colour as written, 0–255, in linear light for shading.
pub fn linear(c: Vec3A, space: ColorSpace) -> Vec3A {
    match space {
        ColorSpace::Linear => c,
        ColorSpace::Srgb => Vec3A::from_array(c.to_array().map(|x| srgb_to_linear(x / 255.0) * 255.0)),
    }
}

/// A linear colour, 0–255, as pixels in `space` hold it.
pub fn encoded(c: Vec3A, space: ColorSpace) -> Vec3A {
    match space {
        ColorSpace::Linear => c,
        ColorSpace::Srgb => Vec3A::from_array(c.to_array().map(|x| linear_to_srgb(x / 255.0) * 255.0)),
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1), on [0, 1].
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function (IEC 61966-2-1), on [0, 1].
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The texture of a material and where it sits, if it has a pattern.
pub fn of_material(m: &ir::Material, render_from_local: DAffine3, space: ColorSpace) -> Option<ShadePattern> {
    m.color
        .is_pattern()
        .then(|| ShadePattern { to_local: render_from_local.inverse(), texture: Texture::new(&m.color, space) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips() {
        for i in 0..=255 {
            let x = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(x)) - x).abs() < 1e-5, "{i}");
        }
        assert!((srgb_to_linear(0.5) - 0.214).abs() < 1e-3);
    }
}
