//! A scene's objects as meshes in a file's frame, with their colours: what every
//! writer takes ([`super::Format::write`]); `export::collect` makes it.

use glam::DVec3;

use crate::span::Span;

/// One material's colour, as the scene gives it (0–255 per channel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Colour(pub [f64; 3]);

impl Colour {
    /// The colour in 8 bits per channel, as scnc writes it to PNG.
    pub fn rgb8(self) -> [u8; 3] {
        self.0.map(|c| c.round().clamp(0.0, 255.0) as u8)
    }

    /// The colour as `#RRGGBB`.
    pub fn hex(self) -> String {
        let [r, g, b] = self.rgb8();
        format!("#{r:02X}{g:02X}{b:02X}")
    }

    /// Linear-light components in [0, 1], reading the 8-bit value as sRGB-encoded (what
    /// a PNG viewer shows), for formats whose colours are linear (glTF).
    pub fn linear(self) -> [f64; 3] {
        self.rgb8().map(|c| {
            let c = c as f64 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    }
}

/// One scene object as a mesh in the file's frame.
#[derive(Clone, Debug)]
pub struct Part {
    /// The object's name in the scene ([`crate::ir::Object::name`]), unique in the file.
    pub name: String,
    /// The `object` statement.
    pub span: Span,
    /// The triangles in the file's frame, counter-clockwise seen from outside.
    pub mesh: crate::geom::TriMesh,
    /// Each triangle's material, an index into [`Export::colours`].
    pub materials: Vec<u32>,
    /// Whether the surface is smooth (shaded with interpolated normals when rendered).
    pub smooth: bool,
    /// Triangles dropped because they had no area.
    pub degenerate: usize,
    /// Of those, the ones with area in f64 that f32 coordinates took away.
    pub rounded_away: usize,
    /// For an isosurface made under a tolerance, how far it was measured from its
    /// surface.
    pub fit: Option<IsoFit>,
}

/// How far an isosurface's mesh was measured from the surface it was made of, in the
/// file's units (`mesh::deviation`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoFit {
    /// The largest distance found from a sampled point to the surface.
    pub max: f64,
    /// The mean over the sampled points.
    pub mean: f64,
    /// Points sampled.
    pub samples: usize,
    /// Triangles proved within the tolerance everywhere (not only at their samples).
    pub proved: usize,
    /// Samples whose distance could not be found (left out of `max` and `mean`).
    pub unresolved: usize,
}

impl Part {
    /// Unit normal of triangle `t` as the file holds it: of the 32-bit corners every
    /// format writes (far from the origin rounding turns small triangles; admesh
    /// "fixes" a stored normal that disagrees with its corners). Zero for none, which
    /// [`crate::export::collect`] never keeps.
    pub fn face_normal(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.mesh.triangles[t].map(|i| self.mesh.positions[i as usize].as_vec3().as_dvec3());
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Area-weighted vertex normals, for smooth surfaces.
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        let mut n = vec![DVec3::ZERO; self.mesh.positions.len()];
        for t in &self.mesh.triangles {
            let [a, b, c] = t.map(|i| self.mesh.positions[i as usize]);
            let face = (b - a).cross(c - a);
            for &i in t {
                n[i as usize] += face;
            }
        }
        n.into_iter().map(|v| v.normalize_or(DVec3::Y)).collect()
    }

    /// The part split by material: for each material used, its own vertices (shared
    /// vertices are copied into every material that uses them) and triangles. Formats
    /// with colours per vertex or one material per primitive write these.
    pub fn groups(&self) -> Vec<Group> {
        let mut groups: Vec<Group> = Vec::new();
        let mut remap = std::collections::HashMap::new();
        for (t, tri) in self.mesh.triangles.iter().enumerate() {
            let material = self.materials[t];
            let g = match groups.iter().position(|g| g.material == material) {
                Some(g) => g,
                None => {
                    groups.push(Group { material, vertices: Vec::new(), triangles: Vec::new() });
                    groups.len() - 1
                }
            };
            let corners = tri.map(|v| {
                *remap.entry((g, v)).or_insert_with(|| {
                    groups[g].vertices.push(v);
                    groups[g].vertices.len() as u32 - 1
                })
            });
            groups[g].triangles.push(corners);
        }
        groups
    }
}

/// The triangles of one material of a [`Part`], over their own vertices.
#[derive(Clone, Debug)]
pub struct Group {
    /// The material, an index into [`Export::colours`].
    pub material: u32,
    /// Indices into the part's positions.
    pub vertices: Vec<u32>,
    /// Triangles over `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// A scene's objects as meshes, with the colours they use.
#[derive(Clone, Debug)]
pub struct Export {
    /// The objects, in scene order.
    pub parts: Vec<Part>,
    /// Every material's colour (a part's materials index this).
    pub colours: Vec<Colour>,
    /// Each colour's material name: the `let` that named it, else `material_N`, unique.
    pub material_names: Vec<String>,
    /// What meshing found wrong but survivable, in scene order (parts an isosurface lost).
    pub warnings: Vec<crate::diag::Diagnostic>,
}

impl Export {
    /// Triangles of every part.
    pub fn triangle_count(&self) -> usize {
        self.parts.iter().map(|p| p.mesh.triangles.len()).sum()
    }
}
