//! The sweep's rows as CSV and as a Markdown table, from one list of columns.

use std::fmt::Write as _;

use super::sweep::Row;

/// How a column's value is shown: in full in the CSV, rounded for people in Markdown.
enum Cell {
    /// Text, the same in both.
    Text(fn(&Row) -> String),
    /// A count, the same in both.
    Count(fn(&Row) -> usize),
    /// A decimal: `csv` digits in the CSV; in Markdown, times `scale`, to `md` digits,
    /// followed by `unit`.
    Fixed { get: fn(&Row) -> f64, csv: usize, md: usize, scale: f64, unit: &'static str },
    /// A small error: full precision in the CSV, three significant digits in Markdown.
    Sci(fn(&Row) -> f64),
    /// KiB if measured: empty in the CSV and `n/a` in Markdown when not.
    Kib(fn(&Row) -> Option<u64>),
    /// Milliseconds if measured, likewise.
    Ms(fn(&Row) -> Option<f64>),
}

impl Cell {
    fn csv(&self, r: &Row) -> String {
        match self {
            Cell::Text(get) => get(r),
            Cell::Count(get) => get(r).to_string(),
            Cell::Fixed { get, csv, .. } => format!("{:.*}", csv, get(r)),
            Cell::Sci(get) => format!("{:e}", get(r)),
            Cell::Kib(get) => get(r).map_or(String::new(), |k| k.to_string()),
            Cell::Ms(get) => get(r).map_or(String::new(), |ms| format!("{ms:.3}")),
        }
    }

