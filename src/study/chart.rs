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

/// One curve of a log–log chart: its name, colour and points (x, y, optional label).
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Line and point colour.
    pub colour: RGBColor,
    /// The points, joined in this order.
    pub points: Vec<(f64, f64, Option<String>)>,
}

/// Plots `axis` against mean geometric error for every row.
pub fn error_chart(rows: &[Row], axis: Axis, title: &str) -> Result<Image, String> {
    let floor = 1e-9;
    let series = [("sdf", RED), ("mesh", BLUE)].map(|(backend, colour)| {
        let mut points: Vec<(f64, f64, Option<String>)> = rows
            .iter()
            .filter(|r| r.setting.backend() == backend)
            .map(|r| (axis.value(r).max(floor), r.geo_mean.max(floor), Some(r.setting.label())))
            .collect();
        points.sort_by(|a, b| b.1.total_cmp(&a.1));
        Series { name: backend.into(), colour, points }
    });
    loglog(title, (axis.label(), "mean geometric error (world units)"), &series, SeriesLabelPosition::UpperRight)
}

/// A log–log chart of `series` (empty ones left out), 960×640, axes described by
/// `(x, y)`, the legend at `legend`.
pub fn loglog(
    title: &str,
    (x_desc, y_desc): (&str, &str),
    series: &[Series],
    legend: SeriesLabelPosition,
) -> Result<Image, String> {
    register_font();
    let (w, h) = (960u32, 640u32);
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let all = || series.iter().flat_map(|s| s.points.iter());
        let range = |v: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = v.fold((f64::INFINITY, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
            // Whole decades: plotters' log mesh crowds its fine ticks into a band when
            // an end falls just past a power of ten.
            if lo.is_finite() && lo > 0.0 {
                (10f64.powf(lo.log10().floor()), 10f64.powf(hi.log10().ceil().max(lo.log10().floor() + 1.0)))
            } else {
                (1e-9, 1.0)
            }
        };
        let (x0, x1) = range(&mut all().map(|p| p.0));
        let (y0, y1) = range(&mut all().map(|p| p.1));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .label_style(("sans-serif", 14))
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(|e| e.to_string())?;
        for s in series.iter().filter(|s| !s.points.is_empty()) {
            let colour = s.colour;
            chart
                .draw_series(LineSeries::new(s.points.iter().map(|p| (p.0, p.1)), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(s.points.iter().map(|p| Circle::new((p.0, p.1), 4, colour.filled())))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(s.points.iter().filter_map(|p| {
                    let label = p.2.clone()?;
                    Some(Text::new(label, (p.0, p.1), ("sans-serif", 12).into_font().color(&colour)))
                }))
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .position(legend)
            .background_style(WHITE)
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(Image { width: w, height: h, depth: crate::render::BitDepth::Eight, pixels })
}

/// An axis tick as a person writes it: `10`, `0.5`, `2e-7`, not `10.0` or `0.00000020`.
fn tick(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}
