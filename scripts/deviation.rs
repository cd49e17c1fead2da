//! How far a mesh file lies from the surface of a scene's first object, measured as
//! `scnc export --stats` measures its own isosurfaces (`mesh::deviation`), but at every
//! point of a barycentric grid on every triangle, for meshes made by other tools (issue
//! 62's comparison with fidget and Manifold, `docs/performance.md`):
//! `cargo run --release --example deviation -- SCENE MESH [--scale S] [--up y|z|none] [--steps N] [--reach R]`.
//! `--scale` is the file's units per scene unit, `--up` its up axis (by default what
//! `scnc export` writes: STL and 3MF 10 and z, the others 1 and y; `none` for a file that
//! holds the field's own coordinates, as fidget and Manifold write them); the grid has
//! `N` steps a side (default 4: 15 points a triangle); `R` is the first reach probed
//! (default 0.01); `--worst K` also lists the K farthest points with their triangles.

use std::io::Write;
use std::process::ExitCode;

use glam::DAffine3;
use rayon::prelude::*;
use scnc::geom::axes::{from_file, to_file, Up};
use scnc::mesh::deviation::{distance, nearer};
use scnc::mesh::samples::IsoField;
use scnc::meshfile::Format;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(1)
        }
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: deviation SCENE MESH [--scale S] [--up y|z|none] [--steps N] [--reach R] [--worst K]";
    let (scene, mesh) = match &args[..] {
        [s, m, ..] => (s.clone(), m.clone()),
        _ => return Err(usage.into()),
    };
    let option = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let ext = std::path::Path::new(&mesh).extension().and_then(|e| e.to_str()).unwrap_or("").to_lowercase();
    let format = Format::from_extension(&ext).ok_or(format!("`{mesh}`: not a mesh file scnc reads"))?;
    let scale: f64 = option("--scale").map_or(Ok(format.default_scale()), |s| s.parse()).map_err(|_| usage)?;
    let up = match option("--up").as_deref() {
        Some("z") => Some(Up::Z),
        Some("y") => Some(Up::Y),
        Some("none") => None,
        None => Some(format.default_up()),
        Some(_) => return Err(usage.into()),
    };
    let steps: usize = option("--steps").map_or(Ok(4), |s| s.parse()).map_err(|_| usage)?;
    let reach: f64 = option("--reach").map_or(Ok(0.01), |s| s.parse()).map_err(|_| usage)?;
    let worst: usize = option("--worst").map_or(Ok(0), |s| s.parse()).map_err(|_| usage)?;

    let text = std::fs::read_to_string(&scene).map_err(|e| format!("`{scene}`: {e}"))?;
    let compiled = scnc::compile_file(&scene, std::path::Path::new(&scene), text, &scnc::source::FsLoader);
    let ir = compiled.scene.ok_or(format!("`{scene}` has errors: run `scnc check` on it"))?;
    let Some(scnc::ir::Body::Shape(shape)) = ir.objects.first().map(|o| &o.geometry) else {
        return Err(format!("`{scene}`'s first object is not a shape"));
    };
    let mut materials = scnc::trace::MaterialTable::default();
    let (dist, surf) = scnc::sdf::Builder::new(&mut materials).build(shape, DAffine3::IDENTITY, 0);
    let field = IsoField { dist: &*dist, surf: &*surf };

    let bytes = std::fs::read(&mesh).map_err(|e| format!("`{mesh}`: {e}"))?;
    let mut m = format.read(&bytes).map_err(|e| format!("`{mesh}`: {e}"))?;
    // The reader turned the file's frame into scnc's as the format's defaults say: back
    // to the file's numbers, then into scnc's as told.
    for p in &mut m.positions {
        let file = to_file(*p, format.default_up()) * format.default_scale();
        *p = up.map_or(file, |up| from_file(file, up)) / scale;
    }
    // Every point's distance (NaN where none was found), with its triangle and place.
    let mut points: Vec<(f64, usize, glam::DVec3, glam::DVec3)> = m
        .triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(k, t)| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            (0..=steps).flat_map(move |i| {
                (0..=steps - i).map(move |j| {
                    let p = a + (b - a) * (i as f64 / steps as f64) + (c - a) * (j as f64 / steps as f64);
                    let found = distance(field, p, n, reach);
                    (found.map_or(f64::NAN, |f| f.0), k, p, found.map_or(n, |f| f.1))
                })
            })
        })
        .collect();
    // The farthest points, searched around their direction for a nearer crossing: the
    // fixed directions can miss it at a crease (a midpoint read 5.7e-3 that the
    // mesher's own probe proved within 4e-3). The top thousandth and a margin below it.
    points.par_sort_unstable_by(|x, y| y.0.total_cmp(&x.0));
    let top = (points.len() / 1000).max(100).min(points.len());
    points[..top].par_iter_mut().for_each(|(d, _, p, dir)| {
        if !d.is_nan() {
            *d = nearer(field, *p, *d, *dir);
        }
    });
    let lost = points.iter().filter(|d| d.0.is_nan()).count();
    let mut all: Vec<f64> = points.iter().map(|d| d.0).filter(|d| !d.is_nan()).collect();
    all.par_sort_unstable_by(f64::total_cmp);
    let at = |q: f64| all.get(((all.len() as f64 - 1.0) * q).round() as usize).copied().unwrap_or(0.0);
    let mean = all.iter().sum::<f64>() / all.len().max(1) as f64;
    let (open, _) = m.open_edges();
    let _ = writeln!(
        std::io::stdout(),
        "{mesh}: {} triangles, {open} open or non-manifold edges; deviation max {:.3e}, 99.99 % {:.3e}, 99.9 % {:.3e}, \
         99 % {:.3e}, median {:.3e}, mean {mean:.3e} over {} points{}",
        m.triangles.len(),
        at(1.0),
        at(0.9999),
        at(0.999),
        at(0.99),
        at(0.5),
        all.len(),
        if lost > 0 { format!(" ({lost} not resolved)") } else { String::new() }
    );
    if worst > 0 {
        let mut far: Vec<_> = points.iter().filter(|d| !d.0.is_nan()).collect();
        far.sort_unstable_by(|x, y| y.0.total_cmp(&x.0));
        for (d, k, p, _) in far.into_iter().take(worst) {
            let corners = m.triangles[*k].map(|i| m.positions[i as usize]);
            let f = corners.map(|c| format!("{:.2e}", field.at(c))).join(", ");
            let _ = writeln!(
                std::io::stdout(),
                "  {d:.3e} at {p:.5} on triangle {k}: corners {corners:.5?}, f there {f}, f here {:.2e}",
                field.at(*p)
            );
        }
    }
    Ok(())
}
