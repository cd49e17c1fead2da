//! Charts of a sweep: time and memory against geometric error, log–log, one curve per
//! back-end, each point labelled by its setting. Drawn with plotters into memory; text
//! uses the bundled DejaVu Sans, so no system font is needed.

use std::sync::Once;

use plotters::prelude::*;

use super::sweep::Row;
use crate::render::Image;

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bundled font is a valid TrueType file; if it were not, text would be missing
        // from the chart and drawing would report the error.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../../assets/DejaVuSans.ttf"),
        );
    });
}

/// What the x axis shows.
#[derive(Clone, Copy, Debug)]
pub enum Axis {
    /// Median wall time, milliseconds.
    Time,
    /// Geometry bytes.
    Memory,
}

impl Axis {
    fn value(self, r: &Row) -> f64 {
        match self {
            Axis::Time => r.wall_ms,
            Axis::Memory => r.bytes as f64,
        }
    }

    fn label(self) -> &'static str {
        match self {
            Axis::Time => "wall time per render (ms, lowering + tracing)",
            Axis::Memory => "geometry memory (bytes)",
        }
    }
}

/// Plots `axis` against mean geometric error for every row.
pub fn error_chart(rows: &[Row], axis: Axis, title: &str) -> Result<Image, String> {
    register_font();
    let (w, h) = (960u32, 640u32);
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let floor = 1e-9;
        let points: Vec<(f64, f64)> = rows.iter().map(|r| (axis.value(r).max(floor), r.geo_mean.max(floor))).collect();
        let range = |v: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = v.fold((f64::INFINITY, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
            if lo.is_finite() {
                (lo / 1.6, hi * 1.6)
            } else {
                (floor, 1.0)
            }
        };
        let (x0, x1) = range(&mut points.iter().map(|p| p.0));
        let (y0, y1) = range(&mut points.iter().map(|p| p.1));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(axis.label())
            .y_desc("mean geometric error (world units)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        for (backend, colour) in [("sdf", RED), ("mesh", BLUE)] {
            let mut pts: Vec<(f64, f64, String)> = rows
                .iter()
                .zip(&points)
                .filter(|(r, _)| r.setting.backend() == backend)
                .map(|(r, p)| (p.0, p.1, r.setting.label()))
                .collect();
            if pts.is_empty() {
                continue;
            }
            pts.sort_by(|a, b| b.1.total_cmp(&a.1));
            chart
                .draw_series(LineSeries::new(pts.iter().map(|p| (p.0, p.1)), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(backend)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 4, colour.filled())))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|p| Text::new(p.2.clone(), (p.0, p.1), ("sans-serif", 12).into_font().color(&colour))),
                )
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE)
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(Image { width: w, height: h, pixels })
}
