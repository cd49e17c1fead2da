//! The smooth minimum that blends CSG seams. (Primitives' distances live with the
//! primitives, in [`crate::primitive`].)

/// Polynomial smooth minimum (radius `k` > 0). It is 1-Lipschitz when `a` and `b` are:
/// in the blend its gradient is a convex combination of theirs.
#[inline]
pub fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
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
        }
    }
}
