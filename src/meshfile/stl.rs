//! An STL reader (binary or ASCII, through `stl_io`, which export already uses): facets
//! welded into a connected mesh by exact vertex position, mapped from the file's z-up
//! frame, the one STL export writes and slicers and CAD tools use, and from millimetres
//! (a scene unit is [`axes::STL_PER_UNIT`] of them).

use glam::DVec3;

use crate::geom::{axes, TriMesh};
use std::io::{self, Write};

use super::{f32s, Export, MeshFormat, Part, Reader, Up, WriteOptions};

/// Parses an STL file's bytes into scnc's space; an error says what is wrong.
pub fn parse(bytes: &[u8]) -> Result<TriMesh, String> {
    let mut cursor = std::io::Cursor::new(bytes);
    let indexed = stl_io::read_stl(&mut cursor).map_err(|e| format!("not a readable STL file ({e})"))?;
    if indexed.vertices.len() > super::MAX_ELEMENTS || indexed.faces.len() > super::MAX_ELEMENTS {
        return Err(format!("more than {} vertices or facets", super::MAX_ELEMENTS));
    }
    let mut mesh = TriMesh::default();
    for (i, v) in indexed.vertices.iter().enumerate() {
        let p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64) / axes::STL_PER_UNIT;
        if !p.is_finite() {
            return Err(format!("vertex {} is not finite", i + 1));
        }
        if let Some(why) = super::unrenderable(p) {
            return Err(format!("vertex {} {why}", i + 1));
        }
        mesh.positions.push(axes::from_file(p, axes::Up::Z));
    }
    for f in &indexed.faces {
        let [a, b, c] = f.vertices.map(|i| i as u32);
        // A facet whose corners weld together has no area.
        if a == b || b == c || a == c {
            continue;
        }
        mesh.triangles.push(axes::wound([a, b, c], false));
    }
    if mesh.triangles.is_empty() {
        return Err("the file has no facets with area".into());
    }
    Ok(mesh)
}

/// The STL format.
pub struct Stl;

impl MeshFormat for Stl {
    const NAME: &'static str = "stl";
    const ABOUT: &'static str = "STL (binary; ASCII with `--ascii`)";
    const EXTENSIONS: &'static [&'static str] = &["stl"];
    const MIME: &'static str = "model/stl";
    const FOR_PRINTING: bool = true;
    // Millimetres to every slicer; a scene unit is a centimetre for printing.
    const DEFAULT_SCALE: f64 = axes::STL_PER_UNIT;
    const FIXED_UP: Option<Up> = None;
    const ONE_FILE: bool = true;
    const READS: &'static str = "STL (`.stl`, binary or ASCII, z up, millimetres)";
    // A file's mesh is the size of the file: the mesh budget is spent once it is read.
    const READER: Reader = Reader::Whole(|bytes, _| parse(bytes));

    fn working_bytes(_: &Part) -> (u64, u64) {
        // Facets are made as they are written.
        (0, 0)
    }

    fn write(export: &Export, options: &WriteOptions, mut w: &mut dyn Write) -> io::Result<()> {
        if options.ascii {
            stl_ascii(export, w)
        } else {
            stl_io::write_stl(&mut w, facets(export))
        }
    }
}

/// Every triangle of every part with its unit normal, in order, made as they are
/// written (a list of them took 16 bytes a triangle: 320 MB for 20 M).
struct Facets<'a> {
    export: &'a Export,
    part: usize,
    triangle: usize,
    left: usize,
}

fn facets(export: &Export) -> Facets<'_> {
    Facets { export, part: 0, triangle: 0, left: export.triangle_count() }
}

impl Iterator for Facets<'_> {
    type Item = stl_io::Triangle;

    fn next(&mut self) -> Option<stl_io::Triangle> {
        loop {
            let p = self.export.parts.get(self.part)?;
            if self.triangle < p.mesh.triangles.len() {
                let t = self.triangle;
                self.triangle += 1;
                self.left -= 1;
                return Some(stl_io::Triangle {
                    normal: stl_io::Vector::new(f32s(p.face_normal(t))),
                    vertices: p.mesh.triangles[t].map(|i| stl_io::Vector::new(f32s(p.mesh.positions[i as usize]))),
                });
            }
            self.part += 1;
            self.triangle = 0;
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

impl ExactSizeIterator for Facets<'_> {}

fn stl_ascii(export: &Export, w: &mut dyn Write) -> io::Result<()> {
    writeln!(w, "solid scnc")?;
    for f in facets(export) {
        let [x, y, z] = f.normal.0;
        writeln!(w, "  facet normal {x} {y} {z}")?;
        writeln!(w, "    outer loop")?;
        for v in f.vertices {
            let [x, y, z] = v.0;
            writeln!(w, "      vertex {x} {y} {z}")?;
        }
        writeln!(w, "    endloop")?;
        writeln!(w, "  endfacet")?;
    }
    writeln!(w, "endsolid scnc")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_read_the_same_welded_tetrahedron() {
        let ascii = b"solid t
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 1 0
  vertex 1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 0 1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 1
  vertex 0 1 0
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 1 0 0
  vertex 0 1 0
  vertex 0 0 1
 endloop
endfacet
endsolid t
";
        let a = parse(ascii).expect("ASCII STL");
        assert_eq!((a.positions.len(), a.triangles.len()), (4, 4));
        assert_eq!(a.open_edges(), (0, 0), "welded and consistently wound");
        assert!(a.signed_volume() > 0.0, "outward, as the file winds it");
        let mut binary = vec![0u8; 80];
        binary.extend_from_slice(&4u32.to_le_bytes());
        let corners = [[0., 0., 0.], [0., 1., 0.], [1., 0., 0.], [0., 0., 0.], [1., 0., 0.], [0., 0., 1.]];
        let more = [[0., 0., 0.], [0., 0., 1.], [0., 1., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
        for tri in corners.chunks(3).chain(more.chunks(3)) {
            binary.extend_from_slice(&[0u8; 12]);
            for v in tri {
                for x in v {
                    binary.extend_from_slice(&(*x as f32).to_le_bytes());
                }
            }
            binary.extend_from_slice(&[0, 0]);
        }
        let b = parse(&binary).expect("binary STL");
        assert_eq!(b.triangles.len(), 4);
        assert!((b.signed_volume() - a.signed_volume()).abs() < 1e-12);
        assert!(parse(b"solid nothing\nendsolid\n").is_err());
        assert!(parse(b"hello").is_err());
    }
}
