//! Draws the CSG-at-scale chart (issue 21): render time against the number of parts,
//! log–log, one curve per way of combining them and one for evaluating the scene alone.
//! Reads `N objects union smooth check` lines (seconds) on standard input, as `scripts/csg-table.sh` writes them, and writes the
//! PNG named by its one argument.

use std::io::{Read, Write};
use std::process::ExitCode;

use plotters::chart::SeriesLabelPosition;
use plotters::style::{BLACK, BLUE, GREEN, RED};
use scnc::study::chart::{loglog, Point, Series};

fn main() -> ExitCode {
    let Some(out) = std::env::args().nth(1) else {
        let _ = writeln!(std::io::stderr(), "usage: csg_plot OUT.png < table");
        return ExitCode::from(2);
    };
    let mut text = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        let _ = writeln!(std::io::stderr(), "error: cannot read the table: {e}");
        return ExitCode::from(1);
    }
    let mut series = [
        ("N separate objects", BLUE),
        ("one union", RED),
        ("one smooth union", GREEN),
        ("evaluating the scene alone (scnc check)", BLACK),
    ]
    .map(|(name, colour)| Series { name: name.into(), colour, points: Vec::new() });
    for (line_no, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let fields: Vec<f64> = match line.split_whitespace().map(str::parse).collect() {
            Ok(f) => f,
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "error: line {}: {e}: `{line}`", line_no + 1);
                return ExitCode::from(1);
            }
        };
        let [n, times @ ..] = fields.as_slice() else { continue };
        for (s, &t) in series.iter_mut().zip(times) {
            s.points.push(Point { x: *n, y: t * 1000.0, ..Point::default() });
        }
    }
    let chart = loglog(
        "one union of N spheres vs N objects (400×400, 2 threads, whole process)",
        ("N (spheres)", "wall time (ms)"),
        &series,
        SeriesLabelPosition::UpperLeft,
    );
    let written = chart.map_err(|e| e.to_string()).and_then(|img| {
        image::save_buffer(&out, &img.pixels, img.width, img.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| e.to_string())
    });
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: cannot write `{out}`: {e}");
            ExitCode::from(1)
        }
    }
}
