//! Mesh files, read and written: one file per format, each a [`MeshFormat`] that says
//! its name, extensions, media type, frame and unit, whether it is for printing, how it
//! is read (for `mesh file(…)`) and how an [`Export`] is written to it (for `scnc
//! export` and the studio's downloads). `formats!` lists them; the [`Format`] enum and
//! its dispatch, the command line's `--format` values and the studio's download buttons
//! are derived from that list, so a new format is its file and one line there.
//!
//! Readers map the file's frame and unit into scnc's ([`crate::geom::axes`]) and refuse,
//! with a reason, what a scene could not place: more than [`MAX_ELEMENTS`] vertices or
//! faces, a coordinate beyond [`MAX_COORDINATE`]. Writers write numbers in Rust's
//! shortest round-trip form, so a file is the same on every run and thread count.

mod model;

use std::io::{self, BufRead, Write};

use glam::DVec3;

pub use crate::geom::axes::Up;
use crate::geom::TriMesh;
pub use model::{Colour, Export, Group, IsoFit, Part};
pub use three_mf::DEFAULT_3MF_UNIT;

/// How a format's files are read.
pub enum Reader {
    /// From the whole file's bytes, within the bytes the mesh may take (a file that
    /// places one mesh many times expands past its own size); an error says what is
    /// wrong.
    Whole(fn(&[u8], u64) -> Result<TriMesh, String>),
    /// A buffer at a time (a large scan need not be held whole); an error names its line.
    Lines(fn(&mut dyn BufRead) -> Result<TriMesh, obj::ObjError>),
}

/// What a writer is told besides the meshes.
#[derive(Clone, Copy, Debug)]
pub struct WriteOptions<'a> {
    /// The unit a 3MF file declares.
    pub units: &'a str,
    /// The MTL file an OBJ file's `mtllib` names.
    pub mtl: &'a str,
    /// STL as text rather than binary.
    pub ascii: bool,
}

impl Default for WriteOptions<'_> {
    fn default() -> Self {
        WriteOptions { units: DEFAULT_3MF_UNIT, mtl: "", ascii: false }
    }
}

/// One mesh file format. Every item is required: there is no default to forget.
pub trait MeshFormat {
    /// Its name: `--format NAME`, the studio's `/api/export?format=NAME`.
    const NAME: &'static str;
    /// What it is, one line (for `--help` and the studio's button).
    const ABOUT: &'static str;
    /// The file name endings it is known by, lowercase, without the dot.
    const EXTENSIONS: &'static [&'static str];
    /// Its media type, for a download.
    const MIME: &'static str;
    /// Whether its files are meant for printing: z up unless told, and an unbounded
    /// shape is left out of them with a warning rather than refused.
    const FOR_PRINTING: bool;
    /// File units per scene unit unless told.
    const DEFAULT_SCALE: f64;
    /// The one up axis its specification allows, where it fixes one.
    const FIXED_UP: Option<Up>;
    /// Whether a written model is one file (OBJ's colours go to a second, its MTL).
    const ONE_FILE: bool;
    /// How `mesh file(…)` reads it, as the note on a bad file says it.
    const READS: &'static str;
    /// How its files are read.
    const READER: Reader;
    /// About the most memory writing `part` keeps until the writer ends, and the most it
    /// takes for the part alone (what the writer builds beside the meshes).
    fn working_bytes(part: &Part) -> (u64, u64);
    /// Writes `export` to `w`.
    fn write(export: &Export, options: &WriteOptions, w: &mut dyn Write) -> io::Result<()>;
}

