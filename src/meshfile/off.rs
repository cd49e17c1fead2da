//! OFF (Object File Format, Geomview's; what OpenSCAD and CGAL read and write): a
//! header line `OFF`, the counts `vertices faces edges`, a line per vertex and a line per
//! face (`n i0 … in-1`, then optionally its colour). Read and written z up in
//! millimetres, as OpenSCAD models are, so a part goes between the two unchanged.
//! Comments (`#` to the end of a line) are allowed anywhere; a vertex line's extra
//! numbers (COFF's colours, NOFF's normals) and a face's colour are read past.

use std::io::{self, Write};

use glam::DVec3;

use super::{Export, MeshFormat, Part, Reader, Up, WriteOptions, MAX_ELEMENTS};
use crate::geom::polygon::{triangulate_within, MAX_CLIPPED_CORNERS};
use crate::geom::{axes, TriMesh};

/// The header keywords read: plain OFF and its variants whose vertex lines carry more
/// than the position (colours, normals, texture coordinates), which are skipped.
const HEADERS: [&str; 6] = ["OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF"];

/// Parses an OFF file's bytes into scnc's space; an error says what is wrong and on
/// which line.
pub fn parse(bytes: &[u8], allowed: u64) -> Result<TriMesh, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not a text OFF file (binary OFF is not read)".to_string())?;
    // Lines without their comments, numbered from 1, blank ones left out.
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(n, l)| (n + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let (n, first) = lines.next().ok_or("the file is empty")?;
    let mut words = first.split_whitespace();
    let header = words.next().unwrap_or("");
    if !HEADERS.contains(&header) {
        return Err(format!("line {n}: an OFF file starts with `OFF`, not `{header}`"));
    }
    // The counts may follow the keyword on its line (as some writers put them).
    let rest: Vec<&str> = words.collect();
    let (n, counts) = if rest.is_empty() { lines.next().ok_or("the file ends before its counts")? } else { (n, "") };
    let counts: Vec<&str> = if rest.is_empty() { counts.split_whitespace().collect() } else { rest };
    let count = |i: usize, what: &str| -> Result<usize, String> {
        let w = counts.get(i).ok_or_else(|| format!("line {n}: the counts line has no number of {what}"))?;
        w.parse::<usize>().map_err(|_| format!("line {n}: `{w}` is not a number of {what}"))
    };
    let (vertices, faces) = (count(0, "vertices")?, count(1, "faces")?);
    if vertices > MAX_ELEMENTS || faces > MAX_ELEMENTS {
        return Err(format!("line {n}: more than {MAX_ELEMENTS} vertices or faces"));
    }
    // A vertex and a triangle per face at least: refused before anything is allocated.
    let bytes_needed = super::Expansion { vertices: vertices as u64, triangles: faces as u64, uses: 1 }.bytes();
    if bytes_needed > allowed {
        return Err(format!(
            "its {vertices} vertices and {faces} faces take {} as a mesh, more than the {} the memory limit leaves \
             (`--memory-limit`)",
            crate::diag::bytes(bytes_needed),
            crate::diag::bytes(allowed)
        ));
    }
    let mut mesh = TriMesh { positions: Vec::with_capacity(vertices), triangles: Vec::with_capacity(faces) };
    for i in 0..vertices {
        let (n, line) = lines.next().ok_or_else(|| format!("the file ends after {i} of its {vertices} vertices"))?;
        let xyz: Vec<f64> = line.split_whitespace().take(3).map(str::parse).collect::<Result<_, _>>().map_err(|_| {
            format!("line {n}: vertex {} is not three numbers", i + 1)
        })?;
        let [x, y, z] = xyz[..] else { return Err(format!("line {n}: vertex {} is not three numbers", i + 1)) };
        let p = DVec3::new(x, y, z) / axes::STL_PER_UNIT;
        if let Some(why) = super::unrenderable(p) {
            return Err(format!("line {n}: vertex {} {why}", i + 1));
        }
        mesh.positions.push(axes::from_file(p, Up::Z));
    }
    read_faces(&mut lines, faces, &mut mesh)?;
    if mesh.triangles.is_empty() {
        return Err("the file has no faces with three distinct corners".into());
    }
    Ok(mesh)
}

