//! `scnc measure`: each object's volume, centre of mass, bounding box and inertia as
//! proved intervals, beside its mesh's figures and surface area; a table for people, one
//! JSON object per object for tools.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use scnc::measure::{Bounds, MeasureOptions, Measured};
use scnc::source::FsLoader;

use super::shared::{Messages, Params, Workers};
use super::{compile, report, usage_error, MessageFormat};

#[derive(clap::Args)]
pub(crate) struct MeasureArgs {
    /// The scene file.
    file: PathBuf,
    /// How wide the volume's interval may be, relative to the volume: `0.1%` or `0.001`.
    #[arg(long, value_parser = parse_relative, default_value = "0.1%")]
    tolerance: f64,
    /// Most cells the proofs may evaluate, shared evenly by the objects and the total
    /// (time and memory grow with it); when a share runs out first, the interval reached
    /// is given, with a warning.
    #[arg(long, value_parser = clap::value_parser!(u64).range(4096..=1 << 34), default_value_t = scnc::measure::DEFAULT_CELLS)]
    cells: u64,
    /// The mesh estimate's tessellation detail: `low`, `high` or N rings (default 64:
    /// 128-point circles, a sphere within 0.2 % of its volume).
    #[arg(long, value_parser = super::shared::parse_detail, default_value = "64")]
    detail: scnc::mesh::Detail,
    #[command(flatten)]
    workers: Workers,
    #[command(flatten)]
    messages: Messages,
    #[command(flatten)]
    params: Params,
}

/// A relative tolerance: a fraction in (0, 1), or a percentage with `%`.
fn parse_relative(s: &str) -> Result<f64, String> {
    let (digits, scale) = match s.strip_suffix('%') {
        Some(d) => (d, 0.01),
        None => (s, 1.0),
    };
    match digits.trim().parse::<f64>() {
        Ok(x) if x * scale > 0.0 && x * scale < 1.0 => Ok(x * scale),
        _ => Err(format!("`{s}` is not a relative tolerance: try `0.1%` or `0.001` (above 0, below 1)")),
    }
}

