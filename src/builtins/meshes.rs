//! Mesh generators (after `mesh`).

use std::sync::Arc;

use glam::{DAffine3, DVec3};

use super::BoundArgs;
use super::Gen;
use super::MAX_MESH_RESOLUTION;
use super::{Host, Value};
use crate::ir::{self, MeshSource};
use crate::sig::Range;

/// The number of points or sides a generator's circles may have.
const RESOLUTION: Range = Range::closed(3.0, MAX_MESH_RESOLUTION as f64);

crate::params! {
    /// `mesh uvsphere(…)`.
    pub struct UvSphereArgs {
        /// the radius
        r: f64 as Num = 1.0, Range::POSITIVE;
        /// latitude bands
        rings: u32 as Int = 14, RESOLUTION;
        /// longitudes (twice `rings` when not given)
        segments: Option<u32> as Int = derived, RESOLUTION;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh icosphere(…)`.
    pub struct IcoSphereArgs {
        /// the radius
        r: f64 as Num = 1.0, Range::POSITIVE;
        /// how many times each triangle of the icosahedron is split in four
        subdivisions: u32 as Int = 2, Range::closed(0.0, 10.0);
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh box(…)`.
    pub struct BoxMeshArgs {
        /// half-extents (a number for a cube)
        size: DVec3 as Size = 1.0, Range::POSITIVE;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh cylinder(…)`.
    pub struct CylinderMeshArgs {
        /// the radius
        r: f64 as Num = 1.0, Range::POSITIVE;
        /// half the height, along y
        half_height: f64 as Num = 1.0, Range::POSITIVE;
        /// points on each cap's circle
        segments: u32 as Int = 32, RESOLUTION;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh torus(…)`.
    pub struct TorusMeshArgs {
        /// the distance from the centre to the middle of the tube
        major: f64 as Num = 1.0, Range::POSITIVE;
        /// the tube's radius
        minor: f64 as Num = 0.25, Range::POSITIVE;
        /// points around the major circle
        segments: u32 as Int = 32, RESOLUTION;
        /// points around the tube
        sides: u32 as Int = 16, RESOLUTION;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh plane(…)`.
    pub struct PlaneMeshArgs {
        /// half the square's side
        size: f64 as Num = 10.0, Range::POSITIVE;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh isosurface(…)`.
    pub struct IsosurfaceArgs {
        /// the shape to triangulate
        shape: Value as Shape = required;
        /// the side of the grid's cells, in the shape's units
        cell: f64 as Num = 0.02, Range::POSITIVE;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

crate::params! {
    /// `mesh file(…)`.
    pub struct FileArgs {
        /// the mesh file, relative to the scene file: OBJ, or by extension `.stl`, `.ply`, `.glb`, `.3mf` or `.off`
        path: String as Str = required;
        /// whether normals are interpolated across faces
        smooth: bool as Bool = false;
    }
}

impl dyn Host + '_ {
    /// A mesh from a generator, or `Value::Error` after reporting.
    pub(super) fn mesh(&mut self, g: Gen, a: BoundArgs) -> Value {
        let (source, smooth) = match g {
            Gen::UvSphere => {
                let UvSphereArgs { r, rings, segments, smooth } = UvSphereArgs::from_args(&a);
                let segments = segments.unwrap_or(2 * rings);
                if !self.triangle_budget(2 * rings as u64 * segments as u64, a.call) {
                    return Value::Error;
                }
                (MeshSource::UvSphere { radius: r, rings, segments }, smooth)
            }
            Gen::IcoSphere => {
                let IcoSphereArgs { r, subdivisions, smooth } = IcoSphereArgs::from_args(&a);
                (MeshSource::IcoSphere { radius: r, subdivisions }, smooth)
            }
            Gen::Box => {
                let BoxMeshArgs { size, smooth } = BoxMeshArgs::from_args(&a);
                (MeshSource::Box { half: size }, smooth)
            }
            Gen::Cylinder => {
                let CylinderMeshArgs { r, half_height, segments, smooth } = CylinderMeshArgs::from_args(&a);
                (MeshSource::Cylinder { radius: r, half_height, segments }, smooth)
            }
            Gen::Torus => {
                let TorusMeshArgs { major, minor, segments, sides, smooth } = TorusMeshArgs::from_args(&a);
                if !self.triangle_budget(2 * segments as u64 * sides as u64, a.call) {
                    return Value::Error;
                }
                (MeshSource::Torus { major, minor, segments, sides }, smooth)
            }
            Gen::Plane => {
                let PlaneMeshArgs { size, smooth } = PlaneMeshArgs::from_args(&a);
                (MeshSource::Plane { size }, smooth)
            }
            Gen::Isosurface => {
                let IsosurfaceArgs { shape: Value::Shape(shape), cell, smooth } = IsosurfaceArgs::from_args(&a) else {
                    return Value::Error;
                };
                (MeshSource::Isosurface { shape, cell }, smooth)
            }
            Gen::File => {
                let FileArgs { path, smooth } = FileArgs::from_args(&a);
                (MeshSource::File { path: self.file_dir().join(&path), written: path }, smooth)
            }
        };
        Value::Mesh(Arc::new(ir::Mesh { source, xf: DAffine3::IDENTITY, material: None, smooth, span: a.call }))
    }
}
