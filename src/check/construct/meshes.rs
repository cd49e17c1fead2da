//! Mesh generators (after `mesh`).

use std::sync::Arc;

use glam::DAffine3;

use super::{MAX_MESH_RESOLUTION, POS};
use crate::check::builtins::{Builtin, Gen};
use crate::check::expr::BoundArgs;
use crate::check::{Ctx, Value};
use crate::ir::{self, MeshSource};

impl Ctx<'_> {
    /// A mesh from a generator, or `Value::Error` after reporting.
    pub(super) fn mesh(&mut self, b: &Builtin, g: Gen, a: BoundArgs) -> Value {
        let pos = |x: f64| x > 0.0;
        let smooth_idx = b.params.iter().position(|p| p.name == "smooth").unwrap_or(0);
        let res = MAX_MESH_RESOLUTION;
        let source = match g {
            Gen::UvSphere => {
                let ok_r = self.check_num(&a, b, 0, pos, POS);
                let rings = self.check_int(&a, b, 1, 3, res);
                let segments = if a.given(2) { self.check_int(&a, b, 2, 3, res) } else { rings.map(|r| 2 * r) };
                let (true, Some(rings), Some(segments)) = (ok_r, rings, segments) else {
                    return Value::Error;
                };
                if !self.triangle_budget(2 * rings as u64 * segments as u64, a.call) {
                    return Value::Error;
                }
                MeshSource::UvSphere { radius: a.num(b, 0), rings, segments }
            }
            Gen::IcoSphere => {
                let ok_r = self.check_num(&a, b, 0, pos, POS);
                let (true, Some(subdivisions)) = (ok_r, self.check_int(&a, b, 1, 0, 10)) else {
                    return Value::Error;
                };
                MeshSource::IcoSphere { radius: a.num(b, 0), subdivisions }
            }
            Gen::Box => {
                if !self.check_vec(&a, b, 0, pos, POS) {
                    return Value::Error;
                }
                MeshSource::Box { half: a.vec(b, 0) }
            }
            Gen::Cylinder => {
                let ok = self.check_num(&a, b, 0, pos, POS) & self.check_num(&a, b, 1, pos, POS);
                let (true, Some(segments)) = (ok, self.check_int(&a, b, 2, 3, res)) else {
                    return Value::Error;
                };
                MeshSource::Cylinder { radius: a.num(b, 0), half_height: a.num(b, 1), segments }
            }
            Gen::Torus => {
                let ok = self.check_num(&a, b, 0, pos, POS) & self.check_num(&a, b, 1, pos, POS);
                let segments = self.check_int(&a, b, 2, 3, res);
                let sides = self.check_int(&a, b, 3, 3, res);
                let (true, Some(segments), Some(sides)) = (ok, segments, sides) else {
                    return Value::Error;
                };
                if !self.triangle_budget(2 * segments as u64 * sides as u64, a.call) {
                    return Value::Error;
                }
                MeshSource::Torus { major: a.num(b, 0), minor: a.num(b, 1), segments, sides }
            }
            Gen::Plane => {
                if !self.check_num(&a, b, 0, pos, POS) {
                    return Value::Error;
                }
                MeshSource::Plane { size: a.num(b, 0) }
            }
            Gen::Isosurface => {
                let Value::Shape(shape) = a.value(b, 0) else {
                    return Value::Error;
                };
                if !self.check_num(&a, b, 1, pos, POS) {
                    return Value::Error;
                }
                MeshSource::Isosurface { shape, cell: a.num(b, 1) }
            }
            Gen::File => {
                let Value::Str(written) = a.value(b, 0) else {
                    return Value::Error;
                };
                MeshSource::File { path: self.dir.join(&*written), written: written.to_string() }
            }
        };
        Value::Mesh(Arc::new(ir::Mesh {
            source,
            xf: DAffine3::IDENTITY,
            material: None,
            smooth: a.flag(b, smooth_idx),
            span: a.call,
        }))
    }
}
