//! A Wavefront OBJ reader for triangle meshes: `v` and `f` records (polygons are fan
//! triangulated; `i`, `i/t`, `i//n`, `i/t/n` and negative relative indices are accepted);
//! other records are ignored. Every problem is reported with its line number.

use glam::DVec3;

use crate::geom::TriMesh;

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

/// Parses OBJ text.
pub fn parse(text: &str) -> Result<TriMesh, ObjError> {
    // Some exporters start the file with a byte-order mark; it would hide the first `v`.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut mesh = TriMesh::default();
    let mut faces: Vec<(usize, Vec<i64>)> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = n + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
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
                    p[k] = x;
                }
                mesh.positions.push(DVec3::from(p));
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
        for k in 1..v.len() - 1 {
            mesh.triangles.push([v[0], v[k], v[k + 1]]);
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
        let m = parse("# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2//1 3 4\nf -4 -3 -2\n")
            .expect("valid");
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
    }

    /// A byte-order mark before the first record is skipped, not read into it.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let m = parse("\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("valid");
        assert_eq!((m.positions.len(), m.triangles.len()), (3, 1));
    }

    #[test]
    fn reports_bad_input_with_lines() {
        assert_eq!(parse("v 0 0\n").unwrap_err().line, 1);
        assert!(parse("v 0 0 nan\n").unwrap_err().message.contains("not finite"));
        assert!(parse("v 0 0 inf\n").unwrap_err().message.contains("not finite"));
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert_eq!((e.line, e.message.contains("out of range")), (4, true));
        assert!(parse("v 0 0 0\nf 1 1\n").unwrap_err().message.contains("at least 3"));
        assert!(parse("v 0 0 0\nf 0 1 1\n").unwrap_err().message.contains("start at 1"));
        assert_eq!(parse("v 0 0 0\n").unwrap_err().line, 0);
        assert!(parse("v 0 0 0\nf a b c\n").is_err());
    }
}
