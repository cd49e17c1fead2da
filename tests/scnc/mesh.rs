//! The mesh back-end: BVH against brute force, watertightness, agreement with the SDF back-end.

use glam::{DAffine3, DVec3, Vec3A, Vec4};
use scnc::accel::Rays4;
use scnc::geom::{tessellate, TriMesh};
use scnc::mesh::Detail;
use scnc::mesh::{triangle, MeshObject};
use scnc::trace::{Counters, Geometry, Hit, Packet, Ray};
use scnc::world::Mode;

use crate::support::{compile, coverage, lower, Rng};

fn brute_force(mesh: &TriMesh, ray: &Ray) -> Option<f32> {
    let shear = triangle::Shear::new(ray.dir);
    let p = |i: u32| mesh.positions[i as usize].as_vec3a();
    mesh.triangles
        .iter()
        .filter_map(|t| triangle::intersect(ray.origin, &shear, p(t[0]), p(t[1]), p(t[2]), ray.t_min, ray.t_max))
        .map(|h| h.t)
        .reduce(f32::min)
}

/// `n` separate random triangles about `spread` around the origin.
fn soup(rng: &mut Rng, n: usize, spread: f32) -> TriMesh {
    let mut mesh = TriMesh::default();
    for _ in 0..n {
        let centre = rng.vec(spread);
        let base = mesh.positions.len() as u32;
        for _ in 0..3 {
            mesh.positions.push((centre + rng.vec(0.3)).as_dvec3());
        }
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    mesh
}

/// The BVH's closest hit is exactly the brute-force closest hit, on random triangle soups
/// of several sizes (so leaves, deep trees and empty space all occur).
#[test]
fn bvh_closest_hit_equals_brute_force() {
    let mut rng = Rng(0x0b5e_55ed);
    for (n, spread) in [(1usize, 1.0f32), (7, 1.0), (60, 2.0), (500, 3.0), (3000, 4.0)] {
        let mesh = soup(&mut rng, n, spread);
        let obj = MeshObject::new(&mesh, DAffine3::IDENTITY, 0, None, scnc::mesh::Normals::Flat);
        for _ in 0..2000 {
            let origin = rng.vec(spread * 2.0);
            let dir = (rng.vec(spread) - origin).try_normalize().unwrap_or(Vec3A::Z);
            let ray = Ray::new(origin, dir, 1e4);
            let mut c = Counters::default();
            let bvh = obj.intersect(&ray, &triangle::Shear::new(ray.dir), ray.t_max, &mut c).map(|h| h.t);
            assert_eq!(bvh, brute_force(&mesh, &ray), "{n} triangles: BVH and brute force disagree for {ray:?}");
            assert_eq!(
                obj.occluded(&ray, &triangle::Shear::new(ray.dir), ray.t_max, &mut c),
                bvh.is_some(),
                "any-hit disagrees with closest-hit"
            );
        }
    }
}

fn generators() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("uvsphere low", tessellate::uvsphere(1.0, 7, 14)),
        ("uvsphere high", tessellate::uvsphere(1.0, 14, 28)),
        ("icosphere", tessellate::icosphere(1.0, 2)),
        ("box", tessellate::cuboid(DVec3::new(1.0, 0.7, 0.4))),
        ("cylinder", tessellate::cylinder(0.8, 1.0, 10)),
        ("cone", tessellate::cone(0.8, 1.0, 12)),
        ("torus", tessellate::torus(1.0, 0.3, 16, 8)),
    ]
}

