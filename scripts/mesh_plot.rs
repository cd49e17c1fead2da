//! Draws the meshing-by-error chart (issue 62): triangles and time against the
//! deviation a mesh was measured at, log–log, one curve per mesher. Reads
//! `SERIES DEVIATION TRIANGLES SECONDS` lines on standard input (the series a word, as
//! `scripts/mesh-error-table.sh` writes them: `scnc`, `fidget`, `Manifold`) and writes
//! the PNG named by its one argument: the triangles above, the time below.

use std::io::{Read, Write};
use std::process::ExitCode;

use plotters::chart::SeriesLabelPosition;
use plotters::style::{RGBColor, BLACK, BLUE, GREEN, MAGENTA, RED};
use scnc::study::chart::{loglog, Point, Series};

fn main() -> ExitCode {
    let Some(out) = std::env::args().nth(1) else {
        let _ = writeln!(std::io::stderr(), "usage: mesh_plot OUT.png < table");
        return ExitCode::from(2);
    };
    let mut text = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        let _ = writeln!(std::io::stderr(), "error: cannot read the table: {e}");
        return ExitCode::from(1);
    }
    let colours = [BLUE, RED, GREEN, MAGENTA, BLACK, RGBColor(200, 120, 0)];
    let (mut triangles, mut seconds): (Vec<Series>, Vec<Series>) = (Vec::new(), Vec::new());
    for (line_no, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#')) {
        let words: Vec<&str> = line.split_whitespace().collect();
        let numbers: Result<Vec<f64>, _> = words.iter().skip(1).map(|w| w.parse::<f64>()).collect();
        let (name, [deviation, tris, secs]) = match (words.first(), numbers.as_deref()) {
            (Some(n), Ok([d, t, s])) => (*n, [*d, *t, *s]),
            _ => {
                let _ = writeln!(
                    std::io::stderr(),
                    "error: line {}: expected `SERIES DEVIATION TRIANGLES SECONDS`",
                    line_no + 1
                );
                return ExitCode::from(1);
            }
        };
        let k = match triangles.iter().position(|s| s.name == name) {
            Some(k) => k,
            None => {
                let colour = colours[triangles.len() % colours.len()];
                triangles.push(Series { name: name.into(), colour, points: Vec::new() });
                seconds.push(Series { name: name.into(), colour, points: Vec::new() });
                triangles.len() - 1
            }
        };
        triangles[k].points.push(Point { x: deviation, y: tris, ..Point::default() });
        seconds[k].points.push(Point { x: deviation, y: secs, ..Point::default() });
    }
    let upper = loglog(
        "triangles against the measured maximum deviation",
        ("maximum deviation from the surface (scene units)", "triangles"),
        &triangles,
        SeriesLabelPosition::UpperRight,
    );
    let lower = loglog(
        "time against the measured maximum deviation (whole process, 2 threads)",
        ("maximum deviation from the surface (scene units)", "seconds"),
        &seconds,
        SeriesLabelPosition::UpperRight,
    );
    let written = upper.and_then(|a| lower.map(|b| (a, b))).and_then(|(a, b)| {
        let mut pixels = a.pixels;
        pixels.extend_from_slice(&b.pixels);
        image::save_buffer(&out, &pixels, a.width, a.height + b.height, image::ExtendedColorType::Rgb8)
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
