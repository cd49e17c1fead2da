//! What accuracy costs: the error model behind `--tolerance`, the `scnc sweep` ladder,
//! its metrics against a reference render, and its report and charts.
//!
//! - [`tolerance`]: the cheapest setting expected to keep error under a bound.
//! - [`accuracy`]: geometric, coverage and image error against a reference.
//! - [`sweep`]: one scene across a ladder of settings, measured.
//! - [`samples`]: under light transport, one scene across a ladder of samples.
//! - [`report`] and [`chart`]: the sweep as CSV, Markdown and PNG charts.

pub mod accuracy;
pub mod chart;
pub mod report;
pub mod samples;
pub mod sweep;
pub mod tolerance;
