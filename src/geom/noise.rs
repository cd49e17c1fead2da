//! Perlin's improved gradient noise (Perlin 2002), shared by the `noise` pattern and
//! the `noise3` field function, with its analytic gradient.

use glam::DVec3;

/// An upper bound of `|∇noise|` anywhere: the steepest slope found (3.40, by climbing
/// from the steepest of a dense sample: `slope_is_bounded` below) with a quarter more
/// as margin, so a field using `noise3` is marched with a step that does not cross its
/// surface. (Dense sampling with a stated margin, not a proof; Perlin's construction
/// bounds it by about 15, which would slow every noisy field fourfold.)
pub const NOISE_SLOPE: f64 = 4.3;

/// Bounds of the noise's value (improved noise stays within about ±1; `bounded_between`
/// below finds 1.0 at most).
pub const NOISE_RANGE: f64 = 1.1;

/// The noise at `p`: at integer lattice points the value is 0 and the gradient one of
/// the twelve cube-edge directions, chosen by hashing the point with `seed` (integer
/// arithmetic, so every machine gives the same field); between them the quintic fade
/// blends the eight corners. Values lie in about [−1, 1].
pub fn noise(p: DVec3, seed: u32) -> f64 {
    noise_gradient(p, seed).0
}

/// The noise at `p` and its gradient.
pub fn noise_gradient(p: DVec3, seed: u32) -> (f64, DVec3) {
    let cell = p.floor();
    let f = p - cell;
    // Lattice points wrap at i32 (saturating casts, then wrapping sums): far points stay
    // defined, and the field repeats there.
    let (x, y, z) = (cell.x as i32, cell.y as i32, cell.z as i32);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let dfade = |t: f64| 30.0 * t * t * (t * (t - 2.0) + 1.0);
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let (du, dv, dw) = (dfade(f.x), dfade(f.y), dfade(f.z));
    // Each corner's value and gradient (the gradient of a dot product with a constant).
    let corner = |dx: i32, dy: i32, dz: i32| {
        let h = hash(x.wrapping_add(dx), y.wrapping_add(dy), z.wrapping_add(dz), seed);
        let g = grad(h);
        (g.dot(f - DVec3::new(dx as f64, dy as f64, dz as f64)), g)
    };
    let c = [
        corner(0, 0, 0),
        corner(1, 0, 0),
        corner(0, 1, 0),
        corner(1, 1, 0),
        corner(0, 0, 1),
        corner(1, 0, 1),
        corner(0, 1, 1),
        corner(1, 1, 1),
    ];
    // Trilinear blend by the faded coordinates, and its derivative by the product rule.
    let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
    let x00 = lerp(u, c[0].0, c[1].0);
    let x10 = lerp(u, c[2].0, c[3].0);
    let x01 = lerp(u, c[4].0, c[5].0);
    let x11 = lerp(u, c[6].0, c[7].0);
    let y0 = lerp(v, x00, x10);
    let y1 = lerp(v, x01, x11);
    let value = lerp(w, y0, y1);
    let weights = [
        (1.0 - u) * (1.0 - v) * (1.0 - w),
        u * (1.0 - v) * (1.0 - w),
        (1.0 - u) * v * (1.0 - w),
        u * v * (1.0 - w),
        (1.0 - u) * (1.0 - v) * w,
        u * (1.0 - v) * w,
        (1.0 - u) * v * w,
        u * v * w,
    ];
    let mut g = DVec3::ZERO;
    for (wt, (_, cg)) in weights.iter().zip(&c) {
        g += *wt * *cg;
    }
    let gx = du * lerp(w, lerp(v, c[1].0 - c[0].0, c[3].0 - c[2].0), lerp(v, c[5].0 - c[4].0, c[7].0 - c[6].0));
    let gy = dv * lerp(w, x10 - x00, x11 - x01);
    let gz = dw * (y1 - y0);
    (value, g + DVec3::new(gx, gy, gz))
}

/// A well-mixed 32-bit hash of a lattice point and a seed (the `lowbias32` finaliser
/// over a combination of the coordinates).
fn hash(x: i32, y: i32, z: i32, seed: u32) -> u32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f)
        ^ seed.wrapping_mul(0x9e37_79b9);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^ (h >> 16)
}

/// The cube-edge gradient `h` picks (Perlin's sixteen-entry table: the twelve edges,
/// four of them twice).
fn grad(h: u32) -> DVec3 {
    let h = h >> 28;
    let mut g = DVec3::ZERO;
    let (u, v) = match h {
        0..=3 => (0, 1),
        12 | 14 => (1, 0),
        4..=7 => (0, 2),
        _ => (1, 2),
    };
    g[u] = if h & 1 == 0 { 1.0 } else { -1.0 };
    g[v] = if h & 2 == 0 { 1.0 } else { -1.0 };
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A number in [0, 1) from `i` (SplitMix64's finaliser).
    fn unit(i: u64) -> f64 {
        let mut z = i.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Points spread over many cells, deterministic.
    fn sample(n: usize) -> impl Iterator<Item = DVec3> {
        (0..n).map(|i| {
            let r = |k: u64| unit(i as u64 * 3 + k) * 40.0 - 20.0;
            DVec3::new(r(0), r(1), r(2))
        })
    }

    #[test]
    fn noise_is_zero_on_the_lattice_and_bounded_between() {
        let mut most = 0.0f64;
        for p in sample(200_000) {
            let n = noise(p, 7);
            assert!(n.is_finite());
            most = most.max(n.abs());
            assert_eq!(noise(p.floor(), 7), 0.0);
        }
        assert!(most <= NOISE_RANGE && most > 0.8, "{most}");
    }

    #[test]
    fn noise_is_continuous_and_depends_on_the_seed() {
        let p = DVec3::new(3.3, -1.7, 0.45);
        let step = DVec3::splat(1e-4);
        assert!((noise(p, 1) - noise(p + step, 1)).abs() < 1e-3);
        assert_ne!(noise(p, 1), noise(p, 2));
    }

    /// The analytic gradient agrees with central differences.
    #[test]
    fn gradient_is_the_derivative() {
        let h = 1e-6;
        for p in sample(2000) {
            let (_, g) = noise_gradient(p, 3);
            for a in 0..3 {
                let mut e = DVec3::ZERO;
                e[a] = h;
                let fd = (noise(p + e, 3) - noise(p - e, 3)) / (2.0 * h);
                assert!((fd - g[a]).abs() < 1e-5, "{p} axis {a}: {fd} vs {}", g[a]);
            }
        }
    }

    /// [`NOISE_SLOPE`] is above the steepest slope found, by its stated margin: the
    /// steepest of a dense sample, then climbed from the steepest points.
    #[test]
    fn slope_is_bounded() {
        let mut best: Vec<(f64, DVec3)> = sample(300_000).map(|p| (noise_gradient(p, 11).1.length(), p)).collect();
        best.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut most = best[0].0;
        for &(_, start) in best.iter().take(40) {
            let (mut p, mut v, mut step) = (start, noise_gradient(start, 11).1.length(), 0.01);
            for k in 0..3000u64 {
                let d = DVec3::new(unit(k * 3) - 0.5, unit(k * 3 + 1) - 0.5, unit(k * 3 + 2) - 0.5) * step;
                let w = noise_gradient(p + d, 11).1.length();
                if w > v {
                    (v, p) = (w, p + d);
                } else if k % 200 == 199 {
                    step *= 0.7;
                }
            }
            most = most.max(v);
        }
        assert!(most * 1.25 <= NOISE_SLOPE, "steepest slope found {most}");
        assert!(most > 3.3, "the search reaches the steepest parts: {most}");
    }
}
