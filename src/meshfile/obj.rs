//! A Wavefront OBJ reader for triangle meshes: `v` and `f` records (polygons are
//! triangulated by ear clipping; `i`, `i/t`, `i//n`, `i/t/n` and negative relative
//! indices are accepted); other records are ignored. Lines may end in `\n`, `\r\n` or
//! `\r` and continue after a `\`; comments may hold any bytes. Every problem is reported
//! with its line number.

use glam::DVec3;

use crate::geom::polygon::{triangulate_within, MAX_CLIPPED_CORNERS};
use super::{MAX_COORDINATE, MAX_ELEMENTS};
use crate::geom::{axes, TriMesh};
use std::io::{self, Write};

use super::{f32s, material_name, used, Export, MeshFormat, Part, Reader, Up, WriteOptions};

/// A problem in an OBJ file.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjError {
    /// One-based line number (0 for the whole file).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

fn err(line: usize, message: impl Into<String>) -> ObjError {
    ObjError { line, message: message.into() }
}

/// The physical lines of an OBJ file read from `r` a buffer at a time: a line ends at
/// `\n`, `\r\n` or a lone `\r` (old Mac exporters), so memory holds one line, not the
/// file.
struct Physical<R> {
    r: R,
    /// The line being read (its end not included).
    line: Vec<u8>,
    /// The last line ended at a `\r`: a `\n` right after it ends nothing.
    after_cr: bool,
}

impl<R: std::io::BufRead> Physical<R> {
    /// The next line, `None` at the end of the file.
    fn next(&mut self) -> std::io::Result<Option<&[u8]>> {
        self.line.clear();
        let mut any = false;
        loop {
            let buf = self.r.fill_buf()?;
            if buf.is_empty() {
                return Ok(any.then_some(&self.line[..]));
            }
            if std::mem::take(&mut self.after_cr) && buf[0] == b'\n' {
                self.r.consume(1);
                continue;
            }
            any = true;
            match buf.iter().position(|&b| b == b'\n' || b == b'\r') {
                Some(i) => {
                    self.line.extend_from_slice(&buf[..i]);
                    self.after_cr = buf[i] == b'\r';
                    self.r.consume(i + 1);
                    return Ok(Some(&self.line[..]));
                }
                None => {
                    let n = buf.len();
                    self.line.extend_from_slice(buf);
                    self.r.consume(n);
                }
            }
        }
    }
}

/// The logical lines of an OBJ file, numbered from 1: a line ending in `\` continues on
/// the next (its number is the first's), and a comment runs from `#` to the end of its
/// line whatever bytes it holds (Latin-1 in a comment is common).
struct Logical<R> {
    physical: Physical<R>,
    /// Physical lines read so far.
    number: usize,
    /// The logical line: its records without comments, continuations joined by a space.
    joined: Vec<u8>,
}

impl<R: std::io::BufRead> Logical<R> {
    fn new(r: R) -> Logical<R> {
        Logical { physical: Physical { r, line: Vec::new(), after_cr: false }, number: 0, joined: Vec::new() }
    }

    /// The next logical line and its number, `None` at the end of the file.
    fn next(&mut self) -> Result<Option<(usize, &[u8])>, ObjError> {
        let io = |e: std::io::Error| err(0, format!("cannot read it: {}", crate::source::io_reason(&e)));
        self.joined.clear();
        let Some(line) = self.physical.next().map_err(io)? else { return Ok(None) };
        self.number += 1;
        let first = self.number;
        let mut line = line;
        loop {
            let content = line.split(|&b| b == b'#').next().unwrap_or(&[]);
            match content.trim_ascii_end().strip_suffix(b"\\") {
                Some(head) if content.len() == line.len() => {
                    self.joined.extend_from_slice(head);
                    self.joined.push(b' ');
                    match self.physical.next().map_err(io)? {
                        Some(next) => {
                            self.number += 1;
                            line = next;
                        }
                        None => break,
                    }
                }
                _ => {
                    self.joined.extend_from_slice(content);
                    break;
                }
            }
        }
        Ok(Some((first, &self.joined[..])))
    }
}

/// A word of a record as text (a replacement character if it is not UTF-8, which no
/// number or index is, so it is refused as one).
fn text(word: &[u8]) -> &str {
    std::str::from_utf8(word).unwrap_or("\u{fffd}")
}

