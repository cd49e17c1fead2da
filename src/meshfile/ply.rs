//! A PLY reader (ASCII, binary little- and big-endian): the `vertex` element's `x y z`
//! and the `face` element's index list (`vertex_indices` or `vertex_index`), polygons
//! triangulated by ear clipping; every other element and property is skipped by its
//! declared type. Written here rather than taken from `ply-rs`, which builds a map of
//! named properties for every vertex (a few hundred bytes each, for millions of vertices)
//! and is no longer maintained; what scnc needs is the header and two elements.
//! PLY is y up, as export writes it ([`axes::Up::Y`]).

use glam::DVec3;

use super::MAX_ELEMENTS;
use crate::geom::polygon::{triangulate_within, MAX_CLIPPED_CORNERS};
use crate::geom::{axes, TriMesh};
use std::io::{self, Write};

use super::{f32s, Export, Group, MeshFormat, Part, Reader, Up, WriteOptions};

/// A scalar type of the header.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

/// A property: a scalar, or a list with its count's type.
#[derive(Clone, Debug)]
struct Property {
    name: String,
    count: Option<Scalar>,
    ty: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// Reads the values of one element, in the file's encoding.
trait Values {
    fn next(&mut self, ty: Scalar) -> Result<f64, String>;
}

struct Binary<'a> {
    bytes: &'a [u8],
    at: usize,
    big: bool,
}

impl Values for Binary<'_> {
    fn next(&mut self, ty: Scalar) -> Result<f64, String> {
        let n = ty.size();
        let b = self.bytes.get(self.at..self.at + n).ok_or("the file ends inside its data")?;
        self.at += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        Ok(match ty {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
}

struct Ascii<'a> {
    words: std::str::SplitAsciiWhitespace<'a>,
}

impl Values for Ascii<'_> {
    fn next(&mut self, _: Scalar) -> Result<f64, String> {
        let w = self.words.next().ok_or("the file ends inside its data")?;
        w.parse().map_err(|_| format!("`{w}` is not a number"))
    }
}

/// Parses a PLY file's bytes into scnc's space; an error says what is wrong.
pub fn parse(bytes: &[u8]) -> Result<TriMesh, String> {
    let (encoding, elements, body) = header(bytes)?;
    let body = &bytes[body..];
    match encoding {
        Encoding::Ascii => {
            let text = std::str::from_utf8(body).map_err(|_| "the ASCII data is not text".to_string())?;
            read(&elements, &mut Ascii { words: text.split_ascii_whitespace() })
        }
        Encoding::Little | Encoding::Big => {
            read(&elements, &mut Binary { bytes: body, at: 0, big: encoding == Encoding::Big })
        }
    }
}

/// The header: encoding, elements, and where the data starts.
fn header(bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize), String> {
    if !bytes.starts_with(b"ply") {
        return Err("not a PLY file (it does not start with `ply`)".into());
    }
    let end = bytes.windows(10).position(|w| w == b"end_header").ok_or("the header has no `end_header`")?;
    // The data starts after the line ending that follows `end_header`.
    let mut body = end + 10;
    while body < bytes.len() && bytes[body] != b'\n' {
        body += 1;
    }
    let text = std::str::from_utf8(&bytes[..end]).map_err(|_| "the header is not text".to_string())?;
    let (mut encoding, mut elements) = (None, Vec::<Element>::new());
    for line in text.lines().skip(1) {
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        match words.as_slice() {
            ["format", f, _] => {
                encoding = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => return Err(format!("unknown format `{other}`")),
                })
            }
            ["element", name, count] => {
                let count = count.parse().map_err(|_| format!("element `{name}` has count `{count}`"))?;
                if count > MAX_ELEMENTS {
                    return Err(format!("more than {MAX_ELEMENTS} {name} elements"));
                }
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            ["property", "list", count, ty, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                let bad = || format!("property `{name}` has an unknown type");
                let (count, ty) = (Scalar::parse(count).ok_or_else(bad)?, Scalar::parse(ty).ok_or_else(bad)?);
                e.properties.push(Property { name: name.to_string(), count: Some(count), ty });
            }
            ["property", ty, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                let ty = Scalar::parse(ty).ok_or_else(|| format!("property `{name}` has an unknown type `{ty}`"))?;
                e.properties.push(Property { name: name.to_string(), count: None, ty });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(format!("cannot read the header line `{line}`")),
        }
    }
    Ok((encoding.ok_or("the header has no `format` line")?, elements, body + 1))
}

