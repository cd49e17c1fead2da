//! What `scnc export --stats` says of each object: whether its mesh is closed and
//! manifold, what was dropped, its volume and bounds.

use glam::DVec3;

use super::Part;

/// The checks of one exported object.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshReport {
    /// Triangles written.
    pub triangles: usize,
    /// Edges not shared by exactly two triangles (0: watertight).
    pub open_edges: usize,
    /// Directed edges used by more than one triangle (0: consistently wound, so with
    /// no open edges every edge has exactly two triangles, one each way: manifold).
    pub misoriented_edges: usize,
    /// Zero-area triangles dropped.
    pub degenerate: usize,
    /// Enclosed volume (meaningful when watertight), in the file's units cubed.
    pub volume: f64,
    /// Smallest and largest corner of the bounds, in the file's frame.
    pub bounds: (DVec3, DVec3),
}

impl MeshReport {
    /// Checks `part`.
    pub fn of(part: &Part) -> MeshReport {
        let mesh = &part.mesh;
        let (open_edges, misoriented_edges) = mesh.open_edges();
        let bounds =
            mesh.positions.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        MeshReport {
            triangles: mesh.triangles.len(),
            open_edges,
            misoriented_edges,
            degenerate: part.degenerate,
            volume: mesh.signed_volume(),
            bounds,
        }
    }

    /// Watertight and manifold: every edge shared by exactly two triangles, wound
    /// opposite ways.
    pub fn is_closed_manifold(&self) -> bool {
        self.open_edges == 0 && self.misoriented_edges == 0
    }
}