/// Reads an OBJ file into scnc's space a line at a time: the file's right-handed, y-up
/// frame mapped as export maps it ([`crate::geom::axes`]), so an exported model reads back
/// where it was, unmirrored. A face is triangulated as it is read when its vertices are
/// there already (as they are in files exporters write); one naming vertices further on
/// waits for the end.
pub fn read(r: impl std::io::BufRead) -> Result<TriMesh, ObjError> {
    let mut lines = Logical::new(r);
    let mut mesh = TriMesh::default();
    // Faces naming vertices not yet read: (line, indices from 1).
    let mut later: Vec<(usize, Vec<i64>)> = Vec::new();
    let mut idx: Vec<i64> = Vec::new();
    let mut faces = 0usize;
    while let Some((line, content)) = lines.next()? {
        // Some exporters start the file with a byte-order mark; it would hide the first `v`.
        let content = if line == 1 { content.strip_prefix("\u{feff}".as_bytes()).unwrap_or(content) } else { content };
        let mut words = content.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty());
        match words.next() {
            Some(b"v") => {
                let mut p = [0.0; 3];
                let mut found = 0;
                for w in words.by_ref().take(3) {
                    let w = text(w);
                    let x: f64 = w.parse().map_err(|_| err(line, format!("`{w}` is not a number")))?;
                    if !x.is_finite() {
                        return Err(err(line, format!("vertex coordinate `{w}` is not finite")));
                    }
                    if x.abs() > MAX_COORDINATE {
                        return Err(err(
                            line,
                            format!("vertex coordinate `{w}` is beyond the renderable range (±{MAX_COORDINATE:e})"),
                        ));
                    }
                    p[found] = x;
                    found += 1;
                }
                if found < 3 {
                    return Err(err(line, format!("a vertex needs 3 coordinates, found {found}")));
                }
                mesh.positions.push(axes::from_file(DVec3::from(p), axes::Up::Y));
            }
            Some(b"f") => {
                idx.clear();
                for w in words {
                    let first = w.split(|&b| b == b'/').next().unwrap_or(&[]);
                    let i: i64 = text(first)
                        .parse()
                        .map_err(|_| err(line, format!("`{}` is not a vertex index", String::from_utf8_lossy(w))))?;
                    if i == 0 {
                        return Err(err(line, "vertex indices start at 1; 0 is not valid"));
                    }
                    // Negative indices count back from the vertices defined so far.
                    idx.push(if i < 0 { mesh.positions.len() as i64 + i + 1 } else { i });
                }
                if idx.len() < 3 {
                    return Err(err(line, format!("a face needs at least 3 vertices, found {}", idx.len())));
                }
                faces += 1;
                if idx.iter().all(|&i| i >= 1 && i <= mesh.positions.len() as i64) {
                    add_face(&mut mesh, &idx).map_err(|e| err(line, e))?;
                } else {
                    later.push((line, idx.clone()));
                }
            }
            _ => {}
        }
        if mesh.positions.len() > MAX_ELEMENTS || faces > MAX_ELEMENTS {
            return Err(err(line, format!("more than {MAX_ELEMENTS} vertices or faces")));
        }
    }
    let count = mesh.positions.len() as i64;
    for (line, idx) in later {
        if let Some(i) = idx.iter().find(|&&i| i < 1 || i > count) {
            return Err(err(line, format!("vertex index {i} is out of range: the file has {count} vertices")));
        }
        add_face(&mut mesh, &idx).map_err(|e| err(line, e))?;
    }
    if mesh.triangles.is_empty() {
        return Err(err(0, "the file has no faces"));
    }
    Ok(mesh)
}

/// Adds the triangles of a face whose indices (from 1) are all in range, wound for
/// scnc's space (the mapping from the file is a reflection); refuses a face that is not
/// convex and has more than [`MAX_CLIPPED_CORNERS`] corners.
fn add_face(mesh: &mut TriMesh, idx: &[i64]) -> Result<(), String> {
    if let [a, b, c] = idx[..] {
        mesh.triangles.push(axes::wound([a, b, c].map(|i| (i - 1) as u32), false));
        return Ok(());
    }
    let v: Vec<u32> = idx.iter().map(|&i| (i - 1) as u32).collect();
    for t in triangulate_within(&v, &mesh.positions, MAX_CLIPPED_CORNERS).ok_or_else(|| too_many_corners(v.len()))? {
        mesh.triangles.push(axes::wound(t, false));
    }
    Ok(())
}

