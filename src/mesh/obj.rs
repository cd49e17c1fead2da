//! A Wavefront OBJ reader for triangle meshes: `v` and `f` records (polygons are
//! triangulated by ear clipping; `i`, `i/t`, `i//n`, `i/t/n` and negative relative
//! indices are accepted); other records are ignored. Lines may end in `\n`, `\r\n` or
//! `\r` and continue after a `\`; comments may hold any bytes. Every problem is reported
//! with its line number.

use glam::DVec3;

use crate::geom::polygon::triangulate;
use crate::geom::{axes, TriMesh};

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

/// Most vertices or faces accepted from one file.
pub const MAX_ELEMENTS: usize = 50_000_000;

/// Largest coordinate accepted: the renderable range of positions in a scene
/// (docs/limits.md), so a mesh file places nothing a scene could not.
pub const MAX_COORDINATE: f64 = 1e15;

/// Why a mesh file's vertex `p` cannot be placed, if it cannot: not finite, or beyond
/// [`MAX_COORDINATE`] (every reader's one check).
pub fn unrenderable(p: DVec3) -> Option<String> {
    (!p.is_finite() || p.abs().max_element() > MAX_COORDINATE)
        .then(|| format!("is beyond the renderable range (±{MAX_COORDINATE:e})"))
}

/// The logical lines of an OBJ file, numbered from 1: lines end at `\n`, `\r\n` or a lone
/// `\r` (old Mac exporters), a line ending in `\` continues on the next (its number is
/// the first's), and a comment runs from `#` to the end of its line whatever bytes it
/// holds (Latin-1 in a comment is common).
fn logical_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, String)> + '_ {
    let mut physical = bytes
        .split(|&b| b == b'\n')
        .flat_map(|l| {
            let l = l.strip_suffix(b"\r").unwrap_or(l);
            l.split(|&b| b == b'\r')
        })
        .enumerate()
        .map(|(n, l)| (n + 1, l));
    std::iter::from_fn(move || {
        let (first, line) = physical.next()?;
        let mut joined: Vec<u8> = Vec::new();
        let mut line = line;
        loop {
            let content = line.split(|&b| b == b'#').next().unwrap_or(&[]);
            let trimmed = content.trim_ascii_end();
            match trimmed.strip_suffix(b"\\") {
                Some(head) if content.len() == line.len() => {
                    joined.extend_from_slice(head);
                    joined.push(b' ');
                    match physical.next() {
                        Some((_, next)) => line = next,
                        None => break,
                    }
                }
                _ => {
                    joined.extend_from_slice(content);
                    break;
                }
            }
        }
        Some((first, String::from_utf8_lossy(&joined).into_owned()))
    })
}

/// Parses an OBJ file's bytes into scnc's space: the file's right-handed, y-up frame
/// mapped as export maps it ([`crate::geom::axes`]), so an exported model reads back where
/// it was, unmirrored.
pub fn parse(bytes: &[u8]) -> Result<TriMesh, ObjError> {
    // Some exporters start the file with a byte-order mark; it would hide the first `v`.
    let bytes = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes);
    let mut mesh = TriMesh::default();
    let mut faces: Vec<(usize, Vec<i64>)> = Vec::new();
    for (line, content) in logical_lines(bytes) {
        let mut words = content.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<&str> = words.collect();
                if coords.len() < 3 {
                    return Err(err(line, format!("a vertex needs 3 coordinates, found {}", coords.len())));
                }
                let mut p = [0.0; 3];
                for (k, w) in coords.iter().take(3).enumerate() {
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
                    p[k] = x;
                }
                mesh.positions.push(axes::from_file(DVec3::from(p), axes::Up::Y));
            }
            Some("f") => {
                let mut idx = Vec::new();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| err(line, format!("`{w}` is not a vertex index")))?;
                    if i == 0 {
                        return Err(err(line, "vertex indices start at 1; 0 is not valid"));
                    }
                    // Negative indices count back from the vertices defined so far.
                    idx.push(if i < 0 { mesh.positions.len() as i64 + i + 1 } else { i });
                }
                if idx.len() < 3 {
                    return Err(err(line, format!("a face needs at least 3 vertices, found {}", idx.len())));
                }
                faces.push((line, idx));
            }
            _ => {}
        }
        if mesh.positions.len() > MAX_ELEMENTS || faces.len() > MAX_ELEMENTS {
            return Err(err(line, format!("more than {MAX_ELEMENTS} vertices or faces")));
        }
    }
    let count = mesh.positions.len() as i64;
    for (line, idx) in faces {
        for &i in &idx {
            if i < 1 || i > count {
                return Err(err(line, format!("vertex index {i} is out of range: the file has {count} vertices")));
            }
        }
        let v: Vec<u32> = idx.iter().map(|&i| (i - 1) as u32).collect();
        for [a, b, c] in triangulate(&v, &mesh.positions) {
            // The mapping from the file is a reflection: reversed, a face stays wound
            // as the file winds it, seen from the same side.
            mesh.triangles.push(if axes::REVERSES_WINDING { [a, c, b] } else { [a, b, c] });
        }
    }
    if mesh.triangles.is_empty() {
        return Err(err(0, "the file has no faces"));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

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
