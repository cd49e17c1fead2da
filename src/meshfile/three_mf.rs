//! A 3MF reader through the `threemf` crate (the zip package and its XML, which export
//! writes with `zip`): the triangles of every build item, through its transform and its
//! components' transforms, in one mesh. 3MF is z up and right-handed ([`axes::Up::Z`]),
//! as export writes it for printing, and declares its unit, which is read back into
//! scene units (a scene unit is a centimetre, as export declares it).

use std::collections::HashMap;

use glam::{DAffine3, DMat3, DVec3};

use super::MAX_ELEMENTS;
use crate::geom::{axes, TriMesh};
use std::io::{self, Write};

use super::{f32s, material_name, slot, used, Expansion, Export, MeshFormat, Part, Reader, Up, WriteOptions};

/// Components deeper than this are refused (a cycle of components would never end).
const MAX_DEPTH: usize = 16;

/// Largest uncompressed model part read: its XML is deserialised whole, at up to about
/// three times its size (an 88-byte triangle from a 33-byte element at least).
const MAX_MODEL_BYTES: u64 = 1 << 30;

/// Parses a `.3mf` file's bytes into scnc's space, within `allowed` bytes of mesh; an
/// error says what is wrong.
pub fn parse(bytes: &[u8], allowed: u64) -> Result<TriMesh, String> {
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
    // The whole expansion first, object by object, so nothing is allocated for a
    // package that places more than it may.
    let mut memos: Vec<HashMap<usize, Expansion>> = Vec::with_capacity(models.len());
    let mut total = Expansion::default();
    for model in &models {
        let mut memo = HashMap::new();
        for item in &model.build.item {
            total = total.plus(expansion(model, item.objectid, &mut memo, 0)?, 1);
            if total.too_many() {
                break;
            }
        }
        memos.push(memo);
    }
    let mut mesh = total.reserve(allowed)?;
    for (model, memo) in models.iter().zip(&memos) {
        let scale = centimetres(&model.unit);
        for item in &model.build.item {
            let place = DAffine3::from_scale(DVec3::splat(scale)) * matrix(item.transform);
            add(&mut mesh, model, memo, item.objectid, place)?;
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

/// Object `id` of `model`, or why the build cannot name it.
fn object(model: &threemf::model::Model, id: usize) -> Result<&threemf::model::Object, String> {
    model
        .resources
        .object
        .iter()
        .find(|o| o.id == id)
        .ok_or_else(|| format!("the build names object {id}, which the model does not define"))
}

/// What object `id` places with its components ([`Expansion`]), each object's count
/// kept in `memo`; refused past [`MAX_DEPTH`] levels (a cycle never ends) or past
/// [`MAX_ELEMENTS`], naming the object.
fn expansion(
    model: &threemf::model::Model,
    id: usize,
    memo: &mut HashMap<usize, Expansion>,
    depth: usize,
) -> Result<Expansion, String> {
    if depth > MAX_DEPTH {
        return Err(format!("its components nest more than {MAX_DEPTH} deep (a cycle?)"));
    }
    if let Some(&e) = memo.get(&id) {
        return Ok(e);
    }
    let object = object(model, id)?;
    let mut e = Expansion::default();
    if let Some(m) = &object.mesh {
        let (vertices, triangles) = (m.vertices.vertex.len() as u64, m.triangles.triangle.len() as u64);
        e = Expansion { vertices, triangles, uses: u64::from(triangles > 0) };
    }
    for c in object.components.iter().flat_map(|c| &c.component) {
        e = e.plus(expansion(model, c.objectid, memo, depth + 1)?, 1);
        if e.too_many() {
            return Err(format!(
                "object {id} places more than {MAX_ELEMENTS} vertices or triangles through its components, \
                 counting each use of a shared object"
            ));
        }
    }
    memo.insert(id, e);
    Ok(e)
}

/// Appends object `id` of `model` (its mesh, or its components), placed by `place`;
/// an object that places no triangle ([`expansion`]'s `memo`) is not walked into.
fn add(
    mesh: &mut TriMesh,
    model: &threemf::model::Model,
    memo: &HashMap<usize, Expansion>,
    id: usize,
    place: DAffine3,
) -> Result<(), String> {
    if memo.get(&id).is_some_and(|e| e.triangles == 0) {
        return Ok(());
    }
    let object = object(model, id)?;
    if let Some(components) = &object.components {
        for c in &components.component {
            add(mesh, model, memo, c.objectid, place * matrix(c.transform))?;
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
        if let Some(why) = super::unrenderable(p) {
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

/// The unit a 3MF file declares unless told: a scene unit is a centimetre for printing.
pub const DEFAULT_3MF_UNIT: &str = "centimeter";

/// The 3MF format.
pub struct ThreeMf;

impl MeshFormat for ThreeMf {
    const NAME: &'static str = "3mf";
    const ABOUT: &'static str = "3MF, one object per scene object, with colours";
    const EXTENSIONS: &'static [&'static str] = &["3mf"];
    const MIME: &'static str = "model/3mf";
    const FOR_PRINTING: bool = true;
    // The file declares its unit ([`DEFAULT_3MF_UNIT`] unless told), so numbers stay.
    const DEFAULT_SCALE: f64 = 1.0;
    const FIXED_UP: Option<Up> = None;
    const ONE_FILE: bool = true;
    const READS: &'static str = "3MF (`.3mf`, z up, in its declared unit)";
    const READER: Reader = Reader::Whole(parse);

    fn working_bytes(_: &Part) -> (u64, u64) {
        // The package is streamed as it is made.
        (0, 0)
    }

    fn write(export: &Export, options: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
        three_mf(export, options.units, w)
    }
}

/// 3MF, streamed: the package's ZIP entries are written as they are made (sizes in data
/// descriptors), the model's XML through a buffer into the deflater, so the file never
/// exists whole in memory (a 21.8 M-triangle package once needed a 3.8 GB buffer).
fn three_mf(export: &Export, units: &str, w: &mut dyn Write) -> io::Result<()> {
    use zip::write::SimpleFileOptions;
    let mut zip = zip::ZipWriter::new_stream(w);
    // A fixed time stamp: the package is the same on every run. Deflate's fastest level:
    // the XML's numbers compress to a third either way, and the default level takes
    // several times longer (`scnc export … -o x.3mf` against `-o x.stl`).
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .compression_level(Some(1))
        .last_modified_time(zip::DateTime::default());
    let parts: [(&str, &str); 2] = [
        (
            "[Content_Types].xml",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\
             <Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>\
             <Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/>\
             <Default Extension=\"config\" ContentType=\"text/xml\"/></Types>\n",
        ),
        (
            "_rels/.rels",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\
             <Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>\n",
        ),
    ];
    for (name, text) in parts {
        zip.start_file(name, options).map_err(io::Error::other)?;
        zip.write_all(text.as_bytes())?;
    }
    // A streamed entry declares ZIP64 before its size is known: past 2 GiB of XML at
    // the most a vertex or triangle line takes, it does.
    let vertices: usize = export.parts.iter().map(|p| p.mesh.positions.len()).sum();
    let most_xml = (vertices as u64 * 80) + (export.triangle_count() as u64 * 80);
    zip.start_file("3D/3dmodel.model", options.large_file(most_xml > 1 << 31)).map_err(io::Error::other)?;
    let used = used(export);
    let orders: Vec<Vec<u32>> = export.parts.iter().map(|p| by_material(p, &used)).collect();
    let mut model = io::BufWriter::with_capacity(1 << 16, &mut zip);
    xml_model(export, units, &used, &orders, &mut model)?;
    model.flush()?;
    drop(model);
    zip.start_file("Metadata/Slic3r_PE_model.config", options).map_err(io::Error::other)?;
    zip.write_all(slicer_config(export, &used, &orders).as_bytes())?;
    zip.finish().map_err(io::Error::other)?;
    Ok(())
}

/// A part's triangles ordered by their material's slot (stable, so each material's run
/// keeps the mesh's order): a slicer's volume is a contiguous run of an object's triangles.
fn by_material(part: &Part, used: &[u32]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..part.mesh.triangles.len() as u32).collect();
    order.sort_by_cached_key(|&t| slot(used, part.materials[t as usize]));
    order
}

/// PrusaSlicer's own description of the objects (`Metadata/Slic3r_PE_model.config`,
/// which PrusaSlicer and its descendants read): each object's name, and one *volume*
/// per material — a run of the object's triangles, named after the material, printed
/// with extruder N for the N-th colour of the file's base materials. The core
/// specification's materials colour the triangles; they do not say which filament
/// prints them, and PrusaSlicer prints a part with one extruder without this.
fn slicer_config(export: &Export, used: &[u32], orders: &[Vec<u32>]) -> String {
    use std::fmt::Write as _;
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<config>\n");
    for (k, (p, order)) in export.parts.iter().zip(orders).enumerate() {
        let _ = writeln!(out, " <object id=\"{}\" instances_count=\"1\">", k + 2);
        let _ = writeln!(out, "  <metadata type=\"object\" key=\"name\" value=\"{}\"/>", p.name);
        let mut first = 0;
        while first < order.len() {
            let m = p.materials[order[first] as usize];
            let run = order[first..].iter().take_while(|&&t| p.materials[t as usize] == m).count();
            let extruder = slot(used, m) + 1;
            let _ = writeln!(out, "  <volume firstid=\"{first}\" lastid=\"{}\">", first + run - 1);
            let _ = writeln!(out, "   <metadata type=\"volume\" key=\"name\" value=\"{}\"/>", material_name(export, m));
            let _ = writeln!(out, "   <metadata type=\"volume\" key=\"extruder\" value=\"{extruder}\"/>");
            out.push_str("  </volume>\n");
            first += run;
        }
        out.push_str(" </object>\n");
    }
    out.push_str("</config>\n");
    out
}

/// The 3MF model: one `basematerials` group holding every colour used (core
/// specification, section 5.1), one mesh object per part whose triangles name their
/// material, and a build item per object.
fn xml_model(
    export: &Export,
    units: &str,
    used: &[u32],
    orders: &[Vec<u32>],
    out: &mut dyn Write,
) -> io::Result<()> {
    write!(
        out,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"{units}\" xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n\
         <metadata name=\"Application\">scnc</metadata>\n<resources>\n<basematerials id=\"1\">\n"
    )?;
    for &m in used {
        writeln!(
            out,
            "<base name=\"{}\" displaycolor=\"{}\"/>",
            material_name(export, m),
            export.colours[m as usize].hex()
        )?;
    }
    out.write_all(b"</basematerials>\n")?;
    for (k, (p, order)) in export.parts.iter().zip(orders).enumerate() {
        let first = order.first().map_or(0, |&t| slot(used, p.materials[t as usize]));
        writeln!(
            out,
            "<object id=\"{}\" name=\"{}\" type=\"model\" pid=\"1\" pindex=\"{first}\">\n<mesh>\n<vertices>",
            k + 2,
            p.name
        )?;
        for v in &p.mesh.positions {
            let [x, y, z] = f32s(*v);
            writeln!(out, "<vertex x=\"{x}\" y=\"{y}\" z=\"{z}\"/>")?;
        }
        out.write_all(b"</vertices>\n<triangles>\n")?;
        for &t in order {
            let [a, b, c] = p.mesh.triangles[t as usize];
            writeln!(
                out,
                "<triangle v1=\"{a}\" v2=\"{b}\" v3=\"{c}\" pid=\"1\" p1=\"{}\"/>",
                slot(used, p.materials[t as usize])
            )?;
        }
        out.write_all(b"</triangles>\n</mesh>\n</object>\n")?;
    }
    out.write_all(b"</resources>\n<build>\n")?;
    for k in 0..export.parts.len() {
        writeln!(out, "<item objectid=\"{}\"/>", k + 2)?;
    }
    out.write_all(b"</build>\n</model>\n")
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
        let m = parse(bytes, u64::MAX).expect("readable");
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
        let parse = |bytes: &[u8]| parse(bytes, u64::MAX);
        assert!(parse(b"not a zip").unwrap_err().contains("not a readable 3MF"));
        assert!(parse(&package(Unit::Centimeter, None, 7, None)).unwrap_err().contains("does not define"));
        // Object 2 holding itself.
        assert!(parse(&package(Unit::Centimeter, None, 3, None)).unwrap_err().contains("nest more than"));
    }

    /// Objects `1..=levels`, each holding the next `fan` times; the last is a triangle.
    fn fanned(levels: usize, fan: usize) -> Vec<u8> {
        let vertex = |x, y, z| Vertex { x, y, z };
        let mesh = Mesh {
            vertices: Vertices { vertex: vec![vertex(0.0, 0.0, 0.0), vertex(1.0, 0.0, 0.0), vertex(0.0, 1.0, 0.0)] },
            triangles: Triangles { triangle: vec![Triangle { v1: 0, v2: 1, v3: 2 }] },
        };
        let mut object: Vec<Object> = (1..levels)
            .map(|id| Object {
                id,
                components: Some(Components {
                    component: (0..fan).map(|_| Component { objectid: id + 1, transform: None }).collect(),
                }),
                ..Object::default()
            })
            .collect();
        object.push(Object { id: levels, mesh: Some(mesh), ..Object::default() });
        let model = Model {
            resources: threemf::model::Resources { object, basematerials: None },
            build: Build { item: vec![Item { objectid: 1, transform: None, partnumber: None }] },
            unit: Unit::Millimeter,
            ..Model::default()
        };
        let mut bytes = std::io::Cursor::new(Vec::new());
        threemf::write(&mut bytes, model).expect("writing a 3MF");
        bytes.into_inner()
    }

    /// Components shared level on level are counted once per object: 8 per level over
    /// 12 levels (8¹¹ ≈ 8.6 G triangles) is refused before anything is allocated,
    /// naming the object; 4 levels of 8 place 512 triangles, and not within fewer bytes
    /// than they take.
    #[test]
    fn shared_components_are_counted_once_and_refused_past_the_budgets() {
        let e = parse(&fanned(12, 8), u64::MAX).expect_err("8^11 triangles");
        assert!(e.contains("object") && e.contains("each use of a shared object"), "{e}");
        let m = parse(&fanned(4, 8), u64::MAX).expect("512 uses");
        assert_eq!((m.triangles.len(), m.positions.len()), (512, 1536));
        assert!(parse(&fanned(4, 8), 43_007).expect_err("over the limit").contains("memory limit"));
    }
}