/// Rays aimed exactly at every shared vertex and edge of every closed generator, from
/// outside and from inside, never pass through: closed meshes stay closed.
#[test]
fn rays_through_shared_edges_and_vertices_never_miss() {
    let mut rng = Rng(0xed6e);
    for (name, mesh) in generators() {
        assert_eq!(mesh.open_edges(), (0, 0), "{name} is not closed");
        let xf = DAffine3::from_translation(DVec3::new(0.3, -0.2, 6.0));
        let obj = MeshObject::new(&mesh, xf, 0, None, scnc::mesh::Normals::Flat);
        let world: Vec<Vec3A> = mesh.positions.iter().map(|p| xf.transform_point3(*p).as_vec3a()).collect();
        let face_normal = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| world[i as usize]);
            (b - a).cross(c - a).normalize()
        };
        // Each target with the mean normal of the faces around it: seen from along that
        // normal every adjacent face is front-facing, so the target is not on a silhouette.
        let mut vertex_normals = vec![Vec3A::ZERO; world.len()];
        let mut edge_normals = std::collections::HashMap::new();
        for t in &mesh.triangles {
            let n = face_normal(t);
            for k in 0..3 {
                vertex_normals[t[k] as usize] += n;
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edge_normals.entry((a.min(b), a.max(b))).or_insert(Vec3A::ZERO) += n;
            }
        }
        let mut targets: Vec<(Vec3A, Vec3A)> =
            world.iter().zip(&vertex_normals).map(|(p, n)| (*p, n.normalize())).collect();
        for ((a, b), n) in &edge_normals {
            let (pa, pb) = (world[*a as usize], world[*b as usize]);
            targets.push(((pa + pb) * 0.5, n.normalize()));
            targets.push((pa + (pb - pa) * 0.237, n.normalize()));
        }
        // From inside, every line crosses the closed surface (the torus from its tube's core).
        let centre = Vec3A::new(0.3, -0.2, 6.0);
        let core = |p: Vec3A| {
            if name == "torus" {
                centre + Vec3A::new(p.x - centre.x, 0.0, p.z - centre.z).normalize_or_zero()
            } else {
                centre
            }
        };
        let mut c = Counters::default();
        for (target, normal) in targets {
            let outside = target + (normal + rng.vec(0.05)).normalize() * 3.0;
            for origin in [outside, core(target)] {
                let dir = (target - origin).normalize();
                let ray = Ray::new(origin, dir, 100.0);
                assert!(
                    obj.intersect(&ray, &triangle::Shear::new(ray.dir), ray.t_max, &mut c).is_some(),
                    "{name}: a ray from {origin} through {target} slipped through"
                );
            }
        }
    }
}

/// At 256×256, which pixels hit geometry differs between `--geometry mesh --detail high`
/// and the SDF back-end in at most 0.5 % of the pixels, and only on silhouettes (within
/// one pixel of a pixel where the SDF render changes between hit and miss).
#[test]
fn mesh_high_coverage_agrees_with_sdf() {
    const SIZE: u32 = 256;
    for path in crate::support::cases("examples/seed") {
        if path.file_name().is_some_and(|n| n == "lights.scn") {
            continue;
        }
        let scene = compile(&path).scene.expect("seed scene compiles");
        let sdf = coverage(&scene, Mode::Sdf, SIZE);
        let mesh = coverage(&scene, Mode::Mesh(Detail::High), SIZE);
        let s = SIZE as i32;
        let at = |x: i32, y: i32| sdf[(y.clamp(0, s - 1) * s + x.clamp(0, s - 1)) as usize];
        let mut differing = 0;
        for y in 0..s {
            for x in 0..s {
                let i = (y * s + x) as usize;
                if sdf[i] == mesh[i] {
                    continue;
                }
                differing += 1;
                let on_edge = (-1..=1).any(|dy| (-1..=1).any(|dx| at(x + dx, y + dy) != sdf[i]));
                assert!(on_edge, "{}: pixel ({x}, {y}) differs away from any silhouette", path.display());
            }
        }
        let allowed = (SIZE * SIZE) as usize / 200;
        assert!(differing <= allowed, "{}: {differing} pixels differ in coverage (at most {allowed})", path.display());
    }
}

/// At `--tolerance pixel` the mesh render covers the pixels the SDF render covers, to
/// within 1 % of them, on every feature scene (CSG, modifiers and capsules meshed as
/// isosurfaces) and on the 1,000-sphere smooth chain, at the detail the tolerance picks.
#[test]
fn mesh_at_pixel_tolerance_covers_what_sdf_covers() {
    const SIZE: u32 = 128;
    let mut paths = crate::support::cases("examples/features");
    paths.push("benches/scenes/chain-1000.scn".into());
    for path in paths {
        let mut scene = compile(&path).scene.expect("scene compiles");
        scene.settings.width = SIZE;
        scene.settings.height = SIZE;
        let detail = scnc::study::tolerance::mesh_detail(&scene, scnc::study::tolerance::Tolerance::Pixel);
        let sdf = coverage(&scene, Mode::Sdf, SIZE);
        let mesh = coverage(&scene, Mode::Mesh(detail), SIZE);
        let differing = sdf.iter().zip(&mesh).filter(|(a, b)| a != b).count();
        let allowed = (SIZE * SIZE) as usize / 100;
        assert!(
            differing <= allowed,
            "{} at detail {}: {differing} pixels differ in coverage (at most {allowed})",
            path.display(),
            detail.rings()
        );
    }
}

