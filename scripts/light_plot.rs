//! Draws issue 60's time-to-error chart: each renderer's wall time against the RMSE of
//! its image, log–log, one curve per renderer, each point labelled with its samples per
//! pixel. Reads `SERIES SAMPLES RMSE SECONDS` lines on standard input (as
//! `benches/light_error.py --rows` writes them) and writes the PNG its one argument names.

use std::io::{Read, Write};
use std::process::ExitCode;

use plotters::chart::SeriesLabelPosition;
use scnc::study::chart::{loglog, named_rows, series_by_name, Point};

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
    let rows = match named_rows(&text, 3) {
        Ok(rows) => rows,
        Err(line) => {
            let _ = writeln!(std::io::stderr(), "error: line {line}: expected `SERIES SAMPLES RMSE SECONDS`");
            return ExitCode::from(1);
        }
    };
    let series =
        series_by_name(&rows, |n| Point { x: n[1], y: n[2], label: Some(format!("{}", n[0])), ..Point::default() });
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
