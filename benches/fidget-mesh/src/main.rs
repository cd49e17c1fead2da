//! The anchor of issue 62's meshing goal: the gyroid sheet of `benches/scenes/gyroid-sheet.scn`
//! (period 0.8, |g| < 0.3, cut by a ball of radius 1.2) meshed by fidget 0.5's manifold dual
//! contouring, on the machine's threads, written as binary STL for `scnc`'s deviation
//! measurement (`cargo run --release --example deviation`). Not part of scnc's build:
//! `cd benches/fidget-mesh && cargo run --release -- DEPTH out.stl [vm|jit]` fetches fidget
//! from crates.io; the octree spans the ball's box, so a finest cell is 2.4 / 2^DEPTH
//! (depth 8: 0.0094). docs/performance.md has the comparison.
use fidget::context::Tree;
use fidget::mesh::{Octree, Settings};
use fidget::render::ThreadPool;

fn main() {
    let mut args = std::env::args().skip(1);
    let depth: u8 = args.next().and_then(|a| a.parse().ok()).expect("usage: DEPTH out.stl [vm|jit]");
    let out = args.next().expect("usage: DEPTH out.stl [vm|jit]");
    let jit = args.next().is_none_or(|a| a == "jit");
    let k = 450f32.to_radians();
    let (x, y, z) = (Tree::x(), Tree::y(), Tree::z());
    let s = |t: &Tree| (t.clone() * k).sin();
    let c = |t: &Tree| (t.clone() * k).cos();
    let g = s(&x) * c(&y) + s(&y) * c(&z) + s(&z) * c(&x);
    let ball = (x.clone().square() + y.clone().square() + z.clone().square()).sqrt() - 1.2;
    // The octree spans [-1, 1]³: the field is read at 1.2 times the octree's coordinates,
    // so the ball's box fills it, and the vertices are scaled back below.
    let body = (g.abs() - 0.3).max(ball).remap_xyz(Tree::x() * 1.2, Tree::y() * 1.2, Tree::z() * 1.2);
    let pool = ThreadPool::Global;
    let settings = Settings { depth, threads: Some(&pool), ..Default::default() };
    let start = std::time::Instant::now();
    let mut mesh = if jit {
        let shape = fidget::jit::JitShape::from(body);
        let bound = shape.try_into().expect("no extra vars");
        Octree::build(&bound, &settings).expect("not cancelled").walk_dual()
    } else {
        let shape = fidget::vm::VmShape::from(body);
        let bound = shape.try_into().expect("no extra vars");
        Octree::build(&bound, &settings).expect("not cancelled").walk_dual()
    };
    let secs = start.elapsed().as_secs_f64();
    for v in &mut mesh.vertices {
        *v *= 1.2;
    }
    let mut f = std::io::BufWriter::new(std::fs::File::create(&out).expect("the STL"));
    mesh.write_stl(&mut f).expect("writing the STL");
    println!(
        "fidget {} depth {depth}: {} triangles in {secs:.3} s (cell {:.4})",
        if jit { "jit" } else { "vm" },
        mesh.triangles.len(),
        2.4 / f64::from(1u32 << depth)
    );
}
