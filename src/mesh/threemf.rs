//! A 3MF reader through the `threemf` crate (the zip package and its XML, which export
//! writes with `zip`): the triangles of every build item, through its transform and its
//! components' transforms, in one mesh. 3MF is z up and right-handed ([`axes::Up::Z`]),
//! as export writes it for printing, and declares its unit, which is read back into
//! scene units (a scene unit is a centimetre, as export declares it).

use glam::{DAffine3, DMat3, DVec3};

use super::obj::MAX_ELEMENTS;
use crate::geom::{axes, TriMesh};

/// Components deeper than this are refused (a cycle of components would never end).
const MAX_DEPTH: usize = 16;

/// Largest uncompressed model part read: its XML is deserialised whole, at up to about
/// three times its size (an 88-byte triangle from a 33-byte element at least).
const MAX_MODEL_BYTES: u64 = 1 << 30;

/// Parses a `.3mf` file's bytes into scnc's space; an error says what is wrong.
pub fn parse(bytes: &[u8]) -> Result<TriMesh, String> {
    let mut zip =
        zip::ZipArchive::new(std::io::Cursor::new(bytes)).map_err(|e| format!("not a readable 3MF package ({e})"))?;
    for i in 0..zip.len() {
        let entry = zip.by_index(i).map_err(|e| format!("not a readable 3MF package ({e})"))?;
        let name = entry.name().map(|n| n.into_owned()).unwrap_or_default();
        if name.ends_with(".model") && entry.size() > MAX_MODEL_BYTES {
            return Err(format!(
                "its model `{name}` is {} bytes uncompressed, more than the {MAX_MODEL_BYTES} scnc reads",
                entry.size()
            ));
        }
    }
    let models = threemf::read(std::io::Cursor::new(bytes)).map_err(|e| format!("not a readable 3MF package ({e})"))?;
    let mut mesh = TriMesh::default();
    for model in &models {
        let scale = centimetres(&model.unit);
        for item in &model.build.item {
            let place = DAffine3::from_scale(DVec3::splat(scale)) * matrix(item.transform);
            add(&mut mesh, model, item.objectid, place, 0)?;
        }
    }
    if mesh.triangles.is_empty() {
        return Err("its build has no triangles".into());
    }
    Ok(mesh)
}

/// Scene units (centimetres) per unit of the model.
fn centimetres(unit: &threemf::model::Unit) -> f64 {
    use threemf::model::Unit;
    match unit {
        Unit::Micron => 1e-4,
        Unit::Millimeter => 0.1,
        Unit::Centimeter => 1.0,
        Unit::Inch => 2.54,
        Unit::Foot => 30.48,
        Unit::Meter => 100.0,
    }
}

/// A 3MF transform, twelve numbers of a 4×3 matrix applied to row vectors (`x' = x·m00 +
/// y·m10 + z·m20 + m30`), as an affine map; none is the identity.
fn matrix(t: Option<[f64; 12]>) -> DAffine3 {
    let Some(m) = t else { return DAffine3::IDENTITY };
    DAffine3::from_mat3_translation(
        DMat3::from_cols(DVec3::new(m[0], m[1], m[2]), DVec3::new(m[3], m[4], m[5]), DVec3::new(m[6], m[7], m[8])),
        DVec3::new(m[9], m[10], m[11]),
    )
}