/// Each lane of a camera-ray packet finds what its ray finds traced alone, for every seed
/// scene and `tests/data/packets` (unions whose parts a packet walks together; in every
/// mode, by `conformance.rs`), for 2×2 packets and 4×4 blocks of four,
/// full and partial: hit or miss exactly, the distance up to rounding, and the same
/// surface except where a ray meets an edge and two faces tie within rounding (then
/// either face is correct; the walks visit leaves in different orders). Packets spread
/// too wide to share a shear still share the BVH walk and test meshes lane by lane.
pub fn packets_agree_with_single_rays(mode: Mode) {
    const SIZE: u32 = 128;
    let mut rng = Rng(0x9ac4_e7a1);
    for path in crate::support::cases("examples/seed").into_iter().chain(crate::support::cases("tests/data/packets")) {
        if path.file_name().is_some_and(|n| n == "lights.scn") {
            continue;
        }
        let (frame, world) = lower(&compile(&path).scene.expect("seed scene compiles"), SIZE, mode);
        let ray =
            |x: u32, y: u32| Ray::new(Vec3A::ZERO, frame.direction(x as f32 + 0.5, y as f32 + 0.5), frame.max_distance);
        let (mut lanes, mut ties) = (0usize, 0usize);
        let mut c = Counters::default();
        let mut check = |packet: &Packet, hits: &[Option<Hit>; 4], at: &str, c: &mut Counters| {
            for (l, r) in packet.rays.iter().enumerate() {
                if packet.mask & (1 << l) == 0 {
                    assert!(hits[l].is_none(), "{at} lane {l}: an unwanted lane returns nothing");
                    continue;
                }
                let alone = world.intersect(r, c);
                lanes += 1;
                match (alone, hits[l]) {
                    (None, None) => {}
                    (Some(a), Some(p)) => {
                        assert!(
                            (a.t - p.t).abs() <= a.t * 1e-6,
                            "{at} lane {l}: distance {} alone, {} in a packet",
                            a.t,
                            p.t
                        );
                        if a.normal != p.normal || a.material != p.material {
                            ties += 1;
                        }
                    }
                    (a, p) => panic!("{at} lane {l}: {} alone, {} in a packet", a.is_some(), p.is_some()),
                }
            }
        };
        for by in (0..SIZE).step_by(4) {
            for bx in (0..SIZE).step_by(4) {
                let quads: [Packet; 4] = std::array::from_fn(|q| {
                    let (qx, qy) = (bx + 2 * (q as u32 % 2), by + 2 * (q as u32 / 2));
                    let mut rays = vec![ray(qx, qy), ray(qx + 1, qy), ray(qx, qy + 1), ray(qx + 1, qy + 1)];
                    // Some packets partial or wanting nothing (a block at the frame's
                    // edge), some spread over the whole frame (the fallback).
                    match rng.below(10) {
                        0 => rays.truncate(1 + rng.below(3)),
                        1 => rays[3] = ray(rng.below(SIZE as usize) as u32, rng.below(SIZE as usize) as u32),
                        2 => return Packet { mask: 0, ..Packet::new(&rays) },
                        _ => {}
                    }
                    Packet::new(&rays)
                });
                let at = format!("{} {mode:?} block ({bx}, {by})", path.display());
                let block = world.intersect16(&quads, &mut c);
                for (q, quad) in quads.iter().enumerate() {
                    check(quad, &block[q], &format!("{at} 4×4 packet {q}"), &mut c);
                    check(quad, &world.intersect4(quad, &mut c), &format!("{at} 2×2 packet {q}"), &mut c);
                }
            }
        }
        assert!(ties <= lanes / 1000, "{} {mode:?}: {ties} of {lanes} lanes found another surface", path.display());
    }
}

