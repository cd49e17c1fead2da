//! The flags several commands take, each declared once here and flattened into every
//! command that takes it, so its name, values, default and help read the same in each
//! (`tests/scnc/cli.rs` holds `docs/cli.md` to what `--help` says).

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
fn parse_detail(s: &str) -> Result<scnc::mesh::Detail, String> {
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
