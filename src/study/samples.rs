//! What accuracy costs under light transport: the samples ladder. The same scene at
//! 1, 4, 16, … samples a pixel, each rung's error against a reference render of many
//! more samples (or an image given), its own noise estimate, and its wall time — the
//! error falling as 1/√N (or faster, with the stratified sampler) is the price of
//! accuracy in time, plotted by [`chart`].

use plotters::style::RGBColor;

use super::chart::{loglog, Point, Series};
use crate::diag::Diagnostic;
use crate::ir::Scene;
use crate::render::{BitDepth, Image};
use crate::source::Loader;
use crate::world::Mode;

/// One rung of the ladder.
#[derive(Clone, Debug, PartialEq)]
pub struct Rung {
    /// Samples a pixel.
    pub samples: u32,
    /// Wall time of the render (lowering excluded), seconds.
    pub seconds: f64,
    /// RMSE against the reference over the reference's mean: the error as a share of the
    /// image's light.
    pub relative_rmse: f64,
    /// The render's own estimate: the mean relative standard error of a pixel (none at
    /// one sample a pixel).
    pub estimated_noise: Option<f64>,
    /// Rays cast.
    pub rays: u64,
}

/// The rungs: powers of four from 1 to `most`.
pub fn ladder(most: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&n| n.checked_mul(4)).take_while(|&n| n <= most.max(1)).collect()
}

/// `scene` at `samples` a pixel as linear float radiance, its wall time and counters,
/// on the current rayon pool.
fn render(
    scene: &Scene,
    samples: u32,
    loader: &dyn Loader,
) -> Result<(Vec<f32>, f64, crate::trace::Counters), Diagnostic> {
    let mut s = scene.clone();
    s.settings.samples = samples;
    s.settings.noise = None;
    let effects = crate::render::effects::derive(&s);
    let (mut frame, world) = crate::world::prepare(&s, effects, Mode::Sdf, loader)?;
    frame.bit_depth = BitDepth::Float;
    let started = std::time::Instant::now();
    let (image, counters) = crate::render::render(&world, &frame, &|| {});
    Ok((image.floats(), started.elapsed().as_secs_f64(), counters))
}

/// Renders each rung of `rungs` and measures it against `reference` (float radiance of
/// the same size), or against a render of 16 × the last rung's samples when `None`;
/// `progress` hears of each render before it starts.
pub fn run(
    scene: &Scene,
    rungs: &[u32],
    reference: Option<Vec<f32>>,
    loader: &dyn Loader,
    progress: &dyn Fn(&str),
) -> Result<Vec<Rung>, Diagnostic> {
    let reference = match reference {
        Some(r) => r,
        None => {
            let most = rungs.last().copied().unwrap_or(1).saturating_mul(16).min(crate::check::MAX_SAMPLES);
            progress(&format!("the reference, {most} samples a pixel"));
            render(scene, most, loader)?.0
        }
    };
    let mean = reference.iter().map(|&v| f64::from(v)).sum::<f64>() / reference.len().max(1) as f64;
    let mut out = Vec::with_capacity(rungs.len());
    for &n in rungs {
        progress(&format!("{n} samples a pixel"));
        let (img, seconds, c) = render(scene, n, loader)?;
        let se: f64 = img.iter().zip(&reference).map(|(a, b)| (f64::from(*a) - f64::from(*b)).powi(2)).sum();
        let rmse = (se / img.len().max(1) as f64).sqrt();
        out.push(Rung {
            samples: n,
            seconds,
            relative_rmse: rmse / mean.max(f64::MIN_POSITIVE),
            estimated_noise: (c.noise_pixels > 0).then(|| c.noise_ppm as f64 / c.noise_pixels as f64 / 1e6),
            rays: c.rays(),
        });
    }
    Ok(out)
}

