//! The mesh file formats `scnc export` writes. Each writer takes the whole [`Export`]
//! and writes it to one stream (OBJ's materials go to a second, the MTL file); the
//! command line writes the streams atomically. Numbers are written in Rust's shortest
//! round-trip form, so a file is the same on every run and thread count.

use std::io::{self, Write};

use super::{Export, Part};
use crate::geom::axes;

/// The unit a 3MF file declares unless told: a scene unit is a centimetre for printing.
pub const DEFAULT_3MF_UNIT: &str = "centimeter";

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// STL, binary (80-byte header, 50 bytes per triangle).
    Stl,
    /// STL, ASCII.
    StlAscii,
    /// Wavefront OBJ, with an MTL file of the materials' colours.
    Obj,
    /// PLY, binary little-endian, with colours per vertex.
    Ply,
    /// 3MF: a ZIP package with the model's XML, one object per scene object.
    ThreeMf,
    /// Binary glTF 2.0 (`.glb`): one node per object, a PBR material per colour.
    Glb,
}

impl Format {
    /// The format an output file name asks for (by its extension), if any.
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "stl" => Some(Format::Stl),
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "3mf" => Some(Format::ThreeMf),
            "glb" => Some(Format::Glb),
            _ => None,
        }
    }

    /// Whether the file is meant for printing (then Z is up by default).
    pub fn for_printing(self) -> bool {
        matches!(self, Format::Stl | Format::StlAscii | Format::ThreeMf)
    }

    /// The up axis a file of this format gets unless told: z for printing (slicers,
    /// CAD), y for viewers (OBJ, PLY, glTF).
    pub fn default_up(self) -> super::Up {
        if self.for_printing() {
            super::Up::Z
        } else {
            super::Up::Y
        }
    }

    /// File units per scene unit unless told: a scene unit is a centimetre for
    /// printing, so STL (millimetres to every slicer) is scaled by
    /// [`axes::STL_PER_UNIT`] and 3MF declares [`DEFAULT_3MF_UNIT`]; OBJ, PLY and glb
    /// (metres to glTF readers) get the scene's numbers as they are.
    pub fn default_scale(self) -> f64 {
        match self {
            Format::Stl | Format::StlAscii => axes::STL_PER_UNIT,
            Format::Obj | Format::Ply | Format::ThreeMf | Format::Glb => 1.0,
        }
    }

    /// The one up axis a format allows, where its specification fixes it (glTF: +y).
    pub fn fixed_up(self) -> Option<super::Up> {
        match self {
            Format::Glb => Some(super::Up::Y),
            Format::Stl | Format::StlAscii | Format::Obj | Format::Ply | Format::ThreeMf => None,
        }
    }

    /// About the most memory writing `export` takes beyond the export itself (what the
    /// writer builds: glb's binary buffer, PLY's and glb's per-material vertex lists, OBJ's
    /// and glb's vertex normals), to ask of the system before the output is begun.
    pub fn working_bytes(self, export: &Export) -> u64 {
        let (mut all, mut largest) = (0u64, 0u64);
        for p in &export.parts {
            let (v, t) = (p.mesh.positions.len() as u64, p.mesh.triangles.len() as u64);
            // Per-material lists: an index and a hash-map entry per vertex, a triangle.
            let groups = 40 * v + 12 * t;
            let normals = if p.smooth { 24 * v } else { 0 };
            // glb's buffer: positions, normals and indices, each also built apart first.
            let buffer = 2 * (12 * v + if p.smooth { 12 * v } else { 0 } + 12 * t);
            let (kept, transient) = match self {
                Format::Stl | Format::StlAscii | Format::ThreeMf => (0, 0),
                Format::Obj => (0, normals),
                Format::Ply => (groups, 0),
                Format::Glb => (buffer / 2, groups + normals + buffer / 2),
            };
            all += kept;
            largest = largest.max(transient);
        }
        all + largest + (1 << 20)
    }

    /// Writes `export` in this format. OBJ's `mtl` names the MTL file its `mtllib` line
    /// points to (written by [`mtl`]).
    /// First it asks the system for the writer's [`Format::working_bytes`]: refused, it
    /// is an error before a byte is written, not an allocation abort halfway.
    pub fn write(self, export: &Export, units: &str, mtl: &str, w: &mut dyn Write) -> io::Result<()> {
        let working = self.working_bytes(export);
        if !crate::mesh::system_gives(working) {
            return Err(io::Error::new(
                io::ErrorKind::OutOfMemory,
                format!(
                    "the system would not give the {} writing it needs beside the meshes (see `ulimit -v`)",
                    crate::diag::bytes(working)
                ),
            ));
        }
        match self {
            Format::Stl => stl_binary(export, w),
            Format::StlAscii => stl_ascii(export, w),
            Format::Obj => obj(export, mtl, w),
            Format::Ply => ply(export, w),
            Format::ThreeMf => three_mf(export, units, w),
            Format::Glb => glb(export, w),
        }
    }
}

