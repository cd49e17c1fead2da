//! The sweep's rows as CSV and as a Markdown table, from one list of columns.

use std::fmt::Write as _;

use super::sweep::Row;

/// One column: its CSV name, its Markdown heading, and its cell in each format.
struct Column {
    csv: &'static str,
    heading: &'static str,
    csv_cell: fn(&Row) -> String,
    md_cell: fn(&Row) -> String,
}

/// Every column, in order.
const COLUMNS: &[Column] = &[
    Column {
        csv: "backend",
        heading: "back-end",
        csv_cell: |r| r.setting.backend().into(),
        md_cell: |r| r.setting.backend().into(),
    },
    Column { csv: "setting", heading: "setting", csv_cell: |r| r.setting.label(), md_cell: |r| r.setting.label() },
    Column {
        csv: "wall_ms",
        heading: "wall",
        csv_cell: |r| format!("{:.3}", r.wall_ms),
        md_cell: |r| format!("{:.1} ms", r.wall_ms),
    },
    Column {
        csv: "rays_per_s",
        heading: "rays/s",
        csv_cell: |r| format!("{:.0}", r.rays_per_s),
        md_cell: |r| format!("{:.2} M", r.rays_per_s / 1e6),
    },
    Column {
        csv: "sdf_evals_per_ray",
        heading: "evals/ray",
        csv_cell: |r| format!("{:.3}", r.evals_per_ray),
        md_cell: |r| format!("{:.2}", r.evals_per_ray),
    },
    Column {
        csv: "node_visits_per_ray",
        heading: "visits/ray",
        csv_cell: |r| format!("{:.3}", r.visits_per_ray),
        md_cell: |r| format!("{:.2}", r.visits_per_ray),
    },
    Column {
        csv: "triangle_tests_per_ray",
        heading: "tri tests/ray",
        csv_cell: |r| format!("{:.3}", r.tests_per_ray),
        md_cell: |r| format!("{:.2}", r.tests_per_ray),
    },
    Column {
        csv: "geometry_bytes",
        heading: "bytes",
        csv_cell: |r| r.bytes.to_string(),
        md_cell: |r| r.bytes.to_string(),
    },
    Column {
        csv: "triangles",
        heading: "triangles",
        csv_cell: |r| r.triangles.to_string(),
        md_cell: |r| r.triangles.to_string(),
    },
    Column {
        csv: "peak_rss_kib",
        heading: "peak RSS",
        csv_cell: |r| r.peak_rss_kib.map_or(String::new(), |k| k.to_string()),
        md_cell: |r| r.peak_rss_kib.map_or("n/a".to_string(), |k| format!("{:.1} MiB", k as f64 / 1024.0)),
    },
    Column {
        csv: "geo_error_mean",
        heading: "geo error mean",
        csv_cell: |r| format!("{:e}", r.geo_mean),
        md_cell: |r| format!("{:.2e}", r.geo_mean),
    },
    Column {
        csv: "geo_error_max",
        heading: "geo error max",
        csv_cell: |r| format!("{:e}", r.geo_max),
        md_cell: |r| format!("{:.2e}", r.geo_max),
    },
    Column {
        csv: "geo_error_max_pixels",
        heading: "max in pixels",
        csv_cell: |r| format!("{:.4}", r.geo_max_px),
        md_cell: |r| format!("{:.3}", r.geo_max_px),
    },
    Column {
        csv: "coverage_error_px",
        heading: "coverage px",
        csv_cell: |r| r.coverage.to_string(),
        md_cell: |r| r.coverage.to_string(),
    },
    Column {
        csv: "rmse",
        heading: "RMSE",
        csv_cell: |r| format!("{:.4}", r.rmse),
        md_cell: |r| format!("{:.2}", r.rmse),
    },
    Column {
        csv: "psnr_db",
        heading: "PSNR",
        csv_cell: |r| format!("{:.2}", r.psnr),
        md_cell: |r| format!("{:.1} dB", r.psnr),
    },
];

/// The header line of `sweep.csv`.
pub fn csv_header() -> String {
    COLUMNS.iter().map(|c| c.csv).collect::<Vec<_>>().join(",")
}

/// Rows as CSV.
pub fn csv(rows: &[Row]) -> String {
    let mut out = csv_header() + "\n";
    for r in rows {
        let cells: Vec<String> = COLUMNS.iter().map(|c| (c.csv_cell)(r)).collect();
        let _ = writeln!(out, "{}", cells.join(","));
    }
    out
}

/// Rows as a Markdown table.
pub fn markdown(rows: &[Row], title: &str) -> String {
    let mut out = format!(
        "# Sweep: {title}\n\nReference: the SDF render at epsilon 1e-6 with a 100 000-step budget. Geometric error is |d| at primary hits, in world units.\n\n"
    );
    let headings: Vec<&str> = COLUMNS.iter().map(|c| c.heading).collect();
    let _ = writeln!(out, "| {} |", headings.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(COLUMNS.len()));
    for r in rows {
        let cells: Vec<String> = COLUMNS.iter().map(|c| (c.md_cell)(r)).collect();
        let _ = writeln!(out, "| {} |", cells.join(" | "));
    }
    out
}
