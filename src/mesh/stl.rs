//! An STL reader (binary or ASCII, through `stl_io`, which export already uses): facets
//! welded into a connected mesh by exact vertex position, mapped from the file's z-up
//! frame, the one STL export writes and slicers and CAD tools use, and from millimetres
//! (a scene unit is [`axes::STL_PER_UNIT`] of them).

use glam::DVec3;

use crate::geom::{axes, TriMesh};

/// Parses an STL file's bytes into scnc's space; an error says what is wrong.
pub fn parse(bytes: &[u8]) -> Result<TriMesh, String> {
    let mut cursor = std::io::Cursor::new(bytes);
    let indexed = stl_io::read_stl(&mut cursor).map_err(|e| format!("not a readable STL file ({e})"))?;
    if indexed.vertices.len() > super::obj::MAX_ELEMENTS || indexed.faces.len() > super::obj::MAX_ELEMENTS {
        return Err(format!("more than {} vertices or facets", super::obj::MAX_ELEMENTS));
    }
    let mut mesh = TriMesh::default();
    for (i, v) in indexed.vertices.iter().enumerate() {
        let p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64) / axes::STL_PER_UNIT;
        if !p.is_finite() {
            return Err(format!("vertex {} is not finite", i + 1));
        }
        if let Some(why) = super::obj::unrenderable(p) {
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