fn f32s(v: glam::DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
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

fn stl_binary(export: &Export, mut w: &mut dyn Write) -> io::Result<()> {
    stl_io::write_stl(&mut w, facets(export))
}

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

/// The name of material `m` in OBJ/MTL, 3MF and glTF.
fn material_name(export: &Export, m: u32) -> &str {
    &export.material_names[m as usize]
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

fn ply(export: &Export, w: &mut dyn Write) -> io::Result<()> {
    let groups: Vec<(&Part, Vec<super::Group>)> = export.parts.iter().map(|p| (p, p.groups())).collect();
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
             <Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>\n",
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
    let mut model = io::BufWriter::with_capacity(1 << 16, &mut zip);
    xml_model(export, units, &mut model)?;
    model.flush()?;
    drop(model);
    zip.finish().map_err(io::Error::other)?;
    Ok(())
}

/// The 3MF model: one `basematerials` group holding every colour used (core
/// specification, section 5.1), one mesh object per part whose triangles name their
/// material, and a build item per object.
fn xml_model(export: &Export, units: &str, out: &mut dyn Write) -> io::Result<()> {
    let used = used(export);
    write!(
        out,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"{units}\" xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n\
         <metadata name=\"Application\">scnc</metadata>\n<resources>\n<basematerials id=\"1\">\n"
    )?;
    for &m in &used {
        writeln!(
            out,
            "<base name=\"{}\" displaycolor=\"{}\"/>",
            material_name(export, m),
            export.colours[m as usize].hex()
        )?;
    }
    out.write_all(b"</basematerials>\n")?;
    for (k, p) in export.parts.iter().enumerate() {
        let first = p.materials.first().map_or(0, |&m| slot(&used, m));
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
        for (t, [a, b, c]) in p.mesh.triangles.iter().enumerate() {
            writeln!(
                out,
                "<triangle v1=\"{a}\" v2=\"{b}\" v3=\"{c}\" pid=\"1\" p1=\"{}\"/>",
                slot(&used, p.materials[t])
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

/// Binary glTF: the JSON document, then one binary buffer holding, per part and
/// material, positions (with their bounds, which glTF requires), normals for smooth
/// parts, and `u32` indices.
fn glb(export: &Export, w: &mut dyn Write) -> io::Result<()> {
    use serde_json::json;
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let used = used(export);
    // Appends a buffer view of `bytes` (aligned to 4) and an accessor over it.
    let mut push = |bin: &mut Vec<u8>, bytes: Vec<u8>, accessor: serde_json::Value, target: u32| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(), "target": target }));
        bin.extend_from_slice(&bytes);
        let mut a = accessor;
        a["bufferView"] = json!(views.len() - 1);
        accessors.push(a);
        accessors.len() - 1
    };
    for p in &export.parts {
        let normals = p.smooth.then(|| p.vertex_normals());
        let mut primitives = Vec::new();
        for g in p.groups() {
            let points: Vec<[f32; 3]> = g.vertices.iter().map(|&v| f32s(p.mesh.positions[v as usize])).collect();
            let (min, max) = points.iter().fold(([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]), |(lo, hi), q| {
                (std::array::from_fn(|k| lo[k].min(q[k])), std::array::from_fn(|k| hi[k].max(q[k])))
            });
            let bytes = points.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
            let position = push(
                &mut bin,
                bytes,
                json!({ "componentType": 5126, "count": points.len(), "type": "VEC3", "min": min, "max": max }),
                34962,
            );
            let mut attributes = json!({ "POSITION": position });
            if let Some(n) = &normals {
                let bytes =
                    g.vertices.iter().flat_map(|&v| f32s(n[v as usize])).flat_map(|c| c.to_le_bytes()).collect();
                let normal = push(
                    &mut bin,
                    bytes,
                    json!({ "componentType": 5126, "count": g.vertices.len(), "type": "VEC3" }),
                    34962,
                );
                attributes["NORMAL"] = json!(normal);
            }
            let bytes = g.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
            let indices = push(
                &mut bin,
                bytes,
                json!({ "componentType": 5125, "count": g.triangles.len() * 3, "type": "SCALAR" }),
                34963,
            );
            primitives.push(
                json!({ "attributes": attributes, "indices": indices, "material": slot(&used, g.material), "mode": 4 }),
            );
        }
        // glTF wants at least one primitive per mesh: a part with no triangles left is
        // a node without a mesh.
        if primitives.is_empty() {
            nodes.push(json!({ "name": p.name }));
        } else {
            meshes.push(json!({ "name": p.name, "primitives": primitives }));
            nodes.push(json!({ "name": p.name, "mesh": meshes.len() - 1 }));
        }
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let materials: Vec<serde_json::Value> = used
        .iter()
        .map(|&m| {
            let [r, g, b] = export.colours[m as usize].linear();
            json!({
                "name": material_name(export, m),
                "pbrMetallicRoughness": { "baseColorFactor": [r, g, b, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8 },
            })
        })
        .collect();
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": "scnc export" },
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
    });
    if !bin.is_empty() {
        doc["buffers"] = json!([{ "byteLength": bin.len() }]);
    }
    // glTF's arrays, where present, hold at least one item.
    if let Some(fields) = doc.as_object_mut() {
        fields.retain(|_, v| v.as_array().is_none_or(|a| !a.is_empty()));
    }
    let mut text = serde_json::to_vec(&doc).map_err(io::Error::other)?;
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = u32::try_from(total).map_err(|_| io::Error::other("a .glb file holds at most 4 GiB"))?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(text.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&text)?;
    if !bin.is_empty() {
        w.write_all(&(bin.len() as u32).to_le_bytes())?;
        w.write_all(b"BIN\0")?;
        w.write_all(&bin)?;
    }
    Ok(())
}
