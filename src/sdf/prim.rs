//! The smooth minimum that blends CSG seams. (Primitives' distances live with the
//! primitives, in [`crate::primitive`].)

/// Polynomial smooth minimum (radius `k` > 0). It is 1-Lipschitz when `a` and `b` are:
/// in the blend its gradient is a convex combination of theirs.
#[inline]
pub fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// [`smin`] and the share of `b` in its gradient, `∂smin/∂b` (that of `a` is one less
/// it): the blend `h/2` towards the higher of the two, `1 − h/2` towards the lower.
#[inline]
pub fn smin_weighted(a: f32, b: f32, k: f32) -> (f32, f32) {
    let h = (k - (a - b).abs()).max(0.0) / k;
    let w = if b < a { 1.0 - h * 0.5 } else { h * 0.5 };
    (a.min(b) - h * h * k * 0.25, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift), so failures reproduce.
    struct Rng(u64);

    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn smooth_min_is_below_min_and_lipschitz() {
        let mut rng = Rng(42);
        for _ in 0..10_000 {
            let (a, b, k) = (rng.f() * 4.0 - 2.0, rng.f() * 4.0 - 2.0, rng.f() + 0.01);
            let (da, db) = (rng.f() * 0.1 - 0.05, rng.f() * 0.1 - 0.05);
            let s = smin(a, b, k);
            assert!(s <= a.min(b) + 1e-6);
            assert!(s >= a.min(b) - k * 0.25 - 1e-6);
            // |Δsmin| ≤ max(|Δa|, |Δb|).
            assert!((smin(a + da, b + db, k) - s).abs() <= da.abs().max(db.abs()) + 1e-5);
            // The weight is the slope in `b` (a central difference, away from the kinks).
            let (v, w) = smin_weighted(a, b, k);
            assert_eq!(v, s);
            let e = 1e-3;
            if ((a - b).abs() - k).abs() > 2.0 * e && (a - b).abs() > 2.0 * e {
                let slope = (smin(a, b + e, k) - smin(a, b - e, k)) / (2.0 * e);
                assert!((slope - w).abs() < 1e-2, "∂smin/∂b at {a}, {b}, {k}: {slope} vs {w}");
            }
        }
    }
}