/// The ladder as CSV.
pub fn csv(rungs: &[Rung]) -> String {
    let mut s = String::from("samples,seconds,relative_rmse,estimated_noise,rays\n");
    for r in rungs {
        let noise = r.estimated_noise.map_or(String::new(), |e| format!("{e:.6e}"));
        s += &format!("{},{:.6},{:.6e},{noise},{}\n", r.samples, r.seconds, r.relative_rmse, r.rays);
    }
    s
}

/// The ladder as a Markdown table, with the fitted slope of log error against log
/// samples (−0.5 is Monte Carlo's 1/√N).
pub fn markdown(rungs: &[Rung], title: &str) -> String {
    let mut s = format!("# Samples against error: {title}\n\n");
    s += "| samples a pixel | time (s) | relative RMSE against the reference | estimated noise | rays |\n";
    s += "|---|---|---|---|---|\n";
    for r in rungs {
        s += &format!(
            "| {} | {:.3} | {:.3} % | {} | {} |\n",
            r.samples,
            r.seconds,
            100.0 * r.relative_rmse,
            r.estimated_noise.map_or("—".to_string(), |e| format!("{:.3} %", 100.0 * e)),
            r.rays
        );
    }
    if let Some(slope) = slope(rungs) {
        s += &format!("\nFitted slope of log error against log samples: {slope:.3} (1/√N is −0.5).\n");
    }
    s
}

/// The least-squares slope of log relative RMSE against log samples, if two rungs have
/// an error.
pub fn slope(rungs: &[Rung]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = rungs
        .iter()
        .filter(|r| r.relative_rmse > 0.0)
        .map(|r| (f64::from(r.samples).ln(), r.relative_rmse.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let var = pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    (var > 0.0).then(|| pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / var)
}

/// Time against error, log–log: the measured error, the render's own estimate, and the
/// 1/√N line through the first rung (time grows with samples, so 1/√time).
pub fn chart(rungs: &[Rung], title: &str) -> Result<Image, String> {
    let point = |r: &Rung, y: f64, label: bool| Point {
        x: r.seconds.max(1e-6),
        y: y.max(1e-9),
        label: label.then(|| format!("{} spp", r.samples)),
        ..Point::default()
    };
    let measured = rungs.iter().map(|r| point(r, r.relative_rmse, true)).collect();
    let estimated = rungs.iter().filter_map(|r| Some(point(r, r.estimated_noise?, false))).collect();
    let line = match rungs.first() {
        Some(f) => rungs
            .iter()
            .map(|r| point(r, f.relative_rmse * (f.seconds.max(1e-6) / r.seconds.max(1e-6)).sqrt(), false))
            .collect(),
        None => Vec::new(),
    };
    let series = [
        Series { name: "relative RMSE against the reference".into(), colour: RGBColor(200, 60, 40), points: measured },
        Series { name: "estimated noise (the render's own)".into(), colour: RGBColor(40, 110, 200), points: estimated },
        Series { name: "1/√time through the first rung".into(), colour: RGBColor(130, 130, 130), points: line },
    ];
    loglog(
        title,
        ("render time (s)", "error relative to the image's mean"),
        &series,
        plotters::chart::SeriesLabelPosition::UpperRight,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ladder_is_powers_of_four_up_to_the_most() {
        assert_eq!(ladder(1024), vec![1, 4, 16, 64, 256, 1024]);
        assert_eq!(ladder(100), vec![1, 4, 16, 64]);
        assert_eq!(ladder(0), vec![1]);
    }

    #[test]
    fn the_slope_of_a_square_root_law_is_minus_a_half() {
        let rung = |n: u32| Rung {
            samples: n,
            seconds: f64::from(n),
            relative_rmse: 0.3 / f64::from(n).sqrt(),
            estimated_noise: Some(0.01),
            rays: 0,
        };
        let rungs: Vec<Rung> = ladder(4096).into_iter().map(rung).collect();
        assert!((slope(&rungs).expect("a slope") + 0.5).abs() < 1e-9);
        assert!(chart(&rungs, "t").is_ok());
    }
}