/// Appends object `id` of `model` (its mesh, or its components), placed by `place`.
fn add(
    mesh: &mut TriMesh,
    model: &threemf::model::Model,
    id: usize,
    place: DAffine3,
    depth: usize,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!("its components nest more than {MAX_DEPTH} deep (a cycle?)"));
    }
    let object = model
        .resources
        .object
        .iter()
        .find(|o| o.id == id)
        .ok_or_else(|| format!("the build names object {id}, which the model does not define"))?;
    if let Some(components) = &object.components {
        for c in &components.component {
            add(mesh, model, c.objectid, place * matrix(c.transform), depth + 1)?;
        }
    }
    let Some(m) = &object.mesh else { return Ok(()) };
    let (vertices, triangles) = (&m.vertices.vertex, &m.triangles.triangle);
    if mesh.positions.len() + vertices.len() > MAX_ELEMENTS || mesh.triangles.len() + triangles.len() > MAX_ELEMENTS {
        return Err(format!("more than {MAX_ELEMENTS} vertices or triangles"));
    }
    let base = mesh.positions.len();
    for v in vertices {
        let p = place.transform_point3(DVec3::new(v.x, v.y, v.z));
        if let Some(why) = super::obj::unrenderable(p) {
            return Err(format!("a vertex of object {id} {why}"));
        }
        mesh.positions.push(axes::from_file(p, axes::Up::Z));
    }
    // A transform that mirrors turns its triangles inside out.
    let mirrored = place.matrix3.determinant() < 0.0;
    for t in triangles {
        let v = [t.v1, t.v2, t.v3];
        if let Some(&i) = v.iter().find(|&&i| i >= vertices.len()) {
            return Err(format!("a triangle of object {id} names vertex {i} of {}", vertices.len()));
        }
        mesh.triangles.push(axes::wound(v.map(|i| (base + i) as u32), mirrored));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use threemf::model::{Build, Component, Components, Item, Mesh, Model, Object, Triangle, Triangles, Unit};
    use threemf::model::{Vertex, Vertices};

    /// A triangle (counter-clockwise about +z in the file, so facing up) in object 1, and
    /// object 2 holding object 1 through `component`; the build places `item` of `built`
    /// (7: an object not defined; 3: object 2, holding itself).
    fn package(unit: Unit, component: Option<[f64; 12]>, built: usize, item: Option<[f64; 12]>) -> Vec<u8> {
        let vertex = |x, y, z| Vertex { x, y, z };
        let mesh = Mesh {
            vertices: Vertices { vertex: vec![vertex(0.0, 0.0, 5.0), vertex(10.0, 0.0, 5.0), vertex(0.0, 10.0, 5.0)] },
            triangles: Triangles { triangle: vec![Triangle { v1: 0, v2: 1, v3: 2 }] },
        };
        let model = Model {
            resources: threemf::model::Resources {
                object: vec![
                    Object { id: 1, mesh: Some(mesh), ..Object::default() },
                    Object {
                        id: 2,
                        components: Some(Components {
                            component: vec![Component {
                                objectid: if built == 3 { 2 } else { 1 },
                                transform: component,
                            }],
                        }),
                        ..Object::default()
                    },
                ],
                basematerials: None,
            },
            // 3 stands for object 2 holding itself.
            build: Build {
                item: vec![Item { objectid: if built == 3 { 2 } else { built }, transform: item, partnumber: None }],
            },
            unit,
            ..Model::default()
        };
        let mut bytes = std::io::Cursor::new(Vec::new());
        threemf::write(&mut bytes, model).expect("writing a 3MF");
        bytes.into_inner()
    }

    /// The triangle's normal in scnc's space, and its first corner.
    fn read(bytes: &[u8]) -> (DVec3, DVec3) {
        let m = parse(bytes).expect("readable");
        let [a, b, c] = m.triangles[0].map(|i| m.positions[i as usize]);
        ((b - a).cross(c - a).normalize(), a)
    }

    #[test]
    fn reads_units_transforms_and_components_into_scncs_space() {
        // Millimetres to centimetres; the file's +z (up) is scnc's +y, and the triangle
        // still faces up.
        let (n, a) = read(&package(Unit::Millimeter, None, 1, None));
        assert!((n - DVec3::Y).length() < 1e-12 && (a - DVec3::new(0.0, 0.5, 0.0)).length() < 1e-12, "{n} {a}");
        // Through a component moved up by 10 mm and an item in metres moved along +x.
        let up = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 10.0];
        let along = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0];
        let (n, a) = read(&package(Unit::Meter, Some(up), 2, Some(along)));
        assert!((n - DVec3::Y).length() < 1e-12, "{n}");
        assert!((a - DVec3::new(200.0, 1500.0, 0.0)).length() < 1e-9, "{a}");
        // A mirroring component turns the triangle over, and it still faces out of the solid
        // it was (down, after z → −z).
        let mirror = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0];
        let (n, _) = read(&package(Unit::Centimeter, Some(mirror), 2, None));
        assert!((n + DVec3::Y).length() < 1e-12, "{n}");
    }

    #[test]
    fn refuses_broken_packages() {
        assert!(parse(b"not a zip").unwrap_err().contains("not a readable 3MF"));
        assert!(parse(&package(Unit::Centimeter, None, 7, None)).unwrap_err().contains("does not define"));
        // Object 2 holding itself.
        assert!(parse(&package(Unit::Centimeter, None, 3, None)).unwrap_err().contains("nest more than"));
    }
}