/// Reads every element in order, keeping vertex positions and faces.
///
/// Long because it reads the header's elements in order, each kind its own branch; PLY
/// files interleave them.
fn read(elements: &[Element], values: &mut dyn Values) -> Result<TriMesh, String> {
    let mut file_positions = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for e in elements {
        let find = |n: &str| e.properties.iter().position(|p| p.name == n && p.count.is_none());
        let xyz = (e.name == "vertex").then(|| (find("x"), find("y"), find("z")));
        let list = e
            .properties
            .iter()
            .position(|p| p.count.is_some() && matches!(p.name.as_str(), "vertex_indices" | "vertex_index"));
        let face = e.name == "face";
        if let Some((None, _, _) | (_, None, _) | (_, _, None)) = xyz {
            return Err("the vertex element has no `x`, `y` and `z`".into());
        }
        if face && list.is_none() {
            return Err("the face element has no `vertex_indices` list".into());
        }
        for i in 0..e.count {
            let mut p = [0.0; 3];
            for (k, prop) in e.properties.iter().enumerate() {
                match prop.count {
                    None => {
                        let v = values.next(prop.ty)?;
                        if let Some((Some(x), Some(y), Some(z))) = xyz {
                            if let Some(axis) = [x, y, z].iter().position(|&a| a == k) {
                                p[axis] = v;
                            }
                        }
                    }
                    Some(count_ty) => {
                        let n = values.next(count_ty)?;
                        if !(0.0..=1e6).contains(&n) {
                            return Err(format!("{} {}: a list of {n} values", e.name, i + 1));
                        }
                        let mut idx = Vec::with_capacity(n as usize);
                        for _ in 0..n as usize {
                            idx.push(values.next(prop.ty)?);
                        }
                        if face && Some(k) == list {
                            let ok = idx.iter().all(|&v| v >= 0.0 && v.fract() == 0.0 && v < u32::MAX as f64);
                            if !ok || idx.len() < 3 {
                                return Err(format!("face {}: a polygon needs three or more vertex indices", i + 1));
                            }
                            faces.push(idx.iter().map(|&v| v as u32).collect());
                        }
                    }
                }
            }
            if xyz.is_some() {
                let p = DVec3::from(p);
                if let Some(why) = super::unrenderable(p) {
                    return Err(format!("vertex {} {why}", i + 1));
                }
                file_positions.push(p);
            }
        }
    }
    let mut mesh = TriMesh {
        positions: file_positions.iter().map(|&p| axes::from_file(p, axes::Up::Y)).collect(),
        triangles: Vec::new(),
    };
    for (f, idx) in faces.iter().enumerate() {
        if let Some(&i) = idx.iter().find(|&&i| i as usize >= mesh.positions.len()) {
            return Err(format!(
                "face {}: vertex index {i} is out of range: the file has {} vertices",
                f + 1,
                mesh.positions.len()
            ));
        }
        let triangles = triangulate_within(idx, &mesh.positions, MAX_CLIPPED_CORNERS)
            .ok_or_else(|| format!("face {}: {}", f + 1, super::obj::too_many_corners(idx.len())))?;
        for [a, b, c] in triangles {
            mesh.triangles.push(axes::wound([a, b, c], false));
        }
    }
    if mesh.triangles.is_empty() {
        return Err("the file has no faces".into());
    }
    Ok(mesh)
}

/// The PLY format.
pub struct Ply;