/// Reads `faces` face lines into `mesh`'s triangles (its vertices read already),
/// ear-clipping polygons; an error names the line.
fn read_faces<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    faces: usize,
    mesh: &mut TriMesh,
) -> Result<(), String> {
    let vertices = mesh.positions.len();
    let mut idx = Vec::new();
    for f in 0..faces {
        let (n, line) = lines.next().ok_or_else(|| format!("the file ends after {f} of its {faces} faces"))?;
        let mut words = line.split_whitespace();
        let corners: usize = words
            .next()
            .and_then(|w| w.parse().ok())
            .ok_or_else(|| format!("line {n}: face {} does not start with its number of corners", f + 1))?;
        if corners < 3 {
            return Err(format!("line {n}: face {} has {corners} corners; a face has at least 3", f + 1));
        }
        idx.clear();
        for _ in 0..corners {
            let i = words
                .next()
                .and_then(|w| w.parse::<u32>().ok())
                .ok_or_else(|| format!("line {n}: face {} lists fewer than its {corners} corners", f + 1))?;
            if i as usize >= vertices {
                return Err(format!(
                    "line {n}: face {}: vertex index {i} is out of range: the file has {vertices} vertices",
                    f + 1
                ));
            }
            idx.push(i);
        }
        // What follows is the face's colour, if any: not a scene's business.
        let triangles = triangulate_within(&idx, &mesh.positions, MAX_CLIPPED_CORNERS)
            .ok_or_else(|| format!("line {n}: face {}: {}", f + 1, super::obj::too_many_corners(corners)))?;
        for t in triangles {
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                mesh.triangles.push(axes::wound(t, false));
            }
        }
    }
    Ok(())
}

/// The OFF format.
pub struct Off;

impl MeshFormat for Off {
    const NAME: &'static str = "off";
    const ABOUT: &'static str = "OFF, as OpenSCAD and CGAL read it, with a colour per face";
    const EXTENSIONS: &'static [&'static str] = &["off"];
    const MIME: &'static str = "text/plain";
    // OpenSCAD's exchange format, for parts headed to a print: z up, millimetres.
    const FOR_PRINTING: bool = true;
    const DEFAULT_SCALE: f64 = axes::STL_PER_UNIT;
    const FIXED_UP: Option<Up> = None;
    const ONE_FILE: bool = true;
    const READS: &'static str = "OFF (`.off`, text, z up, millimetres, as OpenSCAD writes it)";
    const READER: Reader = Reader::Whole(parse);

    fn working_bytes(_: &Part) -> (u64, u64) {
        // Vertices and faces are written as they are read off the parts.
        (0, 0)
    }

    fn write(export: &Export, _: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
        let vertices: usize = export.parts.iter().map(|p| p.mesh.positions.len()).sum();
        writeln!(w, "OFF")?;
        writeln!(w, "# written by scnc: {} parts, z up, millimetres", export.parts.len())?;
        writeln!(w, "{vertices} {} 0", export.triangle_count())?;
        for p in &export.parts {
            for v in &p.mesh.positions {
                // f32, as every other format writes, in its shortest round-trip form.
                let [x, y, z] = super::f32s(*v);
                writeln!(w, "{x} {y} {z}")?;
            }
        }
        // Each part's corners follow those of the parts before it.
        let mut base = 0u32;
        for p in &export.parts {
            for (t, &m) in p.mesh.triangles.iter().zip(&p.materials) {
                let [a, b, c] = t.map(|i| i + base);
                // Colours as Geomview reads them: RGBA, each from 0 to 1.
                let [r, g, bl] = export.colours[m as usize].rgb8().map(|c| c as f32 / 255.0);
                writeln!(w, "3 {a} {b} {c} {r} {g} {bl} 1")?;
            }
            base += p.mesh.positions.len() as u32;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tetrahedron with a comment, counts on the header line, a quad split in two, a
    /// colour after a face and COFF's colour after a vertex: closed, outward, mapped
    /// from z-up millimetres.
    #[test]
    fn reads_a_commented_coloured_file_with_a_quad() {
        let text = b"OFF 5 5 0 # counts on the header line\n\
            0 0 0\n10 0 0 0.5 0.5 0.5 1\n10 10 0\n0 10 0\n5 5 10\n\
            4 0 3 2 1 255 0 0\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";
        let m = parse(text, u64::MAX).expect("a pyramid");
        assert_eq!((m.positions.len(), m.triangles.len()), (5, 6));
        assert_eq!(m.open_edges(), (0, 0), "closed and consistently wound");
        // A 1 × 1 base and a height of 1 in scene units: a third of a unit.
        assert!((m.signed_volume() - 1.0 / 3.0).abs() < 1e-12, "{}", m.signed_volume());
        assert!(m.positions[4].y > 0.9, "the file's z is the scene's up");
    }

    #[test]
    fn refuses_what_it_cannot_place_with_the_line() {
        let cases: [(&[u8], &str); 7] = [
            (b"PLY\n", "starts with `OFF`"),
            (b"OFF\n3 1\n0 0 0\n1 0 0\n", "ends after 2 of its 3 vertices"),
            (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 x\n3 0 1 2\n", "line 5: vertex 3 is not three numbers"),
            (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "vertex index 3 is out of range"),
            (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "has 2 corners"),
            (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 1e300\n3 0 1 2\n", "beyond the renderable range"),
            (b"OFF\n99999999999 1 0\n", "more than"),
        ];
        for (text, why) in cases {
            let e = parse(text, u64::MAX).expect_err(why);
            assert!(e.contains(why), "{e} (expected `{why}`)");
        }
        let e = parse(b"OFF\n1000 1000 0\n", 1000).expect_err("over the allowance");
        assert!(e.contains("memory limit"), "{e}");
    }
}
