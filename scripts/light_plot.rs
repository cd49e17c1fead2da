//! Draws issue 60's time-to-error chart: each renderer's wall time against the RMSE of
//! its image, log–log, one curve per renderer, each point labelled with its samples per
//! pixel. Reads `SERIES SAMPLES RMSE SECONDS` lines on standard input (as
//! `benches/light_error.py --rows` writes them) and writes the PNG its one argument names.

use std::io::{Read, Write};
use std::process::ExitCode;

use plotters::chart::SeriesLabelPosition;
use plotters::style::{RGBColor, BLACK, BLUE, GREEN, MAGENTA, RED};
use scnc::study::chart::{loglog, Point, Series};

fn main() -> ExitCode {
    let Some(out) = std::env::args().nth(1) else {
        let _ = writeln!(std::io::stderr(), "usage: light_plot OUT.png < rows");
        return ExitCode::from(2);
    };
    let mut text = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        let _ = writeln!(std::io::stderr(), "error: cannot read the rows: {e}");
        return ExitCode::from(1);
    }
    let colours = [BLUE, RED, GREEN, MAGENTA, BLACK, RGBColor(200, 120, 0)];
    let mut series: Vec<Series> = Vec::new();
    for (line_no, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#')) {
        let words: Vec<&str> = line.split_whitespace().collect();
        let numbers: Result<Vec<f64>, _> = words.iter().skip(1).map(|w| w.parse::<f64>()).collect();
        let (name, [samples, rmse, seconds]) = match (words.first(), numbers.as_deref()) {
            (Some(n), Ok([s, r, t])) => (*n, [*s, *r, *t]),
            _ => {
                let _ =
                    writeln!(std::io::stderr(), "error: line {}: expected `SERIES SAMPLES RMSE SECONDS`", line_no + 1);
                return ExitCode::from(1);
            }
        };
        let k = series.iter().position(|s| s.name == name).unwrap_or_else(|| {
            let colour = colours[series.len() % colours.len()];
            series.push(Series { name: name.into(), colour, points: Vec::new() });
            series.len() - 1
        });
        series[k].points.push(Point { x: rmse, y: seconds, label: Some(format!("{samples}")), ..Point::default() });
    }
    let chart = loglog(
        "time against error: the Cornell box (labels: samples per pixel)",
        ("RMSE against the converged image (radiance)", "wall seconds, 2 threads"),
        &series,
        SeriesLabelPosition::UpperRight,
    );
    match chart.and_then(|c| {
        image::save_buffer(&out, &c.pixels, c.width, c.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| e.to_string())
    }) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: cannot write `{out}`: {e}");
            ExitCode::from(1)
        }
    }
}