/// `scnc measure`.
pub(crate) fn measure_cmd(args: MeasureArgs) -> ExitCode {
    let format = args.messages.message_format;
    let pool = match args.workers.pool() {
        Ok(p) => p,
        Err(e) => return usage_error(&e),
    };
    let Some(mut compiled) = compile(&args.file, format, &args.params) else { return ExitCode::from(1) };
    super::drop_render_only(&mut compiled);
    if report(&compiled, format) {
        return ExitCode::from(1);
    }
    let Some(scene) = compiled.scene.take() else { return ExitCode::from(1) };
    if scene.objects.is_empty() {
        let _ = writeln!(std::io::stderr(), "error: `{}` has no objects to measure", args.file.display());
        return ExitCode::from(1);
    }
    let opts = MeasureOptions {
        tolerance: args.tolerance,
        cells: args.cells,
        detail: args.detail,
        memory_limit: scnc::mesh::lower::DEFAULT_MEMORY_LIMIT,
    };
    let started = std::time::Instant::now();
    let measured = match pool.install(|| scnc::measure::measure(&scene, &opts, &FsLoader)) {
        Ok(m) => m,
        Err(d) => {
            super::report_in(&compiled.map, &[d], format);
            return ExitCode::from(1);
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let line = |span: Option<scnc::span::Span>| {
        span.map_or_else(String::new, |s| {
            let (id, range) = compiled.map.local_range(s);
            format!(" (line {})", compiled.map.line_col(id, range.start).0)
        })
    };
    let mut out = std::io::stdout().lock();
    let text = match format {
        MessageFormat::Json => measured.iter().map(|m| format!("{}\n", json(m))).collect::<String>(),
        MessageFormat::Human => {
            let mut t = String::new();
            for m in &measured {
                t.push_str(&table(m, &line(m.span)));
            }
            t.push_str(&format!("measured in {seconds:.2} s\n"));
            t
        }
    };
    let _ = out.write_all(text.as_bytes());
    let short: Vec<(&str, f64)> = measured
        .iter()
        .filter_map(|m| m.proved.as_ref().filter(|p| !p.met).map(|p| (m.name.as_str(), p.volume.relative_width())))
        .collect();
    if let Some(&(name, widest)) = short.iter().max_by(|a, b| a.1.total_cmp(&b.1)) {
        let _ = writeln!(
            std::io::stderr(),
            "warning: {} of {} volume intervals are wider than --tolerance {} % (the widest, `{name}`, {:.3} %): \
             their cells ran out first; a proved interval narrows as 1/√cells, and `--cells` gives more",
            short.len(),
            measured.iter().filter(|m| m.proved.is_some()).count(),
            100.0 * args.tolerance,
            100.0 * widest
        );
    }
    ExitCode::SUCCESS
}

fn iv(i: &Bounds) -> serde_json::Value {
    serde_json::json!([i.lo, i.hi])
}

/// One object as JSON: every proved figure an interval `[lo, hi]`, the mesh's figures numbers.
fn json(m: &Measured) -> serde_json::Value {
    let proved = m.proved.as_ref().map(|p| {
        serde_json::json!({
            "volume": iv(&p.volume),
            "mass": iv(&p.mass),
            "centre_of_mass": p.centre.iter().map(iv).collect::<Vec<_>>(),
            "bounds": { "min": p.min.iter().map(iv).collect::<Vec<_>>(), "max": p.max.iter().map(iv).collect::<Vec<_>>() },
            "inertia": p.inertia.iter().map(|row| row.iter().map(iv).collect::<Vec<_>>()).collect::<Vec<_>>(),
            "tolerance_met": p.met,
            "bound_stated": p.stated,
            "cells": p.cells,
            "cell_size": p.cell,
        })
    });
    let mesh = m.mesh.as_ref().map(|e| {
        serde_json::json!({
            "volume": e.volume, "mass": e.mass, "surface_area": e.area, "centre_of_mass": e.centre.to_array(),
            "bounds": { "min": e.min.to_array(), "max": e.max.to_array() }, "inertia": e.inertia,
            "triangles": e.triangles,
        })
    });
    serde_json::json!({ "object": m.name, "density": m.density, "proved": proved, "mesh": mesh })
}

/// A figure as `lo … hi`, with as many digits as tell the ends apart.
fn range(i: &Bounds) -> String {
    if !(i.lo.is_finite() && i.hi.is_finite()) {
        return format!("{} … {}", i.lo, i.hi);
    }
    let width = (i.hi - i.lo).abs().max(i.mid().abs() * 1e-12).max(1e-300);
    let digits = (-(width.log10().floor()) + 1.0).clamp(0.0, 15.0) as usize;
    format!("{:.*} … {:.*}", digits, i.lo, digits, i.hi)
}

fn num(x: f64) -> String {
    format!("{x:.6}")
}

/// One object's rows.
fn table(m: &Measured, line: &str) -> String {
    let density = match m.density {
        Some(1.0) => String::new(),
        Some(d) => format!(", density {d}"),
        None if m.span.is_none() => {
            ", objects of different densities (not proved as one; the mesh weighs each by its own)".into()
        }
        None => ", parts of different densities (mass and inertia at density 1)".into(),
    };
    let mut t = format!("{}{line}{density}\n", m.name);
    let row = |t: &mut String, what: &str, proved: String, mesh: String| {
        t.push_str(&format!("  {what:<16} {proved:<44} {mesh}\n"));
    };
    row(&mut t, "", "proved (distance bound)".into(), "mesh".into());
    let p = m.proved.as_ref();
    let e = m.mesh.as_ref();
    let or_dash = |s: Option<String>| s.unwrap_or_else(|| "—".into());
    row(
        &mut t,
        "volume",
        or_dash(p.map(|p| format!("{} (±{:.3} %)", range(&p.volume), 50.0 * p.volume.relative_width()))),
        or_dash(e.map(|e| num(e.volume))),
    );
    row(&mut t, "mass", or_dash(p.map(|p| range(&p.mass))), or_dash(e.map(|e| num(e.mass))));
    row(&mut t, "surface area", "— (no bound: see docs/measure.md)".into(), or_dash(e.map(|e| num(e.area))));
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let what = format!("centre {axis}");
        row(&mut t, &what, or_dash(p.map(|p| range(&p.centre[k]))), or_dash(e.map(|e| num(e.centre[k]))));
    }
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let what = format!("bounds {axis}");
        let proved = p.map(|p| format!("{} to {}", range(&p.min[k]), range(&p.max[k])));
        row(&mut t, &what, or_dash(proved), or_dash(e.map(|e| format!("{} to {}", num(e.min[k]), num(e.max[k])))));
    }
    let names = ["xx", "yy", "zz", "xy", "yz", "zx"];
    let at = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)];
    for (name, (i, j)) in names.iter().zip(at) {
        let what = format!("inertia {name}");
        row(&mut t, &what, or_dash(p.map(|p| range(&p.inertia[i][j]))), or_dash(e.map(|e| num(e.inertia[i][j]))));
    }
    if let Some(p) = p {
        let sure = if p.stated { "; rests on the scene's stated `lipschitz`" } else { "" };
        t.push_str(&format!("  ({} cells, finest {:.3e}{sure})\n", p.cells, p.cell));
    }
    t
}
