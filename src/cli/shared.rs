//! The flags several commands take, each declared once here and flattened into every
//! command that takes it, so its name, values, default and help read the same in each
//! (`tests/scnc/cli.rs` holds `docs/cli.md` to what `--help` says).

use scnc::source::Loader;
use scnc::study::tolerance::Tolerance;

use super::MessageFormat;

/// `--threads`.
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct Workers {
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub(crate) threads: Option<u16>,
}

impl Workers {
    /// A pool of the threads asked for.
    pub(crate) fn pool(self) -> Result<rayon::ThreadPool, String> {
        super::worker_pool(self.threads)
    }
}

/// `--message-format`.
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct Messages {
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value = "human")]
    pub(crate) message_format: MessageFormat,
}

/// `--tolerance`.
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct Accuracy {
    /// The geometric error to stay within, in scene units, or `pixel` for a pixel's
    /// footprint at the scene's camera: `render` and `export` pick the cheapest setting
    /// expected to keep it (epsilon, or detail with meshes), `sweep` measures only the
    /// settings they would pick, to check that they hold.
    #[arg(long)]
    pub(crate) tolerance: Option<Tolerance>,
}

/// `--detail` and `--memory-limit`: how shapes become meshes.
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct Meshing {
    /// Tessellation detail of meshed shapes: `low` (7 rings, 10-point circles), `high`
    /// (14 rings, 50-point circles) or N (N rings, 2N-point circles).
    #[arg(long, value_parser = parse_detail, default_value = "high", conflicts_with = "tolerance")]
    pub(crate) detail: scnc::mesh::Detail,
    /// Most memory the scene's meshes may take while they are built, in bytes or with a
    /// K, M or G suffix (binary); a mesh that would need more is refused before it is made.
    #[arg(long, value_parser = parse_bytes, default_value = "4G")]
    pub(crate) memory_limit: u64,
}

/// A detail: `low`, `high` or a number of rings.
pub(crate) fn parse_detail(s: &str) -> Result<scnc::mesh::Detail, String> {
    match s {
        "low" => Ok(scnc::mesh::Detail::Low),
        "high" => Ok(scnc::mesh::Detail::High),
        n => match n.parse::<u32>() {
            Ok(n) if (3..=2048).contains(&n) => Ok(scnc::mesh::Detail::N(n)),
            _ => Err("expected `low`, `high` or a number of rings from 3 to 2048".into()),
        },
    }
}

/// A byte count: a whole number, optionally with a K, M or G suffix (powers of 1024).
fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, shift) = match t.char_indices().last() {
        Some((i, 'K' | 'k')) => (&t[..i], 10),
        Some((i, 'M' | 'm')) => (&t[..i], 20),
        Some((i, 'G' | 'g')) => (&t[..i], 30),
        _ => (t, 0),
    };
    let n: u64 = digits.parse().map_err(|_| format!("`{s}` is not a size: try `4G`, `512M` or a number of bytes"))?;
    match n.checked_mul(1 << shift) {
        Some(bytes) if bytes > 0 => Ok(bytes),
        _ => Err(format!("`{s}` must be greater than 0 and at most {} bytes", u64::MAX)),
    }
}

/// `-D`, `--params` and `--set-name`: values for the scene's `param`s.
#[derive(clap::Args, Clone, Default)]
pub(crate) struct Params {
    /// Set a scene parameter (a `param` of the file) for this run, `-D width=30`; may be
    /// repeated, and wins over `--set-name`.
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = scnc::check::Overrides::parse_define)]
    pub(crate) define: Vec<scnc::check::Override>,
    /// A parameter-set file: JSON in the shape of OpenSCAD's customizer files,
    /// `{"parameterSets": {"large": {"width": "30"}}}`.
    #[arg(long = "params", value_name = "FILE", requires = "set_name")]
    pub(crate) sets: Option<std::path::PathBuf>,
    /// The set of `--params` to use.
    #[arg(long, value_name = "NAME", requires = "sets")]
    pub(crate) set_name: Option<String>,
}

impl Params {
    /// The values given: the named set's first, then each `-D` in order (the last given
    /// for a name wins); what is wrong with the set file otherwise.
    pub(crate) fn overrides(&self) -> Result<scnc::check::Overrides, String> {
        let mut all = Vec::new();
        if let (Some(path), Some(name)) = (&self.sets, &self.set_name) {
            all = read_set(path, name)?;
        }
        all.extend(self.define.iter().cloned());
        Ok(scnc::check::Overrides(all))
    }
}

/// The values of set `name` in the parameter-set file at `path`.
fn read_set(path: &std::path::Path, name: &str) -> Result<Vec<scnc::check::Override>, String> {
    let file = path.display();
    let text = scnc::source::FsLoader
        .read(path)
        .map_err(|e| format!("cannot read the parameter sets `{file}`: {}", scnc::source::io_reason(&e)))?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("`{file}` is not JSON: {e}"))?;
    let sets = json
        .get("parameterSets")
        .and_then(serde_json::Value::as_object)
        .ok_or_else(|| format!("`{file}` has no `parameterSets` object"))?;
    let set = sets.get(name).and_then(serde_json::Value::as_object).ok_or_else(|| {
        let names: Vec<&str> = sets.keys().map(String::as_str).collect();
        format!("`{file}` has no set `{name}`; its sets are: {}", names.join(", "))
    })?;
    set.iter()
        .map(|(param, value)| {
            // OpenSCAD writes every value as a string; numbers, booleans and [r, g, b]
            // written as JSON are read too.
            let text = match value {
                serde_json::Value::String(s) => s.clone(),
                serde_json::Value::Number(n) => n.to_string(),
                serde_json::Value::Bool(b) => b.to_string(),
                serde_json::Value::Array(c) if c.len() == 3 && c.iter().all(serde_json::Value::is_number) => {
                    let parts: Vec<String> = c.iter().map(ToString::to_string).collect();
                    format!("rgb({})", parts.join(", "))
                }
                other => return Err(format!("`{file}`: set `{name}` gives `{param}` the value {other}, which is not a number, truth value, string or colour")),
            };
            let origin = format!("`\"{param}\": {value}` of set `{name}` in `{file}`");
            Ok(scnc::check::Override { name: param.clone(), text, origin })
        })
        .collect()
}
