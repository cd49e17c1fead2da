//! Charts of a sweep: time, work and memory against geometric error, log–log, one curve
//! per back-end, each point labelled by its setting, the Pareto front ringed. Drawn with plotters into memory; text
//! uses the bundled DejaVu Sans, so no system font is needed.

use std::sync::Once;

use plotters::prelude::*;

use super::sweep::{Row, Setting};

/// The step budget of every rung of the thresholds' ladder (`Settings::default`'s).
const DEFAULT_STEPS: u32 = 512;
use crate::render::Image;

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bundled font is a valid TrueType file; if it were not, text would be missing
        // from the chart and drawing would report the error.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, crate::geom::font::DEFAULT_FONT);
    });
}

/// What the x axis shows.
#[derive(Clone, Copy, Debug)]
pub enum Axis {
    /// Median wall time, milliseconds, with the fastest and slowest run as a bar.
    Time,
    /// Unit operations per frame (see [`Row::work`]): the same on every run and machine.
    Work,
    /// Geometry bytes.
    Memory,
}

impl Axis {
    fn value(self, r: &Row) -> f64 {
        match self {
            Axis::Time => r.time.median_ms,
            Axis::Work => r.work as f64,
            Axis::Memory => r.bytes as f64,
        }
    }

    /// The spread of the value over the runs, where there is one.
    fn range(self, r: &Row) -> Option<(f64, f64)> {
        match self {
            Axis::Time => Some((r.time.min_ms, r.time.max_ms)),
            Axis::Work | Axis::Memory => None,
        }
    }

    fn label(self) -> &'static str {
        match self {
            Axis::Time => "wall time per render (ms, lowering + tracing; bars: fastest to slowest run)",
            Axis::Work => "work per frame (primitive evaluations + BVH visits + triangle tests)",
            Axis::Memory => "geometry memory (bytes)",
        }
    }
}

/// One point of a chart.
#[derive(Clone, Debug, Default)]
pub struct Point {
    /// Where it is.
    pub x: f64,
    /// Where it is.
    pub y: f64,
    /// Its label, if it has one.
    pub label: Option<String>,
    /// A horizontal bar through it (the spread of `x`), if any.
    pub x_range: Option<(f64, f64)>,
    /// Whether it is on the Pareto front of its chart (ringed).
    pub front: bool,
}

/// One curve of a log–log chart: its name, colour and points.
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Line and point colour.
    pub colour: RGBColor,
    /// The points, joined in this order.
    pub points: Vec<Point>,
}

/// The colours measurement charts give their series, in order of first appearance.
pub const PALETTE: [RGBColor; 6] = [BLUE, RED, GREEN, MAGENTA, BLACK, RGBColor(200, 120, 0)];

/// The rows of a measurement table, `NAME x₁ … xₙ` with `columns` numbers each (blank
/// lines and `#` comments skipped), or the number (from 1) of the first line that is not
/// one: what `scripts/mesh-error-table.sh` and `benches/light_error.py` write for their
/// charts.
pub fn named_rows(text: &str, columns: usize) -> Result<Vec<(&str, Vec<f64>)>, usize> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|(n, line)| {
            let mut words = line.split_whitespace();
            let name = words.next().ok_or(n + 1)?;
            let numbers: Vec<f64> = words.map(str::parse).collect::<Result<_, _>>().map_err(|_| n + 1)?;
            (numbers.len() == columns).then_some((name, numbers)).ok_or(n + 1)
        })
        .collect()
}

/// One series per name of `rows`, in order of first appearance and coloured from
/// [`PALETTE`], each row a point made by `point` from its numbers.
pub fn series_by_name(rows: &[(&str, Vec<f64>)], point: impl Fn(&[f64]) -> Point) -> Vec<Series> {
    let mut series: Vec<Series> = Vec::new();
    for (name, numbers) in rows {
        let k = series.iter().position(|s| s.name == *name).unwrap_or_else(|| {
            series.push(Series {
                name: (*name).into(),
                colour: PALETTE[series.len() % PALETTE.len()],
                points: Vec::new(),
            });
            series.len() - 1
        });
        series[k].points.push(point(numbers));
    }
    series
}

