//! Draws the meshing-by-error chart (issue 62): triangles and time against the
//! deviation a mesh was measured at, log–log, one curve per mesher. Reads
//! `SERIES DEVIATION TRIANGLES SECONDS` lines on standard input (the series a word, as
//! `scripts/mesh-error-table.sh` writes them: `scnc`, `fidget`, `Manifold`) and writes
//! the PNG named by its one argument: the triangles above, the time below.

use std::io::{Read, Write};
use std::process::ExitCode;

use plotters::chart::SeriesLabelPosition;
use scnc::study::chart::{loglog, named_rows, series_by_name, Point};

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
    let rows = match named_rows(&text, 3) {
        Ok(rows) => rows,
        Err(line) => {
            let _ = writeln!(std::io::stderr(), "error: line {line}: expected `SERIES DEVIATION TRIANGLES SECONDS`");
            return ExitCode::from(1);
        }
    };
    let triangles = series_by_name(&rows, |n| Point { x: n[0], y: n[1], ..Point::default() });
    let seconds = series_by_name(&rows, |n| Point { x: n[0], y: n[2], ..Point::default() });
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