/// Why a face of `n` corners that is not convex is refused.
pub fn too_many_corners(n: usize) -> String {
    format!(
        "a face of {n} corners that is not convex: scnc triangulates faces that are not convex up to \
         {MAX_CLIPPED_CORNERS} corners (split it into smaller faces)"
    )
}

/// The Wavefront OBJ format.
pub struct Obj;

impl MeshFormat for Obj {
    const NAME: &'static str = "obj";
    const ABOUT: &'static str = "Wavefront OBJ with an MTL file beside it";
    const EXTENSIONS: &'static [&'static str] = &["obj"];
    const MIME: &'static str = "model/obj";
    const FOR_PRINTING: bool = false;
    const DEFAULT_SCALE: f64 = 1.0;
    const FIXED_UP: Option<Up> = None;
    const ONE_FILE: bool = false;
    const READS: &'static str = "OBJ files (`v x y z` and `f a b c …` records)";
    const READER: Reader = Reader::Lines(|r| read(r));

    fn working_bytes(part: &Part) -> (u64, u64) {
        (0, super::normals_bytes(part))
    }

    /// Its `mtllib` line names `options.mtl`, which [`mtl`] writes.
    fn write(export: &Export, options: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
        obj(export, options.mtl, w)
    }
}

fn obj(export: &Export, mtl: &str, w: &mut dyn Write) -> io::Result<()> {
    writeln!(w, "# scnc export: {} objects, {} triangles", export.parts.len(), export.triangle_count())?;
    writeln!(w, "mtllib {mtl}")?;
    // Vertex and normal numbers run on across objects; a smooth part writes one normal
    // per vertex, so its faces use the same number for both (`f a//a …`).
    let (mut base, mut normals) = (1u64, 1u64);
    for p in &export.parts {
        writeln!(w, "o {}", p.name)?;
        for v in &p.mesh.positions {
            let [x, y, z] = f32s(*v);
            writeln!(w, "v {x} {y} {z}")?;
        }
        if p.smooth {
            for n in p.vertex_normals() {
                // Rounding leaves components like 3e-18 where 0 is meant; f32 prints them
                // out in full, so they are written as 0.
                let [x, y, z] = f32s(n.to_array().map(|c| if c.abs() < 1e-7 { 0.0 } else { c }).into());
                writeln!(w, "vn {x} {y} {z}")?;
            }
        }
        let mut current = None;
        for (t, tri) in p.mesh.triangles.iter().enumerate() {
            if current != Some(p.materials[t]) {
                current = Some(p.materials[t]);
                writeln!(w, "usemtl {}", material_name(export, p.materials[t]))?;
            }
            let [a, b, c] = tri.map(|i| base + i as u64);
            if p.smooth {
                let [na, nb, nc] = tri.map(|i| normals + i as u64);
                writeln!(w, "f {a}//{na} {b}//{nb} {c}//{nc}")?;
            } else {
                writeln!(w, "f {a} {b} {c}")?;
            }
        }
        base += p.mesh.positions.len() as u64;
        if p.smooth {
            normals += p.mesh.positions.len() as u64;
        }
    }
    Ok(())
}

