//! Incoherent-ray throughput of the mesh back-end's BVH, for issue 60's comparison with
//! Embree (`benches/embree.py` casts the same rays):
//! `cargo run --release --example rays -- MESH.stl [--rays N] [--seed S] [--write RAYS.bin] [--binary]`.
//! Origins are uniform in the mesh's box, directions uniform on the sphere — every ray
//! starts somewhere else and points anywhere, as a path's bounces do. Each ray is one
//! closest hit with its surface (`MeshObject::intersect`, what the tracer asks of a mesh) on one thread (rays per second per core),
//! best of three passes over the same rays; `--write` saves them as little-endian f32
//! `ox oy oz dx dy dz` for the other tool, and the hit count and mean distance are
//! printed so the two can be checked against each other. The BVH is the four-wide one
//! light transport gives meshes (`MeshObject::widen`); `--binary` walks the binary one.

use std::io::Write;
use std::process::ExitCode;
use std::time::Instant;

use glam::{DAffine3, Vec3A};
use scnc::geom::axes::{to_file, Up, STL_PER_UNIT};
use scnc::mesh::triangle::Shear;
use scnc::meshfile::Format;
use scnc::trace::{Counters, Ray};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(1)
        }
    }
}

/// A small, fixed generator (PCG32), so that a seed names the same rays on every machine.
struct Pcg(u64);

impl Pcg {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let x = (((self.0 >> 18) ^ self.0) >> 27) as u32;
        let r = x.rotate_right((self.0 >> 59) as u32);
        (r >> 8) as f32 / (1u32 << 24) as f32
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: rays MESH.stl [--rays N] [--seed S] [--write RAYS.bin] [--binary]";
    let path = args.first().ok_or(usage)?;
    let option = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let count: usize = option("--rays").map_or(Ok(1_000_000), |s| s.parse()).map_err(|e| format!("--rays: {e}"))?;
    let seed: u64 = option("--seed").map_or(Ok(1), |s| s.parse()).map_err(|e| format!("--seed: {e}"))?;
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    // Read as a scene reads it (millimetres to scene units, z up to y up); the rays are
    // written back in the file's frame for the other tool, which reads the file raw.
    let mesh = Format::Stl.read(&bytes).map_err(|e| format!("{path}: {e}"))?;
    let start = Instant::now();
    let mut object = scnc::mesh::MeshObject::new(&mesh, DAffine3::IDENTITY, 0, None, scnc::mesh::Normals::Flat);
    let binary = args.iter().any(|a| a == "--binary");
    if !binary {
        object.widen();
    }
    let build = start.elapsed().as_secs_f64();
    let memory = object.memory();
    let scnc::accel::Aabb { min: lo, max: hi } = object.bounds();
    let mut rng = Pcg(seed.wrapping_mul(0x9e3779b97f4a7c15) | 1);
    let rays: Vec<Ray> = (0..count)
        .map(|_| {
            let o = lo + (hi - lo) * Vec3A::new(rng.next(), rng.next(), rng.next());
            let z = 1.0 - 2.0 * rng.next();
            let phi = std::f32::consts::TAU * rng.next();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Ray::new(o, Vec3A::new(s * phi.cos(), s * phi.sin(), z), f32::INFINITY)
        })
        .collect();
    if let Some(out) = option("--write") {
        let mut raw = Vec::with_capacity(count * 24);
        for r in &rays {
            let o = to_file(r.origin.as_dvec3() * STL_PER_UNIT, Up::Z).as_vec3();
            let d = to_file(r.dir.as_dvec3(), Up::Z).as_vec3();
            for v in [o.x, o.y, o.z, d.x, d.y, d.z] {
                raw.extend_from_slice(&v.to_le_bytes());
            }
        }
        std::fs::write(&out, raw).map_err(|e| format!("{out}: {e}"))?;
    }
    let mut best = f64::INFINITY;
    let (mut hits, mut sum) = (0usize, 0f64);
    let mut counters = Counters::default();
    for _ in 0..3 {
        let (mut h, mut s) = (0usize, 0f64);
        let start = Instant::now();
        for r in &rays {
            // The tracer shears each ray's frame once and hands it down (World::reach).
            let shear = Shear::new(r.dir);
            if let Some(hit) = object.intersect(r, &shear, r.t_max, &mut counters) {
                h += 1;
                s += f64::from(hit.t);
            }
        }
        best = best.min(start.elapsed().as_secs_f64());
        (hits, sum) = (h, s);
    }
    let _ = writeln!(
        std::io::stdout(),
        "scnc: {} triangles, {} BVH built in {build:.2} s (all threads), {:.1} MB with its vertices and indices; {count} rays, {hits} hits, mean t {:.6} (file units); \
         best of 3 on one thread: {best:.3} s = {:.2} M rays/s; per ray {:.1} nodes, {:.1} triangle tests",
        mesh.triangles.len(),
        if binary { "binary" } else { "four-wide" },
        (memory.bvh_bytes + memory.vertex_bytes + memory.index_bytes) as f64 / 1e6,
        sum / hits.max(1) as f64 * STL_PER_UNIT,
        count as f64 / best / 1e6,
        counters.node_visits as f64 / (3 * count) as f64,
        counters.triangle_tests as f64 / (3 * count) as f64
    );
    Ok(())
}
