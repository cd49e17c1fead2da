//! Criterion benchmarks: one SDF evaluation per primitive and of the gyroid sheet's field, primary rays (one by one, in
//! 2×2 packets and in 4×4 blocks, shading off) over seed scenes 1 and 6 and a frame-filling sphere, and
//! whole renders of every seed scene at a reduced size on one thread, and unions of
//! 10 to 10,000 spheres against the same spheres as objects.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec3A;
use scnc::render::Frame;
use scnc::trace::{Counters, Geometry, Packet, Ray};

fn lower(path: &str, w: u32, h: u32) -> (Frame, scnc::world::World) {
    lower_mode(path, w, h, scnc::world::Mode::Sdf)
}

fn lower_mode(path: &str, w: u32, h: u32, mode: scnc::world::Mode) -> (Frame, scnc::world::World) {
    let text = std::fs::read_to_string(path).expect("seed scene");
    let c = scnc::compile_source(path, Path::new(path), text, &scnc::source::FsLoader);
    let mut scene = c.scene.expect("seed scenes compile");
    scene.settings.width = w;
    scene.settings.height = h;
    let (frame, g) = scnc::world::prepare(&scene, scnc::render::effects::derive(&scene), mode, &scnc::source::FsLoader)
        .expect("lowering");
    (frame, g)
}

/// The SDF of every shape in `tests/data/primitives.scn` (the one list tests and
/// benches share), lowered alone, at points around it.
fn primitives(c: &mut Criterion) {
    let mut group = c.benchmark_group("sdf eval");
    let path = "tests/data/primitives.scn";
    let text = std::fs::read_to_string(path).expect("the primitives list");
    let c2 = scnc::compile_source(path, Path::new(path), text.clone(), &scnc::source::FsLoader);
    let list = c2.scene.expect("the primitives list compiles");
    for object in &list.objects {
        let scnc::ir::Body::Shape(_) = &object.geometry else { continue };
        let (_, range) = c2.map.local_range(object.span);
        let source = text[range].trim_start_matches("object ").to_string();
        let mut alone = list.clone();
        alone.objects = vec![object.clone()];
        let (_, g) = scnc::world::prepare(
            &alone,
            scnc::render::effects::derive(&alone),
            scnc::world::Mode::Sdf,
            &scnc::source::FsLoader,
        )
        .expect("lowers");
        // The list has no camera, so render space is world space.
        let (centre, r) = scnc::ir::bounding_sphere(&object.geometry).expect("bounded");
        let points: Vec<Vec3A> = (0..256)
            .map(|i| {
                let i = i as f64;
                let offset = glam::DVec3::new((i * 0.37).sin(), (i * 0.71).cos(), (i * 0.13).sin()) * 1.5 * r;
                (centre + offset).as_vec3a()
            })
            .collect();
        group.throughput(Throughput::Elements(points.len() as u64));
        group.bench_function(source, |b| {
            b.iter(|| points.iter().map(|p| g.sdf_eval(0, black_box(*p)).unwrap_or(0.0)).sum::<f32>())
        });
    }
    // A field body whose cost is its interpreter's (field::flat): the gyroid sheet.
    let (_, g) = lower("benches/scenes/gyroid.scn", 64, 64);
    let points: Vec<Vec3A> = (0..256)
        .map(|i| {
            let i = i as f32;
            Vec3A::new((i * 0.37).sin(), (i * 0.71).cos(), (i * 0.13).sin()) * 1.5
        })
        .collect();
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("gyroid sheet (benches/scenes/gyroid.scn)", |b| {
        b.iter(|| points.iter().map(|p| g.sdf_eval(0, black_box(*p)).unwrap_or(0.0)).sum::<f32>())
    });
    group.finish();
}

