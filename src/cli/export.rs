//! `scnc export`: a scene's objects as a mesh file (STL, OBJ + MTL, PLY, 3MF, glb),
//! written whole or not at all.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::ValueEnum;

use super::progress::Reading;
use super::shared::{Accuracy, Meshing, Messages, Params, Workers};
use scnc::diag::Diagnostic;
use scnc::export::report::MeshReport;
use scnc::export::{Export, Placement, Up};
use scnc::mesh::Detail;
use scnc::meshfile::{Format, WriteOptions};

use super::files::{cannot_write, check_output_as, overwritten_input, write_atomic};
use super::{compile, report, usage_error};

/// `--format`: a mesh file format, with the values and help the format list gives.
#[derive(Clone, Copy, PartialEq, Eq)]
struct FormatArg(Format);

impl ValueEnum for FormatArg {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [FormatArg; Format::ALL.len()] = {
            let mut all = [FormatArg(Format::Stl); Format::ALL.len()];
            let mut i = 0;
            while i < all.len() {
                all[i] = FormatArg(Format::ALL[i]);
                i += 1;
            }
            all
        };
        &ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(self.0.about()))
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum UpArg {
    /// Y up (glTF, OBJ and PLY viewers).
    Y,
    /// Z up (slicers, CAD).
    Z,
}

