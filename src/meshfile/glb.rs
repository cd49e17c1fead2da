//! A binary glTF (`.glb`) reader through the `gltf` crate (the glTF project's Rust
//! reader, which validates the document): the triangles of every mesh the default scene
//! places, through each node's transform, in one mesh. glTF is y up and right-handed
//! ([`axes::Up::Y`]), as export writes it; its buffers must be inside the file.

use glam::{DMat4, DVec3};

use super::MAX_ELEMENTS;
use crate::geom::{axes, TriMesh};
use std::io::{self, Write};

use super::{f32s, material_name, slot, used, Expansion, Export, MeshFormat, Part, Reader, Up, WriteOptions};

/// Parses a `.glb` file's bytes into scnc's space, within `allowed` bytes of mesh; an
/// error says what is wrong.
pub fn parse(bytes: &[u8], allowed: u64) -> Result<TriMesh, String> {
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| format!("not a readable glb file ({e})"))?;
    let blob = gltf.blob.as_deref();
    let scene = gltf.default_scene().or_else(|| gltf.scenes().next()).ok_or("the file has no scene")?;
    // The whole expansion first, node by node, so nothing is allocated for a file
    // that places more than it may.
    let mut memo = vec![None; gltf.nodes().count()];
    let mut total = Expansion::default();
    for node in scene.nodes() {
        total = total.plus(expansion(&node, &mut memo, 0)?, 1);
    }
    let mut mesh = total.reserve(allowed)?;
    // Nodes with their parents' transforms, depth first, a shared node once per use;
    // a node that places no triangle is not walked into.
    let mut stack: Vec<(gltf::Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        if memo[node.index()].is_some_and(|e: Expansion| e.triangles == 0) {
            continue;
        }
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        if let Some(m) = node.mesh() {
            for p in m.primitives() {
                add(&mut mesh, &p, world, blob)?;
            }
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    if mesh.triangles.is_empty() {
        return Err("the file's scene has no triangles".into());
    }
    Ok(mesh)
}

/// What `node` places with the nodes under it ([`Expansion`]), each node's count kept
/// in `memo` by its index; refused past 64 levels (a cycle never ends) or past
/// [`MAX_ELEMENTS`], naming the node.
fn expansion(node: &gltf::Node, memo: &mut [Option<Expansion>], depth: usize) -> Result<Expansion, String> {
    if depth > 64 {
        return Err("its nodes nest more than 64 deep".into());
    }
    if let Some(e) = memo[node.index()] {
        return Ok(e);
    }
    let mut e = Expansion::default();
    for p in node.mesh().iter().flat_map(|m| m.primitives()) {
        e = e.plus(primitive_counts(&p), 1);
    }
    for child in node.children() {
        e = e.plus(expansion(&child, memo, depth + 1)?, 1);
    }
    if e.triangles > 0 {
        e.uses = e.uses.saturating_add(1);
    }
    if e.too_many() {
        let name = node.name().map_or(String::new(), |n| format!(" `{n}`"));
        return Err(format!(
            "node {}{name} places more than {MAX_ELEMENTS} vertices or triangles through the nodes under it, \
             counting each use of a shared node ({} triangles)",
            node.index(),
            e.triangles
        ));
    }
    memo[node.index()] = Some(e);
    Ok(e)
}

/// The vertices and triangles one primitive adds ([`add`]), from its accessors' counts.
fn primitive_counts(p: &gltf::Primitive) -> Expansion {
    use gltf::mesh::Mode;
    let vertices = p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count() as u64);
    let corners = p.indices().map_or(vertices, |a| a.count() as u64);
    let triangles = match p.mode() {
        Mode::Triangles => corners / 3,
        Mode::TriangleStrip | Mode::TriangleFan => corners.saturating_sub(2),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => 0,
    };
    Expansion { vertices, triangles, uses: 0 }
}

