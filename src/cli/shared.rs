//! The flags several commands take, each declared once here and flattened into every
//! command that takes it, so its name, values, default and help read the same in each
//! (`tests/scnc/cli.rs` holds `docs/cli.md` to what `--help` says).

use scnc::study::tolerance::Tolerance;

use super::render::{parse_bytes, parse_detail};
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