/// Plots `axis` against mean geometric error for every row, one curve per back-end; the
/// settings no other beats in both cost and error (the Pareto front) are ringed.
pub fn error_chart(rows: &[Row], axis: Axis, title: &str) -> Result<Image, String> {
    let floor = 1e-9;
    let point = |r: &Row| Point {
        x: axis.value(r).max(floor),
        y: r.geo_mean.max(floor),
        label: Some(r.setting.label()),
        x_range: axis.range(r),
        front: false,
    };
    let all: Vec<Point> = rows.iter().map(point).collect();
    let dominated = |p: &Point| all.iter().any(|q| q.x <= p.x && q.y <= p.y && (q.x < p.x || q.y < p.y));
    // The thresholds and the step budgets are two knobs: each its own curve.
    let curve = |r: &Row| match r.setting {
        Setting::Sdf { max_steps, .. } if max_steps < DEFAULT_STEPS => 1,
        Setting::Sdf { .. } => 0,
        Setting::Mesh(_) => 2,
    };
    let series = [("sdf", RED), ("sdf, fewer steps", RGBColor(230, 140, 0)), ("mesh", BLUE)]
        .into_iter()
        .enumerate()
        .map(|(k, (name, colour))| {
            let mut points: Vec<Point> = rows
                .iter()
                .filter(|r| curve(r) == k)
                .map(|r| {
                    let p = point(r);
                    Point { front: !dominated(&p), ..p }
                })
                .collect();
            points.sort_by(|a, b| b.y.total_cmp(&a.y));
            Series { name: name.into(), colour, points }
        });
    let series: Vec<Series> = series.collect();
    loglog(title, (axis.label(), "mean geometric error (world units)"), &series, SeriesLabelPosition::UpperRight)
}

/// A log–log chart of `series` (empty ones left out), 960×640, axes described by
/// `(x, y)`, the legend at `legend`. Labels are placed beside their points where they
/// overlap no label placed before them, and left out where no place is free.
///
/// Long because it draws one SVG in reading order: frame, grid and ticks, series, labels.
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
        let xs = |p: &Point| {
            let (a, b) = p.x_range.unwrap_or((p.x, p.x));
            [a.max(f64::MIN_POSITIVE), p.x, b]
        };
        let (x0, x1) = range(&mut all().flat_map(xs));
        let (y0, y1) = range(&mut all().map(|p| p.y));
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
                .draw_series(LineSeries::new(s.points.iter().map(|p| (p.x, p.y)), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(s.points.iter().filter_map(|p| {
                    let (a, b) = p.x_range?;
                    Some(PathElement::new(vec![(a, p.y), (b, p.y)], colour.stroke_width(1)))
                }))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(s.points.iter().map(|p| Circle::new((p.x, p.y), 4, colour.filled())))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(
                    s.points.iter().filter(|p| p.front).map(|p| Circle::new((p.x, p.y), 8, BLACK.stroke_width(2))),
                )
                .map_err(|e| e.to_string())?;
        }
        // Labels last, each where it overlaps nothing placed so far: right of its point,
        // then left, above or below.
        let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
        let font = ("sans-serif", 12).into_font();
        let style = TextStyle::from(font.clone());
        for s in series.iter() {
            for p in &s.points {
                let Some(label) = &p.label else { continue };
                let (px, py) = chart.backend_coord(&(p.x, p.y));
                let (tw, th) = root.estimate_text_size(label, &style).map_err(|e| e.to_string())?;
                let (tw, th) = (tw as i32, th as i32);
                let spots = [
                    (px + 8, py - th / 2),
                    (px - 8 - tw, py - th / 2),
                    (px - tw / 2, py - 10 - th),
                    (px - tw / 2, py + 10),
                ];
                let free = spots.into_iter().find(|&(x, y)| {
                    let b = (x, y, x + tw, y + th);
                    b.0 >= 0
                        && b.1 >= 0
                        && b.2 <= w as i32
                        && b.3 <= h as i32
                        && placed.iter().all(|q| b.2 < q.0 || q.2 < b.0 || b.3 < q.1 || q.3 < b.1)
                });
                if let Some((x, y)) = free {
                    placed.push((x, y, x + tw, y + th));
                    root.draw(&Text::new(label.clone(), (x, y), font.clone().color(&s.colour)))
                        .map_err(|e| e.to_string())?;
                }
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows are read by name with their numbers, comments and blank lines skipped; a line
    /// with a word for a number or the wrong count is named by its number.
    #[test]
    fn named_rows_read_and_name_bad_lines() {
        let rows = named_rows("# head\nscnc 1 2\n\nfidget 3 4\nscnc 5 6\n", 2).expect("rows");
        assert_eq!(rows, vec![("scnc", vec![1.0, 2.0]), ("fidget", vec![3.0, 4.0]), ("scnc", vec![5.0, 6.0])]);
        assert_eq!(named_rows("a 1 2\nb 1 x\n", 2), Err(2));
        assert_eq!(named_rows("a 1 2 3\n", 2), Err(1));
        let series = series_by_name(&rows, |n| Point { x: n[0], y: n[1], ..Point::default() });
        assert_eq!(
            series.iter().map(|s| (s.name.as_str(), s.points.len())).collect::<Vec<_>>(),
            [("scnc", 2), ("fidget", 1)]
        );
        assert_eq!((series[0].colour, series[1].colour), (PALETTE[0], PALETTE[1]));
    }
}