impl From<UpArg> for Up {
    fn from(u: UpArg) -> Up {
        match u {
            UpArg::Y => Up::Y,
            UpArg::Z => Up::Z,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Units {
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches.
    In,
}

impl Units {
    /// The 3MF `unit` attribute.
    fn three_mf(self) -> &'static str {
        match self {
            Units::Mm => "millimeter",
            Units::Cm => "centimeter",
            Units::M => "meter",
            Units::In => "inch",
        }
    }
}

#[derive(clap::Args)]
pub(crate) struct ExportArgs {
    /// The scene file.
    file: PathBuf,
    /// Output mesh file; its extension picks the format (see `--format`).
    #[arg(short, long)]
    output: PathBuf,
    /// The format, whatever the output's extension.
    #[arg(long, value_enum)]
    format: Option<FormatArg>,
    /// Write ASCII STL instead of binary.
    #[arg(long)]
    ascii: bool,
    #[command(flatten)]
    meshing: Meshing,
    #[command(flatten)]
    accuracy: Accuracy,
    /// The file's up axis (default: `z` for STL and 3MF, `y` for OBJ, PLY and glb).
    #[arg(long, value_enum)]
    up: Option<UpArg>,
    /// File units per scene unit (default: 10 for STL, whose unit slicers read as mm,
    /// so a scene unit prints as a centimetre; 1 otherwise).
    #[arg(long, value_parser = parse_scale)]
    scale: Option<f64>,
    /// The unit a 3MF file declares (default: cm, one scene unit a centimetre).
    #[arg(long, value_enum)]
    units: Option<Units>,
    /// Leave out unbounded objects (a `plane`), with a warning, instead of stopping at
    /// them: always so for STL and 3MF, which are for printing.
    #[arg(long)]
    skip_unbounded: bool,
    /// Check each object's mesh: watertight and manifold, degenerate triangles dropped,
    /// enclosed volume and bounds.
    #[arg(long)]
    stats: bool,
    #[command(flatten)]
    workers: Workers,
    #[command(flatten)]
    messages: Messages,
    #[command(flatten)]
    params: Params,
}

/// A scale from 1e-12 to 1e12, which keeps a renderable scene finite in f32.
fn parse_scale(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if (1e-12..=1e12).contains(&x) {
        Ok(x)
    } else {
        Err("must be a number from 1e-12 to 1e12".into())
    }
}

impl ExportArgs {
    /// The format: `--format`, else the output's extension.
    fn format(&self) -> Result<Format, String> {
        let format = match self.format {
            Some(FormatArg(f)) => f,
            None => {
                self.output.extension().and_then(|e| e.to_str()).and_then(Format::from_extension).ok_or_else(|| {
                    format!(
                        "cannot tell the format of `{}`: name it {}, or give --format",
                        self.output.display(),
                        Format::extension_list()
                    )
                })?
            }
        };
        if self.ascii && format != Format::Stl {
            return Err("--ascii is for STL only".into());
        }
        Ok(format)
    }
}

/// `scnc export`: the flags checked, the scene compiled and meshed (refined where a
/// tolerance promises a usable mesh), the files written whole or not at all.
pub(crate) fn export_cmd(args: ExportArgs) -> ExitCode {
    let (format, mtl) = match args.checked() {
        Ok(f) => f,
        Err(e) => return usage_error(&e),
    };
    if let Err(e) = super::files::stop_on_interrupt(130) {
        let _ = writeln!(std::io::stderr(), "warning: {e}");
    }
    let pool = match args.workers.pool() {
        Ok(p) => p,
        Err(e) => return usage_error(&e),
    };
    let Some(mut compiled) = compile(&args.file, args.messages.message_format, &args.params) else {
        return ExitCode::from(1);
    };
    super::drop_render_only(&mut compiled);
    if report(&compiled, args.messages.message_format) {
        return ExitCode::from(1);
    }
    let Some(scene) = compiled.scene.take() else { return ExitCode::from(1) };
    if let Err(e) = args.inputs_kept(&scene, &compiled) {
        return usage_error(&e);
    }
    if scene.objects.is_empty() {
        let _ = writeln!(std::io::stderr(), "error: `{}` has no objects to export", args.file.display());
        return ExitCode::from(1);
    }
    let started = Instant::now();
    let (result, detail, up) = pool.install(|| args.mesh(&scene, format));
    let export = match result {
        Ok(e) => {
            super::report_in(&compiled.map, &e.warnings, args.messages.message_format);
            e
        }
        Err(d) => {
            super::report_in(&compiled.map, &[d], args.messages.message_format);
            return ExitCode::from(1);
        }
    };
    if export.parts.is_empty() {
        // A file with no solid in it is of no use to a slicer or viewer, and some refuse it.
        let _ = writeln!(
            std::io::stderr(),
            "error: no object of `{}` has a surface to write (see the warnings above); nothing written",
            args.file.display()
        );
        return ExitCode::from(1);
    }
    let bytes = match args.write(&export, format, &mtl) {
        Ok(b) => b,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            return ExitCode::from(1);
        }
    };
    let mut err = std::io::stderr().lock();
    let _ = writeln!(
        err,
        "exported {}: {} objects, {} triangles, {bytes} bytes in {:.3} s (up {}, detail {})",
        args.output.display(),
        export.parts.len(),
        export.triangle_count(),
        started.elapsed().as_secs_f64(),
        if up == Up::Y { "y" } else { "z" },
        detail.rings(),
    );
    if args.stats {
        for part in &export.parts {
            let _ = writeln!(err, "  {}", part_stats(part, &compiled.map));
            if let Some(fit) = part.fit {
                let _ = writeln!(err, "    {}", fit_stats(&fit, part.mesh.triangles.len()));
            }
        }
    }
    ExitCode::SUCCESS
}

impl ExportArgs {
    /// The format, and where an OBJ's materials go, once every flag agrees with it.
    fn checked(&self) -> Result<(Format, PathBuf), String> {
        let format = self.format()?;
        if let (Some(fixed), Some(asked)) = (format.fixed_up(), self.up) {
            if Up::from(asked) != fixed {
                return Err(
                    "--up: glTF fixes +y as up (glTF 2.0, \"Coordinate System and Units\"); turn the scene instead"
                        .into(),
                );
            }
        }
        if self.units.is_some() && format != Format::ThreeMf {
            return Err("--units is for 3MF, the one format that records units; use --scale to convert".into());
        }
        check_output_as(&self.output, "a mesh file")?;
        let mtl = mtl_path(&self.output);
        if format == Format::Obj && mtl == self.output {
            return Err("an OBJ export writes its materials beside it in a .mtl file; name the output .obj".into());
        }
        Ok((format, mtl))
    }

    /// Refuses an output that is one of the scene's inputs (a source or a mesh file).
    fn inputs_kept(&self, scene: &scnc::ir::Scene, compiled: &scnc::Compiled) -> Result<(), String> {
        let meshes = scene.objects.iter().filter_map(|o| match &o.geometry {
            scnc::ir::Body::Mesh(m) => match &m.source {
                scnc::ir::MeshSource::File { path, .. } => Some(path.as_path()),
                _ => None,
            },
            scnc::ir::Body::Shape(_) => None,
        });
        let sources = compiled.map.files().map(|(_, f)| f.path.as_path());
        match overwritten_input(&self.output, sources.chain(meshes)) {
            Some(input) => Err(format!(
                "`{}` is an input of the scene ({}); name another output",
                self.output.display(),
                input.display()
            )),
            None => Ok(()),
        }
    }