/// Lists the formats: each line a variant of [`Format`] and the type, in its own file,
/// that implements [`MeshFormat`] for it.
macro_rules! formats {
    ($($(#[doc = $doc:literal])* $variant:ident => $module:ident::$ty:ident,)*) => {
        $(pub mod $module;)*

        /// A mesh file format.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Format {
            $($(#[doc = $doc])* $variant,)*
        }

        impl Format {
            /// Every format, in the order `--help` lists them.
            pub const ALL: &[Format] = &[$(Format::$variant),*];

            /// Its name ([`MeshFormat::NAME`]).
            pub fn name(self) -> &'static str {
                match self { $(Format::$variant => $module::$ty::NAME,)* }
            }

            /// What it is ([`MeshFormat::ABOUT`]).
            pub fn about(self) -> &'static str {
                match self { $(Format::$variant => $module::$ty::ABOUT,)* }
            }

            /// Its file name endings ([`MeshFormat::EXTENSIONS`]).
            pub fn extensions(self) -> &'static [&'static str] {
                match self { $(Format::$variant => $module::$ty::EXTENSIONS,)* }
            }

            /// Its media type ([`MeshFormat::MIME`]).
            pub fn mime(self) -> &'static str {
                match self { $(Format::$variant => $module::$ty::MIME,)* }
            }

            /// Whether it is meant for printing ([`MeshFormat::FOR_PRINTING`]).
            pub fn for_printing(self) -> bool {
                match self { $(Format::$variant => $module::$ty::FOR_PRINTING,)* }
            }

            /// File units per scene unit unless told ([`MeshFormat::DEFAULT_SCALE`]).
            pub fn default_scale(self) -> f64 {
                match self { $(Format::$variant => $module::$ty::DEFAULT_SCALE,)* }
            }

            /// The up axis its specification fixes ([`MeshFormat::FIXED_UP`]).
            pub fn fixed_up(self) -> Option<Up> {
                match self { $(Format::$variant => $module::$ty::FIXED_UP,)* }
            }

            /// Whether a model is one file ([`MeshFormat::ONE_FILE`]).
            pub fn one_file(self) -> bool {
                match self { $(Format::$variant => $module::$ty::ONE_FILE,)* }
            }

            /// How `mesh file(…)` reads it ([`MeshFormat::READS`]).
            pub fn reads(self) -> &'static str {
                match self { $(Format::$variant => $module::$ty::READS,)* }
            }

            /// How its files are read ([`MeshFormat::READER`]).
            pub fn reader(self) -> Reader {
                match self { $(Format::$variant => $module::$ty::READER,)* }
            }

            fn part_working_bytes(self, part: &Part) -> (u64, u64) {
                match self { $(Format::$variant => $module::$ty::working_bytes(part),)* }
            }

            fn write_unchecked(self, export: &Export, options: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
                match self { $(Format::$variant => $module::$ty::write(export, options, w),)* }
            }
        }
    };
}

formats! {
    /// STL: binary (80-byte header, 50 bytes per triangle), or ASCII.
    Stl => stl::Stl,
    /// Wavefront OBJ, with an MTL file of the materials' colours.
    Obj => obj::Obj,
    /// PLY, binary little-endian, with colours per vertex.
    Ply => ply::Ply,
    /// 3MF: a ZIP package with the model's XML, one object per scene object.
    ThreeMf => three_mf::ThreeMf,
    /// Binary glTF 2.0 (`.glb`): one node per object, a PBR material per colour.
    Glb => glb::Glb,
    /// OFF, OpenSCAD's and CGAL's text format: z up, millimetres, a colour per face.
    Off => off::Off,
}

impl Format {
    /// The format a file name's extension asks for, if any.
    pub fn from_extension(ext: &str) -> Option<Format> {
        let ext = ext.to_ascii_lowercase();
        Format::ALL.iter().copied().find(|f| f.extensions().contains(&ext.as_str()))
    }

    /// The format named `name` ([`MeshFormat::NAME`]).
    pub fn from_name(name: &str) -> Option<Format> {
        Format::ALL.iter().copied().find(|f| f.name() == name)
    }

    /// The format `mesh file(…)` reads a file as: by its extension, and any other name
    /// as OBJ, the format of scans and of most tools' plain output.
    pub fn for_reading(path: &std::path::Path) -> Format {
        path.extension().and_then(|e| e.to_str()).and_then(Format::from_extension).unwrap_or(Format::Obj)
    }

    /// Every extension, as `.stl, .obj, …, or .glb` for a message.
    pub fn extension_list() -> String {
        let all: Vec<String> = Format::ALL.iter().map(|f| format!(".{}", f.extensions()[0])).collect();
        match all.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => all.join(""),
        }
    }

    /// The up axis a file of this format gets unless told: z for printing (slicers,
    /// CAD), y for viewers (OBJ, PLY, glTF).
    pub fn default_up(self) -> Up {
        if self.for_printing() {
            Up::Z
        } else {
            Up::Y
        }
    }

    /// About the most memory writing `export` takes beyond the export itself, to ask of
    /// the system before the output is begun.
    pub fn working_bytes(self, export: &Export) -> u64 {
        let (mut all, mut largest) = (0u64, 0u64);
        for p in &export.parts {
            let (kept, transient) = self.part_working_bytes(p);
            all += kept;
            largest = largest.max(transient);
        }
        all + largest + (1 << 20)
    }

    /// Writes `export` in this format. First it asks the system for the writer's
    /// [`Format::working_bytes`]: refused, it is an error before a byte is written, not
    /// an allocation abort halfway.
    pub fn write(self, export: &Export, options: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
        let working = self.working_bytes(export);
        if !crate::source::system_gives(working) {
            return Err(io::Error::new(
                io::ErrorKind::OutOfMemory,
                format!(
                    "the system would not give the {} writing it needs beside the meshes (see `ulimit -v`)",
                    crate::diag::bytes(working)
                ),
            ));
        }
        self.write_unchecked(export, options, w)
    }

    /// Reads the file `bytes` hold (a test's or a tool's shortcut for [`Format::reader`]).
    pub fn read(self, bytes: &[u8]) -> Result<TriMesh, String> {
        match self.reader() {
            Reader::Whole(read) => read(bytes, u64::MAX),
            Reader::Lines(read) => read(&mut { bytes }).map_err(|e| format!("line {}: {}", e.line, e.message)),
        }
    }
}