/// Appends one primitive's triangles, placed by `world`.
fn add(mesh: &mut TriMesh, p: &gltf::Primitive, world: DMat4, blob: Option<&[u8]>) -> Result<(), String> {
    use gltf::mesh::Mode;
    let external = p
        .attributes()
        .any(|(_, a)| a.view().is_some_and(|v| matches!(v.buffer().source(), gltf::buffer::Source::Uri(_))));
    let reader = p.reader(|b| match b.source() {
        gltf::buffer::Source::Bin => blob,
        gltf::buffer::Source::Uri(_) => None,
    });
    let Some(positions) = reader.read_positions() else {
        return Err(if external {
            "its buffers are in other files: scnc reads a .glb whose data is inside it".into()
        } else {
            "a primitive has no positions".into()
        });
    };
    let base = mesh.positions.len() as u32;
    for q in positions {
        let q = world.transform_point3(DVec3::from(q.map(f64::from)));
        if let Some(why) = super::unrenderable(q) {
            return Err(format!("a vertex {why}"));
        }
        mesh.positions.push(axes::from_file(q, axes::Up::Y));
    }
    let count = mesh.positions.len() as u32 - base;
    if mesh.positions.len() > MAX_ELEMENTS {
        return Err(format!("more than {MAX_ELEMENTS} vertices"));
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..count).collect(),
    };
    if let Some(&i) = indices.iter().find(|&&i| i >= count) {
        return Err(format!("index {i} is out of range: the primitive has {count} vertices"));
    }
    let triangles: Vec<[u32; 3]> = match p.mode() {
        Mode::Triangles => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        // Every other strip triangle is wound the other way (glTF 2.0, 3.7.2.1).
        Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                let (a, b, c) = (indices[k - 2], indices[k - 1], indices[k]);
                if k % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len()).map(|k| [indices[0], indices[k - 1], indices[k]]).collect(),
        // Points and lines have no surface.
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => Vec::new(),
    };
    // A transform that mirrors turns the file's winding inside out.
    let mirrored = world.determinant() < 0.0;
    for t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        mesh.triangles.push(axes::wound(t.map(|i| base + i), mirrored));
    }
    if mesh.triangles.len() > MAX_ELEMENTS {
        return Err(format!("more than {MAX_ELEMENTS} triangles"));
    }
    Ok(())
}

/// The binary glTF 2.0 format.
pub struct Glb;

impl MeshFormat for Glb {
    const NAME: &'static str = "glb";
    const ABOUT: &'static str = "binary glTF 2.0";
    const EXTENSIONS: &'static [&'static str] = &["glb"];
    const MIME: &'static str = "model/gltf-binary";
    const FOR_PRINTING: bool = false;
    // Metres to glTF readers: the scene's numbers as they are.
    const DEFAULT_SCALE: f64 = 1.0;
    // glTF's specification: +y is up.
    const FIXED_UP: Option<Up> = Some(Up::Y);
    const ONE_FILE: bool = true;
    const READS: &'static str = "binary glTF (`.glb`)";
    const READER: Reader = Reader::Whole(parse);

    fn working_bytes(part: &Part) -> (u64, u64) {
        // The binary buffer: positions, normals and indices, each also built apart first.
        let (v, t) = (part.mesh.positions.len() as u64, part.mesh.triangles.len() as u64);
        let buffer = 2 * (12 * v + if part.smooth { 12 * v } else { 0 } + 12 * t);
        (buffer / 2, super::groups_bytes(part) + super::normals_bytes(part) + buffer / 2)
    }

    fn write(export: &Export, _: &WriteOptions, w: &mut dyn Write) -> io::Result<()> {
        glb(export, w)
    }
}