fn march(c: &mut Criterion) {
    let mut group = c.benchmark_group("primary rays");
    let modes = [("sdf", scnc::world::Mode::Sdf), ("mesh-high", scnc::world::Mode::Mesh(scnc::mesh::Detail::High))];
    // 256×256 for quick comparisons; the study's 1000×1000 (where the throughput
    // targets are stated) for the two scenes those targets name.
    let cases = [
        ("examples/seed/01-sphere.scn", 256),
        ("examples/seed/06-many-spheres.scn", 256),
        ("benches/scenes/full-frame-sphere.scn", 256),
        ("examples/seed/06-many-spheres.scn", 1000),
        ("benches/scenes/full-frame-sphere.scn", 1000),
    ];
    for ((path, size), (mode_name, mode)) in cases.into_iter().flat_map(|c| modes.into_iter().map(move |m| (c, m))) {
        let (frame, g) = lower_mode(path, size, size, mode);
        let n = size as usize;
        let dirs: Vec<Vec3A> =
            (0..n * n).map(|i| frame.direction((i % n) as f32 + 0.5, (i / n) as f32 + 0.5)).collect();
        group.throughput(Throughput::Elements(dirs.len() as u64));
        let stem = Path::new(path).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let name = if size == 256 { stem } else { format!("{stem} {size}") };
        group.bench_function(BenchmarkId::new(format!("intersect {mode_name}"), &name), |b| {
            b.iter(|| {
                let mut counters = Counters::default();
                dirs.iter()
                    .filter(|d| g.intersect(&Ray::new(Vec3A::ZERO, **d, frame.max_distance), &mut counters).is_some())
                    .count()
            })
        });
        // The packet of the 2×2 pixels from `(x, y)`.
        let quad = |x: usize, y: usize| {
            Packet::from_fn(4, |l| Ray::new(Vec3A::ZERO, dirs[(y + l / 2) * n + x + l % 2], frame.max_distance))
        };
        let half = n / 2;
        let blocks: Vec<Packet> = (0..half * half).map(|b| quad(2 * (b % half), 2 * (b / half))).collect();
        group.bench_function(BenchmarkId::new(format!("packets {mode_name}"), &name), |b| {
            b.iter(|| {
                let mut counters = Counters::default();
                blocks
                    .iter()
                    .map(|p| g.intersect4(p, &mut counters).iter().filter(|h| h.is_some()).count())
                    .sum::<usize>()
            })
        });
        // The same rays as the tracer casts them: 4×4 pixel blocks as four 2×2 packets,
        // traced together.
        let quarter = n / 4;
        let blocks16: Vec<[Packet; 4]> = (0..quarter * quarter)
            .map(|b| {
                let (bx, by) = (4 * (b % quarter), 4 * (b / quarter));
                std::array::from_fn(|g| quad(bx + 2 * (g % 2), by + 2 * (g / 2)))
            })
            .collect();
        group.bench_function(BenchmarkId::new(format!("blocks {mode_name}"), &name), |b| {
            b.iter(|| {
                let mut counters = Counters::default();
                blocks16
                    .iter()
                    .map(|p| g.intersect16(p, &mut counters).iter().flatten().filter(|h| h.is_some()).count())
                    .sum::<usize>()
            })
        });
    }
    group.finish();
}

fn renders(c: &mut Criterion) {
    let mut group = c.benchmark_group("render 200x200 1 thread");
    group.sample_size(20);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    for i in 1..=7 {
        let path = std::fs::read_dir("examples/seed")
            .expect("examples")
            .filter_map(Result::ok)
            .map(|e| e.path())
            .find(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with(&format!("0{i}-"))))
            .expect("seed scene");
        let path = path.to_string_lossy().into_owned();
        let (frame, g) = lower(&path, 200, 200);
        group.throughput(Throughput::Elements(200 * 200));
        group.bench_function(BenchmarkId::new("sdf", i), |b| {
            b.iter(|| pool.install(|| scnc::render::render(&g, &frame, &|| {})))
        });
    }
    group.finish();
}

/// Issue 21's scenes: the same N jittered spheres as N objects, one union and one smooth
/// union (`benches/scenes/{objects,union,smooth}-N.scn`), rendered at 200×200 on both
/// threads; the ratios between the three at each N are what the README reports.
fn csg_scale(c: &mut Criterion) {
    let mut group = c.benchmark_group("csg scale 200x200");
    group.sample_size(10);
    for n in [10, 100, 1_000, 10_000] {
        for kind in ["objects", "union", "smooth"] {
            let (frame, g) = lower(&format!("benches/scenes/{kind}-{n}.scn"), 200, 200);
            group.throughput(Throughput::Elements(200 * 200));
            group.bench_function(BenchmarkId::new(kind, n), |b| b.iter(|| scnc::render::render(&g, &frame, &|| {})));
        }
    }
    group.finish();
}

fn bvh(c: &mut Criterion) {
    let mut group = c.benchmark_group("bvh");
    group.sample_size(10);
    for rings in [14u32, 100, 700] {
        let mesh = scnc::geom::tessellate::uvsphere(1.0, rings, 2 * rings);
        group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        group.bench_function(BenchmarkId::new("build uvsphere triangles", mesh.triangles.len()), |b| {
            b.iter(|| {
                scnc::mesh::MeshObject::new(
                    &mesh,
                    glam::DAffine3::from_translation(glam::DVec3::new(0.0, 0.0, 5.0)),
                    0,
                    None,
                    scnc::mesh::Normals::Flat,
                )
            })
        });
    }
    // Issue 22's target: a million triangles generated and built in ≤ 0.3 s on 2 cores.
    let (rings, segments) = (500, 1000);
    group.throughput(Throughput::Elements(scnc::geom::tessellate::count::uvsphere(rings, segments)));
    group.bench_function("tessellate and build smooth uvsphere 998000", |b| {
        b.iter(|| {
            let mesh = scnc::geom::tessellate::uvsphere(1.0, rings, segments);
            scnc::mesh::MeshObject::new(
                &mesh,
                glam::DAffine3::from_translation(glam::DVec3::new(0.0, 0.0, 5.0)),
                0,
                None,
                scnc::mesh::Normals::Vertex,
            )
        })
    });
    group.finish();
}

criterion_group!(benches, primitives, march, renders, csg_scale, bvh);
criterion_main!(benches);