/// Most vertices or faces accepted from one file.
pub const MAX_ELEMENTS: usize = 50_000_000;

/// What a node of a file's instance graph (a glb node, a 3MF object) places with
/// everything under it, each use of a shared node counted: summed over the graph with
/// each node's sum kept, so a node listed 16 times by each of 40 nested nodes costs 40
/// sums, not 16⁴⁰ visits, and the whole expansion is known before anything is
/// allocated. The counts saturate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Expansion {
    vertices: u64,
    triangles: u64,
    /// Uses of nodes that place triangles: the steps of the walk that places them.
    uses: u64,
}

impl Expansion {
    /// `self` and `other` placed `times` times.
    fn plus(self, other: Expansion, times: u64) -> Expansion {
        Expansion {
            vertices: self.vertices.saturating_add(other.vertices.saturating_mul(times)),
            triangles: self.triangles.saturating_add(other.triangles.saturating_mul(times)),
            uses: self.uses.saturating_add(other.uses.saturating_mul(times)),
        }
    }

    /// Whether more than [`MAX_ELEMENTS`] of anything.
    fn too_many(&self) -> bool {
        self.vertices.max(self.triangles).max(self.uses) > MAX_ELEMENTS as u64
    }

    /// What the mesh it expands to takes.
    fn bytes(&self) -> u64 {
        let (v, t) = (std::mem::size_of::<DVec3>() as u64, std::mem::size_of::<[u32; 3]>() as u64);
        self.vertices.saturating_mul(v).saturating_add(self.triangles.saturating_mul(t))
    }

    /// An empty mesh with room for the whole expansion, refused with a reason past
    /// [`MAX_ELEMENTS`], past the `allowed` bytes or past what the system gives: so the
    /// walk that fills it allocates nothing more, and no abort is reachable from a
    /// small file.
    fn reserve(&self, allowed: u64) -> Result<TriMesh, String> {
        if self.too_many() {
            return Err(format!(
                "it places more than {MAX_ELEMENTS} vertices or triangles, counting each use of a shared mesh \
                 ({} triangles in all)",
                self.triangles
            ));
        }
        if self.bytes() > allowed {
            return Err(format!(
                "it places {} triangles, counting each use of a shared mesh: {} as a mesh, more than the {} \
                 the memory limit leaves (`--memory-limit`)",
                self.triangles,
                crate::diag::bytes(self.bytes()),
                crate::diag::bytes(allowed)
            ));
        }
        let mut mesh = TriMesh::default();
        let (v, t) = (self.vertices as usize, self.triangles as usize);
        if mesh.positions.try_reserve_exact(v).is_err() || mesh.triangles.try_reserve_exact(t).is_err() {
            return Err(format!(
                "the system would not give the {} its {} triangles take (see `ulimit -v`)",
                crate::diag::bytes(self.bytes()),
                self.triangles
            ));
        }
        Ok(mesh)
    }
}

/// Largest coordinate accepted: the renderable range of positions in a scene
/// (docs/limits.md), so a mesh file places nothing a scene could not.
pub const MAX_COORDINATE: f64 = 1e15;

/// Why a mesh file's vertex `p` cannot be placed, if it cannot: not finite, or beyond
/// [`MAX_COORDINATE`] (every reader's one check).
pub fn unrenderable(p: DVec3) -> Option<String> {
    (!p.is_finite() || p.abs().max_element() > MAX_COORDINATE)
        .then(|| format!("is beyond the renderable range (±{MAX_COORDINATE:e})"))
}

fn f32s(v: DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

/// The name of material `m` in OBJ/MTL, 3MF and glTF.
fn material_name(export: &Export, m: u32) -> &str {
    &export.material_names[m as usize]
}

/// The materials any part uses, in increasing order.
fn used(export: &Export) -> Vec<u32> {
    let mut seen = vec![false; export.colours.len()];
    for &m in export.parts.iter().flat_map(|p| &p.materials) {
        seen[m as usize] = true;
    }
    (0..seen.len() as u32).filter(|&m| seen[m as usize]).collect()
}

/// Material `m`'s position in `used` (sorted; every part's materials are in it): its
/// index among a 3MF file's base materials and a glb file's materials.
fn slot(used: &[u32], m: u32) -> usize {
    used.binary_search(&m).unwrap_or(0)
}

/// What splitting `part` by material ([`Part::groups`]) takes: an index and a hash-map
/// entry per vertex, a triangle.
fn groups_bytes(part: &Part) -> u64 {
    40 * part.mesh.positions.len() as u64 + 12 * part.mesh.triangles.len() as u64
}

/// What `part`'s vertex normals take (none for a faceted part).
fn normals_bytes(part: &Part) -> u64 {
    if part.smooth {
        24 * part.mesh.positions.len() as u64
    } else {
        0
    }
}
