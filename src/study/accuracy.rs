//! Accuracy metrics: how far a render's geometry and colours are from a reference.
//!
//! - **Geometric error**: for each primary hit, `|d(p)|` where `d` is the scene's own SDF
//!   (the SDF back-end's evaluator, min over objects). It is the exact distance to the
//!   surface for primitives under rigid transforms and sharp unions, intersections and
//!   subtractions' outer faces (every seed scene), and a lower bound otherwise. It is
//!   evaluated in f32 render space, so it resolves errors down to about 1e-6 of the
//!   distance from the camera.
//! - **Coverage error**: pixels whose centre ray hits geometry in one render and not in the other.
//! - **Image error**: RMSE over all channels (0–255) and the PSNR derived from it.
//!
//! The reference for coverage and image error is the SDF render at an extreme setting
//! (`epsilon = 1e-6`, a 100 000-step budget): its hit points lie within 1e-6 of the
//! distance from the camera of the true surface, far below any setting being judged.

use glam::Vec3A;

use crate::render::{Frame, Image};
use crate::trace::{Counters, Geometry, Ray};
use crate::world::World;

/// Where each pixel's centre ray first hits geometry (render space), `None` for a miss.
pub fn primary_hits(world: &World, frame: &Frame) -> Vec<Option<Vec3A>> {
    let mut c = Counters::default();
    (0..frame.width * frame.height)
        .map(|i| {
            let dir = frame.direction((i % frame.width) as f32 + 0.5, (i / frame.width) as f32 + 0.5);
            world.intersect(&Ray::new(Vec3A::ZERO, dir, frame.max_distance), &mut c).map(|h| h.point)
        })
        .collect()
}

/// Mean and maximum of `|distance(p)|` over the hit points; `(0, 0)` when there are none.
pub fn geometric_error(hits: &[Option<Vec3A>], distance: &dyn Fn(Vec3A) -> f32) -> (f64, f64) {
    let errors: Vec<f64> = hits.iter().flatten().map(|p| distance(*p).abs() as f64).collect();
    if errors.is_empty() {
        return (0.0, 0.0);
    }
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    (mean, errors.iter().copied().fold(0.0, f64::max))
}

/// The largest geometric error in pixels: `|distance(p)|` over the footprint of a pixel
/// at the hit's distance from the camera (`pixel_angle · |p|` in render space).
pub fn geometric_error_pixels(hits: &[Option<Vec3A>], distance: &dyn Fn(Vec3A) -> f32, pixel_angle: f64) -> f64 {
    hits.iter()
        .flatten()
        .map(|p| distance(*p).abs() as f64 / (pixel_angle * p.length() as f64).max(f64::MIN_POSITIVE))
        .fold(0.0, f64::max)
}

/// Pixels where exactly one of the two renders hits geometry.
pub fn coverage_error(a: &[Option<Vec3A>], b: &[Option<Vec3A>]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x.is_some() != y.is_some()).count()
}

/// Root-mean-square difference over all channels, in 0–255 units.
pub fn rmse(a: &Image, b: &Image) -> f64 {
    let n = a.pixels.len().min(b.pixels.len()).max(1);
    let sum: f64 = a.pixels.iter().zip(&b.pixels).map(|(x, y)| (*x as f64 - *y as f64).powi(2)).sum();
    (sum / n as f64).sqrt()
}

/// Peak signal-to-noise ratio in dB for an RMSE (infinite for identical images).
pub fn psnr(rmse: f64) -> f64 {
    if rmse == 0.0 {
        f64::INFINITY
    } else {
        20.0 * (255.0 / rmse).log10()
    }
}

/// The distance to the nearest surface of a scene lowered as SDFs, at a render-space point.
pub fn scene_distance(world: &World) -> impl Fn(Vec3A) -> f32 + '_ {
    move |p| (0..world.len()).filter_map(|i| world.sdf_eval(i, p)).fold(f32::INFINITY, f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: Vec<u8>) -> Image {
        Image { width: (pixels.len() / 3) as u32, height: 1, depth: crate::render::BitDepth::Eight, pixels }
    }

    #[test]
    fn image_metrics_match_hand_computed_values() {
        let a = image(vec![0, 0, 0, 10, 10, 10]);
        let b = image(vec![0, 0, 0, 10, 10, 10]);
        assert_eq!(rmse(&a, &b), 0.0);
        assert_eq!(psnr(0.0), f64::INFINITY);
        // One channel off by 6 of six: RMSE = sqrt(36 / 6) = sqrt(6).
        let c = image(vec![6, 0, 0, 10, 10, 10]);
        assert!((rmse(&a, &c) - 6f64.sqrt()).abs() < 1e-12);
        // RMSE 255 is 0 dB; each tenfold drop adds 20 dB.
        assert!(psnr(255.0).abs() < 1e-12 && (psnr(25.5) - 20.0).abs() < 1e-9);
    }

    #[test]
    fn hit_metrics_match_hand_computed_values() {
        let unit_sphere = |p: Vec3A| p.length() - 1.0;
        let hits = vec![
            Some(Vec3A::new(1.0, 0.0, 0.0)),
            Some(Vec3A::new(0.0, 1.5, 0.0)),
            None,
            Some(Vec3A::new(0.0, 0.0, 0.5)),
        ];
        let (mean, max) = geometric_error(&hits, &unit_sphere);
        assert!((mean - (0.0 + 0.5 + 0.5) / 3.0).abs() < 1e-6 && (max - 0.5).abs() < 1e-6);
        assert_eq!(geometric_error(&[None, None], &unit_sphere), (0.0, 0.0));
        let other = vec![Some(Vec3A::ZERO), None, None, None];
        assert_eq!(coverage_error(&hits, &other), 2);
    }
}
