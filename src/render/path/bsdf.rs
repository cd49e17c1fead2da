//! Today's materials read as a physically based, energy-conserving BSDF.
//!
//! A material is a mixture of three lobes whose weights sum to 1, so the mixture
//! conserves energy if each lobe does:
//!
//! - **glass**, weight `transparency`: a smooth dielectric of index `ior` (exact Fresnel
//!   reflectance, Snell refraction; Beer–Lambert `absorption` inside, applied by the
//!   integrator along each segment);
//! - **mirror**, weight `(1 − transparency)·reflective`: perfect, untinted reflection, as
//!   Whitted shading blends it;
//! - **base**, the rest: `(1 − F)·colour/π` (Lambert) plus, for a material with a
//!   `specular` exponent `s`, `F·(s + 2)/(2π)·cos^s α` (the normalised modified Phong
//!   lobe around the mirror direction, whose albedo never exceeds 1), where `F` is
//!   Schlick's Fresnel reflectance of a dielectric coat (f0 = 0.04) at the viewing angle.
//!   The base's albedo is `F·A_phong + (1 − F)·colour ≤ 1`.
//!
//! Colours are albedos: 255 (or a white pattern cell) reflects all the light.

use glam::Vec3A;

use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Schlick's f0 of the dielectric coat over a glossy base (index 1.5).
const COAT_F0: f32 = 0.04;

/// A surface's BSDF at one point, in render space, the normal facing the viewer.
pub struct Bsdf {
    /// Shading normal on the side the ray came from.
    pub normal: Vec3A,
    /// Diffuse albedo, 0–1 per channel.
    pub albedo: Vec3A,
    /// The Phong exponent of the glossy lobe, if any.
    pub exponent: Option<f32>,
    /// Weight of the glass lobe.
    pub glass: f32,
    /// Weight of the mirror lobe.
    pub mirror: f32,
    /// Fresnel reflectance of the coat for this view.
    pub coat: f32,
}

/// A direction the BSDF scattered into.
pub struct Scatter {
    /// Unit direction.
    pub dir: Vec3A,
    /// `f·cos/pdf`: what the path's throughput is multiplied by.
    pub weight: Vec3A,
    /// The density of `dir` (per steradian; 0 for a delta lobe).
    pub pdf: f32,
}

/// Which lobe a sample chose.
pub enum Lobe {
    /// The base lobe, with the direction it scattered into.
    Base(Scatter),
    /// The mirror.
    Mirror,
    /// The glass: the integrator splits it by Fresnel itself, as it knows the media.
    Glass,
}

impl Bsdf {
    /// The BSDF of a material seen along `view` (unit, towards the viewer) at a point
    /// whose normal faces the viewer.
    pub fn new(normal: Vec3A, view: Vec3A, albedo: Vec3A, exponent: Option<f32>, glass: f32, mirror: f32) -> Bsdf {
        let coat = if exponent.is_some() {
            let c = (1.0 - normal.dot(view).clamp(0.0, 1.0)).powi(5);
            COAT_F0 + (1.0 - COAT_F0) * c
        } else {
            0.0
        };
        Bsdf { normal, albedo, exponent, glass, mirror, coat }
    }

    /// The weight of the base lobe.
    pub fn base(&self) -> f32 {
        (1.0 - self.glass - self.mirror).max(0.0)
    }

    /// `f(view, w)` of the non-delta part (the base lobe times its weight).
    pub fn eval(&self, view: Vec3A, w: Vec3A) -> Vec3A {
        let cos_i = self.normal.dot(w);
        if cos_i <= 0.0 {
            return Vec3A::ZERO;
        }
        let mut f = self.albedo * ((1.0 - self.coat) * FRAC_1_PI);
        if let Some(s) = self.exponent {
            f += Vec3A::splat(self.coat * (s + 2.0) / TAU * self.phong(view, w, s));
        }
        f * self.base()
    }

    /// The density with which [`sample`](Self::sample) picks `w` through the base lobe.
    pub fn pdf(&self, view: Vec3A, w: Vec3A) -> f32 {
        let cos_i = self.normal.dot(w);
        if cos_i <= 0.0 {
            return 0.0;
        }
        let mut p = (1.0 - self.coat) * cos_i * FRAC_1_PI;
        if let Some(s) = self.exponent {
            p += self.coat * (s + 1.0) / TAU * self.phong(view, w, s);
        }
        p * self.base()
    }

    /// `cos^s α` between `w` and the mirror direction of `view`.
    fn phong(&self, view: Vec3A, w: Vec3A, s: f32) -> f32 {
        let r = self.normal * (2.0 * self.normal.dot(view)) - view;
        r.dot(w).max(0.0).powf(s)
    }

