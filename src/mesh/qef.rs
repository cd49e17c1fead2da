//! The quadric error function of dual contouring: the point nearest, in the least-squares
//! sense, to the tangent planes of a cell's surface crossings, so that a vertex lands on
//! the edge or corner where planes of different directions meet.
//!
//! Solved as in Ju et al. 2002 and Lindstrom 2000: relative to the mass point of the
//! crossings, through the eigen-decomposition of the 3×3 normal matrix with small
//! eigenvalues dropped. On a flat patch only the normal's direction is constrained and
//! the vertex stays at the mass point along the plane; on an edge two directions are;
//! at a corner all three. Dropping instead of inverting a near-zero eigenvalue is what
//! keeps nearly parallel planes from throwing the vertex far away.

use glam::{DMat3, DVec3};

/// Eigenvalues below this fraction of the largest are treated as zero.
const TRUNCATE: f64 = 0.05;

/// Accumulated tangent planes.
#[derive(Clone, Copy, Debug)]
pub struct Qef {
    /// Σ n nᵀ.
    ata: DMat3,
    /// Σ n (n · p).
    atb: DVec3,
    /// Σ p, for the mass point.
    sum: DVec3,
    count: u32,
}

impl Default for Qef {
    /// No planes. (Not derived: glam's default matrix is the identity.)
    fn default() -> Qef {
        Qef { ata: DMat3::ZERO, atb: DVec3::ZERO, sum: DVec3::ZERO, count: 0 }
    }
}

impl Qef {
    /// Adds the plane through `p` with unit normal `n`.
    pub fn add(&mut self, p: DVec3, n: DVec3) {
        self.ata += DMat3::from_cols(n * n.x, n * n.y, n * n.z);
        self.atb += n * n.dot(p);
        self.sum += p;
        self.count += 1;
    }

    /// The mass point: the mean of the crossings.
    pub fn mass_point(&self) -> DVec3 {
        self.sum / self.count.max(1) as f64
    }

    /// The minimiser nearest the mass point.
    pub fn solve(&self) -> DVec3 {
        let m = self.mass_point();
        let rhs = self.atb - self.ata * m;
        let (values, vectors) = eigen_symmetric(self.ata);
        let largest = values.abs().max_element();
        if largest <= 0.0 || !largest.is_finite() {
            return m;
        }
        // x − m = V Σ⁺ Vᵀ rhs, with Σ⁺ dropping the small eigenvalues.
        let mut offset = DVec3::ZERO;
        for k in 0..3 {
            let v = vectors.col(k);
            if values[k].abs() > TRUNCATE * largest {
                offset += v * (v.dot(rhs) / values[k]);
            }
        }
        m + offset
    }
}

/// Eigenvalues and eigenvectors (as columns) of a symmetric matrix, by cyclic Jacobi
/// rotations; a handful of sweeps converge to f64 precision for 3×3.
fn eigen_symmetric(a: DMat3) -> (DVec3, DMat3) {
    let mut m = a.to_cols_array_2d();
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _ in 0..12 {
        let off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
        if off <= 1e-30 * (m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2]) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if m[p][q] == 0.0 {
                continue;
            }
            // The rotation that zeroes m[p][q] (Golub & Van Loan, symmetric Schur).
            let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← A·J (columns p and q of every row), then A ← Jᵀ·A (rows p and q).
            for row in m.iter_mut() {
                let (mkp, mkq) = (row[p], row[q]);
                row[p] = c * mkp - s * mkq;
                row[q] = s * mkp + c * mkq;
            }
            let (rp, rq) = (m[p], m[q]);
            for k in 0..3 {
                m[p][k] = c * rp[k] - s * rq[k];
                m[q][k] = s * rp[k] + c * rq[k];
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // `v` holds the rotations applied to the rows of the identity: its rows index the
    // original coordinates, its columns the eigenvectors, so read it transposed.
    let vectors = DMat3::from_cols_array_2d(&v).transpose();
    (DVec3::new(m[0][0], m[1][1], m[2][2]), vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decomposition reproduces the matrix.
    #[test]
    fn eigen_decomposition_reconstructs() {
        let a = DMat3::from_cols_array(&[4.0, 1.0, -2.0, 1.0, 3.0, 0.5, -2.0, 0.5, 5.0]);
        let (values, vectors) = eigen_symmetric(a);
        let back = vectors * DMat3::from_diagonal(values) * vectors.transpose();
        for (x, y) in back.to_cols_array().iter().zip(a.to_cols_array()) {
            assert!((x - y).abs() < 1e-9, "{back} vs {a}");
        }
    }

    /// Three planes meeting at a box corner give the corner; two give a point on their
    /// edge nearest the mass point; parallel planes give the mass point's projection.
    #[test]
    fn planes_meet_at_corners_and_edges() {
        let corner = DVec3::new(1.0, 2.0, 3.0);
        let mut q = Qef::default();
        q.add(corner + DVec3::new(0.0, -0.3, -0.2), DVec3::X);
        q.add(corner + DVec3::new(-0.1, 0.0, -0.4), DVec3::Y);
        q.add(corner + DVec3::new(-0.3, -0.2, 0.0), DVec3::Z);
        assert!((q.solve() - corner).length() < 1e-9, "{}", q.solve());

        let mut q = Qef::default();
        q.add(DVec3::new(1.0, 0.2, 0.5), DVec3::X);
        q.add(DVec3::new(0.7, 1.0, 0.1), DVec3::Y);
        let x = q.solve();
        assert!((x - DVec3::new(1.0, 1.0, 0.3)).length() < 1e-9, "{x}");

        let mut q = Qef::default();
        q.add(DVec3::new(0.0, 0.0, 1.0), DVec3::Z);
        q.add(DVec3::new(1.0, 0.0, 1.0), DVec3::Z);
        // Nearly parallel: the small eigenvalue is dropped, not inverted.
        q.add(DVec3::new(0.5, 1.0, 1.0), DVec3::new(0.001, 0.0, 1.0).normalize());
        let x = q.solve();
        assert!((x - DVec3::new(0.5, 1.0 / 3.0, 1.0)).length() < 1e-3, "{x}");
    }
}