    fn markdown(&self, r: &Row) -> String {
        match self {
            Cell::Text(get) => get(r),
            Cell::Count(get) => get(r).to_string(),
            Cell::Fixed { get, md, scale, unit, .. } => format!("{:.*}{unit}", md, get(r) * scale),
            Cell::Sci(get) => format!("{:.2e}", get(r)),
            Cell::Kib(get) => get(r).map_or("n/a".to_string(), |k| format!("{:.1} MiB", k as f64 / 1024.0)),
            Cell::Ms(get) => get(r).map_or("n/a".to_string(), |ms| format!("{ms:.1} ms")),
        }
    }
}

/// A decimal shown to `csv` digits in the CSV and `md` in Markdown, unscaled.
const fn fixed(get: fn(&Row) -> f64, csv: usize, md: usize) -> Cell {
    Cell::Fixed { get, csv, md, scale: 1.0, unit: "" }
}

/// Every column in order: its CSV name, its Markdown heading, and its cell.
const COLUMNS: &[(&str, &str, Cell)] = &[
    ("backend", "back-end", Cell::Text(|r| r.setting.backend().into())),
    ("setting", "setting", Cell::Text(|r| r.setting.label())),
    ("work", "work", Cell::Count(|r| r.work as usize)),
    ("runs", "runs", Cell::Count(|r| r.time.runs)),
    ("wall_ms_min", "wall min", Cell::Fixed { get: |r| r.time.min_ms, csv: 3, md: 1, scale: 1.0, unit: " ms" }),
    ("wall_ms", "wall median", Cell::Fixed { get: |r| r.time.median_ms, csv: 3, md: 1, scale: 1.0, unit: " ms" }),
    ("wall_ms_max", "wall max", Cell::Fixed { get: |r| r.time.max_ms, csv: 3, md: 1, scale: 1.0, unit: " ms" }),
    ("wall_ci_ms", "± (95 %)", Cell::Fixed { get: |r| r.time.ci_ms, csv: 3, md: 1, scale: 1.0, unit: " ms" }),
    ("cpu_ms", "CPU", Cell::Ms(|r| r.time.cpu_ms)),
    ("rays_per_s", "rays/s", Cell::Fixed { get: |r| r.rays_per_s, csv: 0, md: 2, scale: 1e-6, unit: " M" }),
    ("sdf_evals_per_ray", "evals/ray", fixed(|r| r.evals_per_ray, 3, 2)),
    ("leaf_evals_per_ray", "primitives/ray", fixed(|r| r.leaves_per_ray, 3, 2)),
    ("node_visits_per_ray", "visits/ray", fixed(|r| r.visits_per_ray, 3, 2)),
    ("triangle_tests_per_ray", "tri tests/ray", fixed(|r| r.tests_per_ray, 3, 2)),
    ("geometry_bytes", "bytes", Cell::Count(|r| r.bytes)),
    ("triangles", "triangles", Cell::Count(|r| r.triangles)),
    ("peak_rss_kib", "peak RSS", Cell::Kib(|r| r.peak_rss_kib)),
    ("geo_error_mean", "geo error mean", Cell::Sci(|r| r.geo_mean)),
    ("geo_error_max", "geo error max", Cell::Sci(|r| r.geo_max)),
    ("geo_error_max_pixels", "max in pixels", fixed(|r| r.geo_max_px, 4, 3)),
    ("coverage_error_px", "coverage px", Cell::Count(|r| r.coverage)),
    ("rmse", "RMSE", fixed(|r| r.rmse, 4, 2)),
    ("psnr_db", "PSNR", Cell::Fixed { get: |r| r.psnr, csv: 2, md: 1, scale: 1.0, unit: " dB" }),
];

/// The header line of `sweep.csv`.
pub fn csv_header() -> String {
    COLUMNS.iter().map(|(name, _, _)| *name).collect::<Vec<_>>().join(",")
}

/// Rows as CSV.
pub fn csv(rows: &[Row]) -> String {
    let mut out = csv_header() + "\n";
    for r in rows {
        let cells: Vec<String> = COLUMNS.iter().map(|(_, _, cell)| cell.csv(r)).collect();
        let _ = writeln!(out, "{}", cells.join(","));
    }
    out
}

/// Rows as a Markdown table.
pub fn markdown(rows: &[Row], title: &str) -> String {
    let mut out = format!(
        "# Sweep: {title}\n\nReference: the SDF render at epsilon 1e-6 with a 100 000-step budget. Geometric error is |d| at primary hits, in world units. Work is the frame's unit operations (primitive evaluations, BVH node visits, triangle tests), the same on every run; wall times are lowering plus rendering, timed until the median's 95 % interval (±) is within 2 % of it or the time cap.\n\n"
    );
    let headings: Vec<&str> = COLUMNS.iter().map(|(_, heading, _)| *heading).collect();
    let _ = writeln!(out, "| {} |", headings.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(COLUMNS.len()));
    for r in rows {
        let cells: Vec<String> = COLUMNS.iter().map(|(_, _, cell)| cell.markdown(r)).collect();
        let _ = writeln!(out, "| {} |", cells.join(" | "));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Detail;
    use crate::study::sweep::Setting;

    fn row(peak_rss_kib: Option<u64>) -> Row {
        Row {
            setting: Setting::Mesh(Detail::N(28)),
            time: crate::study::sweep::Timing {
                runs: 7,
                min_ms: 11.5,
                median_ms: 12.34567,
                max_ms: 14.0,
                ci_ms: 0.25,
                cpu_ms: Some(24.5),
            },
            work: 987_654,
            rays_per_s: 4_567_890.4,
            evals_per_ray: 1.23456,
            leaves_per_ray: 9.87654,
            visits_per_ray: 7.5,
            tests_per_ray: 0.0,
            bytes: 123_456,
            triangles: 789,
            peak_rss_kib,
            geo_mean: 1.5e-4,
            geo_max: 2.25e-3,
            geo_max_px: 0.12345,
            coverage: 3,
            rmse: 1.23456,
            psnr: 45.678,
        }
    }

    /// The formats the README documents and scripts parse.
    #[test]
    fn rows_are_written_as_documented() {
        let csv = csv(&[row(Some(2048)), row(None)]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], csv_header());
        assert_eq!(
            lines[1],
            "mesh,detail 28,987654,7,11.500,12.346,14.000,0.250,24.500,4567890,1.235,9.877,7.500,0.000,123456,789,2048,1.5e-4,2.25e-3,0.1235,3,1.2346,45.68"
        );
        assert_eq!(
            lines[2],
            "mesh,detail 28,987654,7,11.500,12.346,14.000,0.250,24.500,4567890,1.235,9.877,7.500,0.000,123456,789,,1.5e-4,2.25e-3,0.1235,3,1.2346,45.68"
        );
        let md = markdown(&[row(Some(2048))], "t");
        assert!(md.contains("| mesh | detail 28 | 987654 | 7 | 11.5 ms | 12.3 ms | 14.0 ms | 0.2 ms | 24.5 ms | 4.57 M | 1.23 | 9.88 | 7.50 | 0.00 | 123456 | 789 | 2.0 MiB | 1.50e-4 | 2.25e-3 | 0.123 | 3 | 1.23 | 45.7 dB |"), "{md}");
        assert!(markdown(&[row(None)], "t").contains("| 789 | n/a |"));
    }
}
