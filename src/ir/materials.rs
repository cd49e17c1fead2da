//! What materials an object can show: every `with` in its tree, and the default grey
//! where some part has none (what the effect set and the checker's lints read).

use super::{Body, Material, MeshSource, Shape, ShapeKind};

fn materials_of_shape(shape: &Shape, out: &mut Vec<Material>) {
    if let ShapeKind::Paint { material, .. } = &shape.kind {
        out.push((**material).clone());
    }
    shape.children().iter().for_each(|c| materials_of_shape(c, out));
}

/// Every material an object can show, plus the default grey when some part has none.
pub fn materials_of(geometry: &Body) -> Vec<Material> {
    let mut out = Vec::new();
    match geometry {
        Body::Shape(s) => {
            materials_of_shape(s, &mut out);
            if !painted_everywhere(s) {
                out.push(Material::default_grey());
            }
        }
        Body::Mesh(m) => {
            out.push(m.material.as_deref().cloned().unwrap_or_else(Material::default_grey));
            if let MeshSource::Isosurface { shape, .. } = &m.source {
                materials_of_shape(shape, &mut out);
            }
        }
    }
    out
}

/// Whether every leaf of the tree has a material above it.
fn painted_everywhere(shape: &Shape) -> bool {
    match &shape.kind {
        ShapeKind::Paint { .. } => true,
        // A field's surface is its own: the shapes its body measures paint nothing.
        ShapeKind::Primitive(_) | ShapeKind::Field { .. } => false,
        ShapeKind::Warp { .. }
        | ShapeKind::Displace { .. }
        | ShapeKind::Csg { .. }
        | ShapeKind::Round { .. }
        | ShapeKind::Shell { .. }
        | ShapeKind::Repeat { .. }
        | ShapeKind::Transform { .. } => shape.children().iter().all(|c| painted_everywhere(c)),
    }
}