    /// Chooses a lobe with `u_lobe` and, for the base lobe, a direction with `(u1, u2)`.
    pub fn sample(&self, view: Vec3A, u_lobe: f32, (u1, u2): (f32, f32)) -> Option<Lobe> {
        if u_lobe < self.glass {
            return Some(Lobe::Glass);
        }
        if u_lobe < self.glass + self.mirror {
            return Some(Lobe::Mirror);
        }
        let base = self.base();
        if base <= 0.0 {
            return None;
        }
        // Within the base: the glossy lobe with the coat's probability, else diffuse.
        let (t, b) = basis(self.normal);
        let dir = match self.exponent {
            Some(s) if u1 < self.coat => {
                let u1 = u1 / self.coat;
                let r = self.normal * (2.0 * self.normal.dot(view)) - view;
                let (rt, rb) = basis(r);
                let cos_a = u1.powf(1.0 / (s + 1.0));
                let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
                let phi = TAU * u2;
                (rt * (sin_a * phi.cos()) + rb * (sin_a * phi.sin()) + r * cos_a).normalize()
            }
            _ => {
                let u1 = if self.exponent.is_some() { (u1 - self.coat) / (1.0 - self.coat) } else { u1 };
                let r = u1.clamp(0.0, 1.0).sqrt();
                let phi = TAU * u2;
                (t * (r * phi.cos()) + b * (r * phi.sin()) + self.normal * (1.0 - r * r).max(0.0).sqrt()).normalize()
            }
        };
        let pdf = self.pdf(view, dir) / base;
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        let cos_i = self.normal.dot(dir);
        // The base's own f·cos/pdf: its weight cancels against the chance of choosing it.
        let weight = self.eval(view, dir) / base * (cos_i / pdf);
        Some(Lobe::Base(Scatter { dir, weight, pdf: pdf * base }))
    }
}

/// Two unit vectors completing `n` (unit) to an orthonormal basis (Duff et al. 2017).
pub fn basis(n: Vec3A) -> (Vec3A, Vec3A) {
    let sign = 1f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3A::new(b, sign + n.y * n.y * a, -n.y))
}

/// A direction cosine-distributed about `n`, and its density.
pub fn cosine(n: Vec3A, (u1, u2): (f32, f32)) -> (Vec3A, f32) {
    let (t, b) = basis(n);
    let r = u1.sqrt();
    let phi = TAU * u2;
    let cos = (1.0 - u1).max(0.0).sqrt();
    ((t * (r * phi.cos()) + b * (r * phi.sin()) + n * cos).normalize(), cos / PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The base lobe's albedo by Monte Carlo over its own samples never exceeds 1, and
    /// its `eval`/`pdf` agree with what `sample` returns.
    #[test]
    fn the_base_lobe_conserves_energy_and_agrees_with_its_sampler() {
        let n = Vec3A::Y;
        for exponent in [None, Some(1.0), Some(10.0), Some(100.0), Some(10_000.0)] {
            for cos_v in [1.0f32, 0.5, 0.1, 0.01] {
                let view = Vec3A::new((1.0 - cos_v * cos_v).sqrt(), cos_v, 0.0);
                let bsdf = Bsdf::new(n, view, Vec3A::ONE, exponent, 0.0, 0.0);
                let mut sum = 0.0f64;
                let count = 64 * 64;
                for i in 0..count {
                    let u = ((i % 64) as f32 + 0.5) / 64.0;
                    let v = ((i / 64) as f32 + 0.5) / 64.0;
                    if let Some(Lobe::Base(s)) = bsdf.sample(view, 0.9, (u, v)) {
                        let expect = bsdf.eval(view, s.dir) * n.dot(s.dir) / s.pdf;
                        assert!((expect - s.weight).abs().max_element() < 1e-3 * expect.max_element().max(1.0));
                        sum += f64::from(s.weight.x);
                    }
                }
                let albedo = sum / count as f64;
                assert!(albedo <= 1.0 + 0.02, "exponent {exponent:?}, cos {cos_v}: albedo {albedo}");
                if exponent.is_none() {
                    assert!((albedo - 1.0).abs() < 1e-3, "Lambert of albedo 1 keeps all: {albedo}");
                }
            }
        }
    }

    #[test]
    fn the_basis_is_orthonormal() {
        for n in [Vec3A::X, Vec3A::NEG_Z, Vec3A::new(0.3, -0.4, 0.866).normalize(), Vec3A::new(0.0, 0.0, -1.0)] {
            let (t, b) = basis(n);
            for (a, c) in [(t, b), (t, n), (b, n)] {
                assert!(a.dot(c).abs() < 1e-5);
            }
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
        }
    }
}