    /// The scene meshed at the detail the flags ask for. A tolerance promises a mesh
    /// good enough to use, so it is refined where an isosurface lost volume ([`scnc::export::collect_refined`]).
    fn mesh(&self, scene: &scnc::ir::Scene, format: Format) -> (Result<Export, Diagnostic>, Detail, Up) {
        let detail: Detail = match self.accuracy.tolerance {
            Some(tol) => {
                let detail = scnc::study::tolerance::mesh_detail(scene, tol);
                let _ = writeln!(std::io::stderr(), "tolerance {tol}: picked {}", detail.describe());
                detail
            }
            None => self.meshing.detail,
        };
        let up = self.up.map_or(format.default_up(), Up::from);
        let frame = Placement { up, scale: self.scale.unwrap_or(format.default_scale()) };
        let skip = self.skip_unbounded || format.for_printing();
        let limit = self.meshing.memory_limit;
        if self.accuracy.tolerance.is_none() {
            return (scnc::export::collect(scene, detail, frame, limit, skip, &Reading), detail, up);
        }
        let mut said = |from: Detail, to: Detail| {
            let _ = writeln!(
                std::io::stderr(),
                "detail {} is coarser than parts of an isosurface: refining to detail {}",
                from.rings(),
                to.rings()
            );
        };
        let (result, detail) = scnc::export::collect_refined(scene, detail, frame, limit, skip, &Reading, &mut said);
        (result, detail, up)
    }

    /// Writes the export (and an OBJ's MTL first, so the OBJ never names a missing
    /// file; a new MTL is removed again if the OBJ fails): the bytes written.
    fn write(&self, export: &Export, format: Format, mtl: &Path) -> Result<u64, String> {
        let units = self.units.map_or(scnc::meshfile::DEFAULT_3MF_UNIT, Units::three_mf);
        let mtl_name = mtl.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let mut bytes = 0u64;
        let mut write = |path: &Path, what: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| {
            write_atomic(path, ".tmp", |w| {
                let mut counted = Counted { inner: w, bytes: 0 };
                what(&mut counted)?;
                bytes += counted.bytes;
                Ok(())
            })
            .map_err(|e| cannot_write(path, &e))
        };
        let mtl_existed = mtl.exists();
        if format == Format::Obj {
            write(mtl, &|w| scnc::meshfile::obj::mtl(export, w))?;
        }
        let options = WriteOptions { units, mtl: &mtl_name, ascii: self.ascii };
        let written = write(&self.output, &|w| format.write(export, &options, w));
        if written.is_err() && format == Format::Obj && !mtl_existed {
            let _ = std::fs::remove_file(mtl);
        }
        written.map(|()| bytes)
    }
}

/// One line of `--stats` for an exported part: where it came from, its triangles,
/// whether it is closed, its volume and bounds.
fn part_stats(part: &scnc::meshfile::Part, map: &scnc::source::SourceMap) -> String {
    let r = MeshReport::of(part);
    let (id, range) = map.local_range(part.span);
    let (line, _) = map.line_col(id, range.start);
    let (lo, hi) = r.bounds;
    format!(
        "{} ({}:{line}): {} triangles, {}, {} degenerate dropped, volume {:.6}, bounds [{:.4}, {:.4}, {:.4}] to [{:.4}, {:.4}, {:.4}]",
        part.name,
        map.file(id).name,
        r.triangles,
        if r.is_closed_manifold() {
            "watertight and manifold".to_string()
        } else {
            format!("not closed: {} open edges, {} wound twice one way", r.open_edges, r.misoriented_edges)
        },
        r.degenerate,
        r.volume,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
    )
}

/// The second line of `--stats` for an isosurface made under a tolerance: its measured
/// deviation from the surface.
pub(crate) fn fit_stats(fit: &scnc::meshfile::IsoFit, triangles: usize) -> String {
    let unresolved = if fit.unresolved > 0 { format!(", {} not resolved", fit.unresolved) } else { String::new() };
    format!(
        "deviation from the surface: max {:.3e}, mean {:.3e} ({} points sampled on every triangle{unresolved}; \
         {} of {triangles} triangles proved within the tolerance everywhere)",
        fit.max, fit.mean, fit.samples, fit.proved
    )
}

/// Where an OBJ export's MTL file goes: beside it, same stem.
/// The MTL file beside an OBJ: its name with `.mtl`, whitespace and characters outside
/// printable ASCII made `_`, because `mtllib` names are whitespace-separated and readers
/// differ on anything else.
fn mtl_path(output: &Path) -> PathBuf {
    let with = output.with_extension("mtl");
    let Some(name) = with.file_name() else { return with };
    let safe: String = name.to_string_lossy().chars().map(|c| if c.is_ascii_graphic() { c } else { '_' }).collect();
    with.with_file_name(safe)
}

/// A writer counting the bytes through it, for the summary line.
struct Counted<'a> {
    inner: &'a mut dyn Write,
    bytes: u64,
}

impl Write for Counted<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}