/// The packet walk of a mesh finds exactly the brute-force closest hit for every lane,
/// on random triangle soups, with coherent rays from one origin as the camera casts them,
/// in packets of one and of four groups of four, some lanes unwanted.
#[test]
fn packet_closest_hit_equals_brute_force() {
    fn check<const N: usize>(rng: &mut Rng, n: usize, spread: f32) {
        let mesh = soup(rng, n, spread);
        let obj = MeshObject::new(&mesh, DAffine3::IDENTITY, 0, None, scnc::mesh::Normals::Flat);
        let (mut packets, mut fallbacks) = (0, 0);
        for _ in 0..1000 {
            let origin = rng.vec(spread * 2.0);
            let aim = rng.vec(spread) - origin;
            let groups: [[Ray; 4]; N] = std::array::from_fn(|_| {
                std::array::from_fn(|_| {
                    Ray::new(origin, (aim + rng.vec(0.05 * spread)).try_normalize().unwrap_or(Vec3A::Z), 1e4)
                })
            });
            let mut rays4 = [Rays4 { origin: [Vec4::ZERO; 3], inv_dir: [Vec4::ZERO; 3], t_min: Vec4::ZERO }; N];
            let mut dirs = [[Vec4::ZERO; 3]; N];
            for (g, rays) in groups.iter().enumerate() {
                let packet = Packet::new(rays);
                rays4[g] = Rays4 {
                    origin: packet.across(|r| r.origin),
                    inv_dir: packet.across(|r| r.inv_dir),
                    t_min: packet.each(|r| r.t_min),
                };
                dirs[g] = packet.across(|r| r.dir);
            }
            let Some(shear) = triangle::PacketShear::new(origin, &dirs) else {
                fallbacks += 1;
                continue;
            };
            packets += 1;
            let mut t_max = groups.map(|rays| Vec4::from_array(rays.map(|r| r.t_max)));
            // Every lane wanted, or a random subset (never none).
            let all = (1u32 << (4 * N)) - 1;
            let mask = if rng.below(2) == 0 { all } else { (rng.below(all as usize) as u32 + 1) & all };
            let mut c = Counters::default();
            let mut hits = [[None; 4]; N];
            obj.closest_packet(&rays4, &shear, mask, &mut t_max, &mut c, |g, l, _, hit| hits[g][l] = Some(hit.t));
            for (lane, ray) in groups.iter().flatten().enumerate().filter(|(lane, _)| mask & (1 << lane) != 0) {
                let found = hits[lane / 4][lane % 4];
                assert_eq!(found, brute_force(&mesh, ray), "{n} triangles, {N} groups, lane {lane}: {ray:?}");
                // The walk leaves each lane's `t_max` at its closest hit.
                assert_eq!(t_max[lane / 4][lane % 4], found.unwrap_or(ray.t_max), "lane {lane}: {ray:?}");
            }
        }
        assert!(
            packets > 10 * fallbacks,
            "{n} triangles: {fallbacks} of {} packets could not share a shear",
            packets + fallbacks
        );
    }
    let mut rng = Rng(0x5eed_4a11);
    for (n, spread) in [(1usize, 1.0f32), (60, 2.0), (3000, 4.0)] {
        check::<1>(&mut rng, n, spread);
        check::<4>(&mut rng, n, spread);
    }
}

/// The generators the renderer treats as convex (a secondary ray leaving one of their
/// faces outward skips the mesh) make convex polytopes: every vertex lies behind the
/// plane of every face, at many sizes. The torus, the one that is not, is caught.
#[test]
fn convex_generators_make_convex_polytopes() {
    fn worst_bulge(mesh: &TriMesh) -> f64 {
        let mut worst = f64::NEG_INFINITY;
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = (b - a).cross(c - a).normalize();
            for p in &mesh.positions {
                worst = worst.max((*p - a).dot(n));
            }
        }
        worst
    }
    let mut meshes = vec![("box".to_string(), tessellate::cuboid(DVec3::new(1.0, 0.7, 0.4)))];
    for n in [3u32, 4, 5, 7, 10, 14, 25, 50, 64] {
        meshes.push((format!("uvsphere {n}"), tessellate::uvsphere(1.0, n, 2 * n)));
        meshes.push((format!("uvsphere {n}×3"), tessellate::uvsphere(2.0, n, 3)));
        meshes.push((format!("cylinder {n}"), tessellate::cylinder(0.8, 1.0, n)));
        meshes.push((format!("cone {n}"), tessellate::cone(0.8, 1.0, n)));
    }
    for s in 0..=4 {
        meshes.push((format!("icosphere {s}"), tessellate::icosphere(1.0, s)));
    }
    for (name, mesh) in &meshes {
        let bulge = worst_bulge(mesh);
        assert!(bulge <= 1e-12, "{name}: a vertex lies {bulge} in front of a face");
    }
    let torus = worst_bulge(&tessellate::torus(1.0, 0.3, 16, 8));
    assert!(torus > 0.1, "the torus is not convex, but its worst bulge is {torus}");
}

