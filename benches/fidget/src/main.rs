//! The reference for issue 41's camera-ray goal: the gyroid sheet of
//! benches/scenes/gyroid-primary.scn rendered by fidget 0.5's bytecode VM (its 3D
//! heightmap, 1000 voxels deep), framed like the scene: seen from the scene camera's
//! direction, the ball of radius 1.6 filling 0.79 of the half-width as it does under
//! the scene's 40° lens (orthographic here, perspective there; 479,195 pixels covered
//! against scnc's 481,473). Not part of scnc's build: `cd benches/fidget && cargo run
//! --release -- 1000` fetches fidget from crates.io and prints the best of five renders
//! on the machine's threads. docs/fields.md has the comparison.
use fidget::context::Tree;
use fidget::raster::voxel::RenderConfig;
use fidget::render::VoxelSize;
use fidget::vm::VmShape;
use nalgebra::{Matrix4, Vector3};

fn main() {
    let k = 450f32.to_radians();
    let (x, y, z) = (Tree::x(), Tree::y(), Tree::z());
    let s = |t: &Tree| (t.clone() * k).sin();
    let c = |t: &Tree| (t.clone() * k).cos();
    let g = s(&x) * c(&y) + s(&y) * c(&z) + s(&z) * c(&x);
    let ball = (x.clone().square() + y.clone().square() + z.clone().square()).sqrt() - 1.6;
    let body = (g.abs() - 0.3).max(ball);
    let shape = VmShape::from(body);
    let size: u32 = std::env::args().nth(1).map_or(1000, |a| a.parse().unwrap());
    // Camera basis: back towards the camera at [3.2, 2.4, -4.2], right, up.
    let back = Vector3::new(3.2f32, 2.4, -4.2).normalize();
    let right = Vector3::new(0.0f32, 1.0, 0.0).cross(&back).normalize();
    let up = back.cross(&right);
    let scale = 1.6 / 0.79;
    let mut m = Matrix4::identity();
    for r in 0..3 {
        m[(r, 0)] = right[r] * scale;
        m[(r, 1)] = up[r] * scale;
        m[(r, 2)] = back[r] * scale;
    }
    let mut best = f64::MAX;
    let mut filled = 0;
    for _ in 0..5 {
        let cfg = RenderConfig { image_size: VoxelSize::from(size), world_to_model: m };
        let t = std::time::Instant::now();
        let image = cfg.run(shape.clone().try_into().unwrap());
        best = best.min(t.elapsed().as_secs_f64());
        filled = image.iter().filter(|p| p.depth > 0).count();
    }
    println!("fidget VM {size}x{size}x{size}: best of 5 {best:.3} s, {filled} pixels with depth");
}