/// Binary glTF: the JSON document, then one binary buffer holding, per part and
/// material, positions (with their bounds, which glTF requires), normals for smooth
/// parts, and `u32` indices.
///
/// Long because the document is written in the order glTF lays it out (buffer views,
/// accessors, meshes, nodes, the buffer), which reads against the specification top to
/// bottom.
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A .glb of one triangle (no indices), placed by `nodes` (the scene is node 0).
    fn glb(nodes: serde_json::Value, mode: u32) -> Vec<u8> {
        let bin: Vec<u8> = [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let doc = serde_json::json!({
            "asset": { "version": "2.0" },
            "scene": 0,
            "scenes": [{ "nodes": [0] }],
            "nodes": nodes,
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "mode": mode }] }],
            "accessors": [{ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                            "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] }],
            "bufferViews": [{ "buffer": 0, "byteLength": 36 }],
            "buffers": [{ "byteLength": 36 }],
        });
        let mut json = serde_json::to_vec(&doc).expect("json");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }

    fn parse_all(bytes: &[u8]) -> Result<TriMesh, String> {
        parse(bytes, u64::MAX)
    }

    /// Nodes `0..levels`, each listing the next `fan` times; the last places the mesh.
    fn fanned(levels: usize, fan: usize) -> serde_json::Value {
        let mut nodes: Vec<serde_json::Value> =
            (0..levels - 1).map(|i| serde_json::json!({ "children": vec![i + 1; fan] })).collect();
        nodes.push(serde_json::json!({ "mesh": 0 }));
        serde_json::Value::Array(nodes)
    }

    /// A node listed many times by each of many nested nodes is counted once per node,
    /// not walked path by path: 41 levels of 16 (16⁴⁰ uses) are refused at once,
    /// naming the deepest node past the limit (node 34: 16⁶ uses of 3 vertices); 10 levels of 2 place 512 triangles; a budget of fewer bytes
    /// than the expansion takes is refused before anything is allocated.
    #[test]
    fn shared_nodes_are_counted_once_and_refused_past_the_budgets() {
        let e = parse_all(&glb(fanned(41, 16), 4)).expect_err("16^40 uses");
        assert!(e.starts_with("node 34 ") && e.contains("each use of a shared node"), "{e}");
        let m = parse_all(&glb(fanned(10, 2), 4)).expect("512 uses");
        assert_eq!((m.triangles.len(), m.positions.len()), (512, 1536));
        // 512 triangles and 1,536 vertices take 43,008 bytes.
        let e = parse(&glb(fanned(10, 2), 4), 40_000).expect_err("over the memory limit");
        assert!(e.contains("memory limit"), "{e}");
        assert!(parse(&glb(fanned(10, 2), 4), 43_008).is_ok());
        // Nodes that place nothing are neither counted nor walked into.
        let empty = serde_json::json!([{ "children": vec![1; 16] }, { "children": vec![2; 16] }, {}]);
        assert!(parse_all(&glb(empty, 4)).expect_err("no triangles").contains("no triangles"));
    }

    #[test]
    fn nodes_place_their_meshes_and_a_mirror_keeps_the_winding_outward() {
        let plain = parse_all(&glb(serde_json::json!([{ "mesh": 0 }]), 4)).expect("reads");
        assert_eq!(plain.positions[1], DVec3::new(1.0, 0.0, 0.0));
        // A parent moves, a child mirrors in x: (1, 0, 0) lands at (−1 + 0, 0, 2) in the
        // file, (−1, 0, −2) in scnc's space, and the triangle is wound the other way.
        let nodes = serde_json::json!([{ "translation": [0.0, 0.0, 2.0], "children": [1] }, { "scale": [-1.0, 1.0, 1.0], "mesh": 0 }]);
        let placed = parse_all(&glb(nodes, 4)).expect("reads");
        assert_eq!(placed.positions[1], DVec3::new(-1.0, 0.0, -2.0));
        let [a, b, c] = plain.triangles[0];
        assert_eq!(placed.triangles[0], [a, c, b]);
    }

    #[test]
    fn strips_and_fans_are_triangles_and_points_have_none() {
        for mode in [5, 6] {
            assert_eq!(parse_all(&glb(serde_json::json!([{ "mesh": 0 }]), mode)).expect("reads").triangles.len(), 1);
        }
        let e = parse_all(&glb(serde_json::json!([{ "mesh": 0 }]), 0)).expect_err("points only");
        assert!(e.contains("no triangles"), "{e}");
        let e = parse_all(b"glTF\x02\0\0\0").expect_err("truncated");
        assert!(e.contains("not a readable glb"), "{e}");
    }
}