/// The MTL file of an OBJ export: each material used, its diffuse colour.
pub fn mtl(export: &Export, w: &mut dyn Write) -> io::Result<()> {
    writeln!(w, "# scnc export: material colours")?;
    for m in used(export) {
        let [r, g, b] = export.colours[m as usize].rgb8().map(|c| c as f32 / 255.0);
        writeln!(w, "newmtl {}", material_name(export, m))?;
        writeln!(w, "Kd {r} {g} {b}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(bytes: &[u8]) -> Result<TriMesh, ObjError> {
        read(bytes)
    }

    #[test]
    fn reads_triangles_quads_and_index_forms() {
        let m = parse(b"# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2//1 3 4\nf -4 -3 -2\n")
            .expect("valid");
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles.len(), 3);
    }

    /// The file's right-handed frame reads back as export writes it: z negated, and each
    /// triangle reversed with it, so its normal (in scnc's space) is the mirrored one.
    #[test]
    fn reads_into_scncs_space_as_export_writes() {
        let m = parse(b"v 0 0 1\nv 1 0 1\nv 0 1 1\nf 1 2 3\n").expect("valid");
        assert_eq!(m.positions[0], DVec3::new(0.0, 0.0, -1.0));
        // Counter-clockwise about +z in the file faces −z in scnc, towards the camera.
        let [a, b, c] = m.triangles[0].map(|i| m.positions[i as usize]);
        assert!((b - a).cross(c - a).z < 0.0);
    }

    /// Line ends of every kind, a continued line, and bytes that are not UTF-8 in a comment.
    #[test]
    fn reads_messy_files() {
        let cr = parse(b"v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r").expect("CR line ends");
        assert_eq!(cr.triangles.len(), 1);
        let crlf = parse(b"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n").expect("CRLF");
        assert_eq!(crlf.triangles.len(), 1);
        let continued = parse(b"v 0 0 0\nv 1 \\\n 0 0\nv 0 1 0\nf 1 \\\n2 3\n").expect("continuation");
        assert_eq!((continued.positions[1], continued.triangles.len()), (DVec3::X, 1));
        let latin1 = parse(b"# caf\xe9 \xff\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("Latin-1 comment");
        assert_eq!(latin1.triangles.len(), 1);
        // A continued line keeps the number of its first line in errors.
        assert_eq!(parse(b"v 0 0 0\nv 1 \\\n x 0\n").unwrap_err().line, 2);
    }

    /// Read a few bytes at a time, so that every line end, `\r\n` pair and continuation
    /// falls across the reader's buffers somewhere, a file reads as it does whole.
    #[test]
    fn lines_split_across_buffers_read_as_whole() {
        let files: [&[u8]; 4] = [
            b"v 0 0 0\rv 1 0 0\r\nv 0 1 0\n\rf 1 2 3\r",
            b"# caf\xe9\r\nv 0 0 0\nv 1 \\\r\n 0 0\nv 0 1 0 # x\r\nf 1 \\\r2 3",
            b"v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n",
            b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
        ];
        for bytes in files {
            let whole = parse(bytes).expect("valid");
            for capacity in 1..8 {
                let mesh = read(std::io::BufReader::with_capacity(capacity, bytes)).expect("valid");
                assert_eq!((&mesh.positions, &mesh.triangles), (&whole.positions, &whole.triangles), "{capacity}");
            }
        }
        // Line numbers count `\r\n` once, split or not.
        let bad = b"v 0 0 0\r\nv 1 0 0\r\nv x 0 0\r\n";
        for capacity in 1..8 {
            assert_eq!(read(std::io::BufReader::with_capacity(capacity, &bad[..])).unwrap_err().line, 3);
        }
    }

    /// An L-shaped plate: ear clipping keeps the notch open (a fan from the first corner
    /// would cover it), and the triangles' area is the L's.
    #[test]
    fn concave_polygons_keep_their_outline() {
        let l = b"v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n";
        let m = parse(l).expect("valid");
        assert_eq!(m.triangles.len(), 4);
        let area: f64 = m
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                (b - a).cross(c - a).length() / 2.0
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-12, "area {area}");
        // The notch's centre (1.5, 1.5) is in no triangle.
        let inside = |p: glam::DVec2| {
            m.triangles.iter().any(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize].truncate());
                let s = |u: glam::DVec2, v: glam::DVec2| (v - u).perp_dot(p - u);
                let (x, y, z) = (s(a, b), s(b, c), s(c, a));
                (x >= 0.0 && y >= 0.0 && z >= 0.0) || (x <= 0.0 && y <= 0.0 && z <= 0.0)
            })
        };
        assert!(!inside(glam::DVec2::new(1.5, 1.5)) && inside(glam::DVec2::new(0.5, 1.5)));
    }

    /// A byte-order mark before the first record is skipped, not read into it.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let m = parse("\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".as_bytes()).expect("valid");
        assert_eq!((m.positions.len(), m.triangles.len()), (3, 1));
    }

    #[test]
    fn reports_bad_input_with_lines() {
        assert_eq!(parse(b"v 0 0\n").unwrap_err().line, 1);
        assert!(parse(b"v 0 0 nan\n").unwrap_err().message.contains("not finite"));
        assert!(parse(b"v 0 0 inf\n").unwrap_err().message.contains("not finite"));
        assert!(parse(b"v 0 0 1e300\n").unwrap_err().message.contains("renderable range"));
        let e = parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert_eq!((e.line, e.message.contains("out of range")), (4, true));
        assert!(parse(b"v 0 0 0\nf 1 1\n").unwrap_err().message.contains("at least 3"));
        assert!(parse(b"v 0 0 0\nf 0 1 1\n").unwrap_err().message.contains("start at 1"));
        assert_eq!(parse(b"v 0 0 0\n").unwrap_err().line, 0);
        assert!(parse(b"v 0 0 0\nf a b c\n").is_err());
    }
}