/// The memory budget's per-triangle estimate is above what every generator's mesh keeps
/// once built (vertices, normals, indices, BVH), flat and smooth, small and large, and
/// under light transport, whose meshes keep a four-wide BVH and their corners in leaf
/// order as well.
#[test]
fn memory_estimate_bounds_what_meshes_keep() {
    let generators = [
        "uvsphere(rings = 3",
        "uvsphere(rings = 200",
        "icosphere(subdivisions = 5",
        "torus(segments = 300, sides = 100",
        "box(1",
        "cylinder(segments = 500",
    ];
    for smooth in [false, true] {
        for generator in generators {
            let kept = |light: &str| {
                let s = crate::support::scene(&format!(
                    "light {light}\nobject mesh {generator}, smooth = {smooth}) at [0, 0, 5]\n"
                ));
                let (_, world) = lower(&s, 8, Mode::Mesh(Detail::High));
                let mem = world.memory();
                let per = mem.mesh_bytes() as f64 / mem.triangles().max(1) as f64;
                assert!(
                    per <= scnc::mesh::lower::BYTES_PER_TRIANGLE as f64,
                    "{generator}) smooth {smooth}, {light}: {per:.1} bytes per triangle kept"
                );
                per
            };
            // An environment light turns light transport on, and its meshes keep more.
            let (whitted, transport) = (kept("ambient(1)"), kept("environment(1)"));
            assert!(transport > whitted, "{generator}) smooth {smooth}: {transport:.1} ≤ {whitted:.1} bytes");
        }
    }
}

/// A lowering that stops being wanted stops building its meshes' BVHs too (most of a
/// large mesh's lowering): `wanted` is asked between objects, once the meshes are made,
/// and at every BVH subtree of 4,096 or more triangles, and once it says no the result
/// is `None`. Counted, not timed: told no at its third question, the build asks only a
/// few more times where a whole build of this mesh asks at each of its large subtrees.
#[test]
fn an_unwanted_lowering_stops_in_the_bvh_build() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;
    let text = "camera(position = [0, 0, -4], look_at = [0, 0, 0])\nlight ambient(1)\n\
                object mesh uvsphere(rings = 200, segments = 400)\n";
    let scene = crate::support::scene(text);
    let loader = scnc::source::FsLoader;
    let asks = |until: usize| {
        let asked = Arc::new(AtomicUsize::new(0));
        let counted = Arc::clone(&asked);
        let wanted: scnc::mesh::Wanted = Arc::new(move || counted.fetch_add(1, Ordering::Relaxed) < until);
        let limit = scnc::mesh::lower::DEFAULT_MEMORY_LIMIT;
        let effects = scnc::render::effects::derive(&scene);
        let lowered = scnc::world::prepare_until(&scene, effects, Mode::Sdf, &loader, limit, wanted).expect("lowers");
        (lowered.is_some(), asked.load(Ordering::Relaxed))
    };
    let (whole, all_asks) = asks(usize::MAX);
    assert!(whole, "a wanted lowering makes its world");
    // 160,000 triangles: dozens of subtrees of 4,096 or more.
    assert!(all_asks > 20, "a whole build asked {all_asks} times");
    let (made, stopped_asks) = asks(2);
    assert!(!made, "an unwanted lowering makes nothing");
    assert!(stopped_asks > 3 && stopped_asks < all_asks / 2, "stopped after {stopped_asks} of {all_asks} questions");
}