impl MeshFormat for Ply {
    const NAME: &'static str = "ply";
    const ABOUT: &'static str = "PLY, binary, with vertex colours";
    const EXTENSIONS: &'static [&'static str] = &["ply"];
    const MIME: &'static str = "application/octet-stream";
    const FOR_PRINTING: bool = false;
    const DEFAULT_SCALE: f64 = 1.0;
    const FIXED_UP: Option<Up> = None;
    const ONE_FILE: bool = true;
    const READS: &'static str = "PLY (`.ply`)";
    // A file's mesh is the size of the file: the mesh budget is spent once it is read.
    const READER: Reader = Reader::Whole(|bytes, _| parse(bytes));

    fn working_bytes(part: &Part) -> (u64, u64) {
        (super::groups_bytes(part), 0)
    }

    fn write(export: &Export, _: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
        ply(export, w)
    }
}

fn ply(export: &Export, w: &mut dyn Write) -> io::Result<()> {
    let groups: Vec<(&Part, Vec<Group>)> = export.parts.iter().map(|p| (p, p.groups())).collect();
    let vertices: usize = groups.iter().flat_map(|(_, gs)| gs.iter().map(|g| g.vertices.len())).sum();
    let faces = export.triangle_count();
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment scnc export\nelement vertex {vertices}\n\
         property float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {faces}\nproperty list uchar uint vertex_indices\nend_header\n"
    )?;
    for (p, gs) in &groups {
        for g in gs {
            let rgb = export.colours[g.material as usize].rgb8();
            for &v in &g.vertices {
                for c in f32s(p.mesh.positions[v as usize]) {
                    w.write_all(&c.to_le_bytes())?;
                }
                w.write_all(&rgb)?;
            }
        }
    }
    let mut base = 0u32;
    for (_, gs) in &groups {
        for g in gs {
            for t in &g.triangles {
                w.write_all(&[3])?;
                for i in t {
                    w.write_all(&(base + i).to_le_bytes())?;
                }
            }
            base += g.vertices.len() as u32;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "ply\nformat ascii 1.0\ncomment a unit square and a triangle\n\
        element vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n\
        element face 2\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n0 0 1 5\n4 0 1 2 3\n3 0 1 4\n";

    #[test]
    fn ascii_polygons_are_triangulated_in_scncs_space() {
        let m = parse(SQUARE.as_bytes()).expect("reads");
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles.len(), 3);
        // y up, mirrored in z as export writes it.
        assert_eq!(m.positions[4], DVec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn binary_of_either_endianness_reads_the_same() {
        let ascii = parse(SQUARE.as_bytes()).expect("reads");
        for (name, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut b = format!(
                "ply\nformat {name} 1.0\nelement vertex 5\nproperty double x\nproperty float y\nproperty float z\n\
                 property uchar red\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
            )
            .into_bytes();
            let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            for v in vertices {
                let x = if big { f64::to_be_bytes(v[0]) } else { f64::to_le_bytes(v[0]) };
                b.extend_from_slice(&x);
                for c in [v[1] as f32, v[2] as f32] {
                    b.extend_from_slice(&if big { c.to_be_bytes() } else { c.to_le_bytes() });
                }
                b.push(7);
            }
            for f in [&[0i32, 1, 2, 3][..], &[0, 1, 4]] {
                b.push(f.len() as u8);
                for i in f {
                    b.extend_from_slice(&if big { i.to_be_bytes() } else { i.to_le_bytes() });
                }
            }
            let m = parse(&b).expect(name);
            assert_eq!((m.positions.clone(), m.triangles.clone()), (ascii.positions.clone(), ascii.triangles.clone()));
        }
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let cases = [
            ("solid x", "not a PLY file"),
            ("ply\nformat ascii 1.0\nelement vertex 1\n", "no `end_header`"),
            ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n", "no `x`, `y` and `z`"),
            (
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n",
                "vertex index 9 is out of range",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n",
                "ends inside its data",
            ),
            (
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1e300 0 0\n",
                "beyond the renderable range",
            ),
        ];
        for (text, message) in cases {
            let e = parse(text.as_bytes()).expect_err(text);
            assert!(e.contains(message), "{text}: {e}");
        }
    }
}
