//! Triangles that lose their area in the 32-bit coordinates every format writes, removed
//! without opening the surface. Dropping one opens a crack: its edges were shared with
//! neighbours (lib3mf then calls the object invalid, `--stats` finds open edges). So a
//! triangle with two corners that round to one point has that edge collapsed (the
//! corners welded, as a mesher would), and a cap — three distinct corners on a line —
//! is removed by splitting the neighbour across its long edge at the middle corner, the
//! standard cap removal (Botsch et al., *Polygon Mesh Processing*, 2010, §6.2).
//! Corners an ulp or two apart (`NEAR_ULPS`) are welded like coincident ones: the needle
//! between them has area, but not a facing a 32-bit reader agrees on.

use std::collections::HashMap;

use glam::Vec3;

/// What [`mend`] did.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Mended {
    /// Triangles removed (collapsed, or caps whose neighbour was split).
    pub removed: usize,
    /// Zero-area triangles that had to be dropped as they were (a cap on an open edge, or
    /// past the round limit): each may leave an open edge.
    pub dropped: usize,
}

/// How near, in units of the last place of the corners' largest coordinate, two corners
/// of a triangle count as one point. The isosurface mesher can put two feature vertices
/// a rounding apart (a box corner on a cell's face, reached from both sides); in f32 they
/// land an ulp or so apart and the needle between them has a normal no 32-bit reader
/// recomputes alike (admesh "fixed" one half an ulp of its largest coordinate wide).
/// Welding moves a corner by at most this. Legitimate needles stay: the poles of a sphere
/// at `--detail 2048` have edges about 20 ulps long.
const NEAR_ULPS: f64 = 2.0;

/// Whether a triangle of these corners has no area.
fn flat(p: &[Vec3], t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|i| p[i as usize]);
    (b - a).cross(c - a).length_squared() == 0.0
}

/// The edge (k, k+1) of `t` whose ends are [`NEAR_ULPS`] apart or nearer, if any.
fn needle(p: &[Vec3], t: [u32; 3]) -> Option<usize> {
    let q = t.map(|i| p[i as usize].as_dvec3());
    let scale = q.iter().map(|v| v.abs().max_element()).fold(0.0, f64::max);
    let near = NEAR_ULPS * f64::from(f32::EPSILON) * scale;
    let len = |k: usize| (q[(k + 1) % 3] - q[k]).length();
    let short = (0..3).min_by(|&x, &y| len(x).total_cmp(&len(y)))?;
    (len(short) <= near).then_some(short)
}

/// Mends `triangles` over the 32-bit corners `p` (`tag` holds a value per triangle
/// that a split copies, its material). Vertices may be left unused.
///
/// Long because mending is one pipeline over shared index arrays (weld, drop degenerate
/// triangles, split non-manifold edges, orient); its stages share state that splitting
/// would pass around.
pub fn mend(p: &[Vec3], triangles: &mut Vec<[u32; 3]>, tag: &mut Vec<u32>) -> Mended {
    let mut out = Mended::default();
    if !triangles.iter().any(|&t| flat(p, t) || needle(p, t).is_some()) {
        return out;
    }
    // Weld the ends of a needle's short edge (corners that round to one point, or so
    // near that no 32-bit reader can tell the triangle's facing).
    let mut root: Vec<u32> = (0..p.len() as u32).collect();
    fn find(root: &mut [u32], mut i: u32) -> u32 {
        while root[i as usize] != i {
            root[i as usize] = root[root[i as usize] as usize];
            i = root[i as usize];
        }
        i
    }
    for &t in triangles.iter() {
        let short = needle(p, t);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b && (p[a as usize] == p[b as usize] || short == Some(k)) {
                let (ra, rb) = (find(&mut root, a), find(&mut root, b));
                root[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    let (mut kept, mut kept_tag) = (Vec::with_capacity(triangles.len()), Vec::with_capacity(tag.len()));
    for (&t, &m) in triangles.iter().zip(tag.iter()) {
        let t = t.map(|i| find(&mut root, i));
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            out.removed += 1;
        } else {
            kept.push(t);
            kept_tag.push(m);
        }
    }
    // Caps: split the neighbour across the long edge. A split can make a new cap (its
    // far corner on the line too), so this goes round a bounded number of times.
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for (i, t) in kept.iter().enumerate() {
        for k in 0..3 {
            edges.insert((t[k], t[(k + 1) % 3]), i);
        }
    }
    let mut alive = vec![true; kept.len()];
    let mut work: Vec<usize> = (0..kept.len()).filter(|&i| flat(p, kept[i])).collect();
    // Bounded by the triangles there were at the start: every split adds one, so a bound
    // on the growing count could be chased for ever (a disc of radius 1e-12 extruded,
    // all of whose caps are flat in f32, was).
    let (mut rounds, most) = (0, 4 * kept.len());
    while let Some(i) = work.pop() {
        if !alive[i] || !flat(p, kept[i]) {
            continue;
        }
        rounds += 1;
        let t = kept[i];
        // The middle corner is the one opposite the longest edge.
        let len = |k: usize| (p[t[(k + 1) % 3] as usize] - p[t[k] as usize]).length_squared();
        let long = (0..3).max_by(|&x, &y| len(x).total_cmp(&len(y))).unwrap_or(0);
        let (a, c, b) = (t[long], t[(long + 1) % 3], t[(long + 2) % 3]);
        // The neighbour holds the long edge the other way round: (c, a, d).
        let neighbour = edges.get(&(c, a)).copied().filter(|&n| alive[n] && n != i);
        let Some(n) = neighbour.filter(|_| rounds <= most) else {
            alive[i] = false;
            out.dropped += 1;
            continue;
        };
        let nt = kept[n];
        let k = (0..3).find(|&k| nt[k] == c).unwrap_or(0);
        let d = nt[(k + 2) % 3];
        if d == b {
            // Two flat triangles back to back: both go, and their outer edges meet.
            alive[i] = false;
            alive[n] = false;
            out.removed += 2;
            continue;
        }
        alive[i] = false;
        out.removed += 1;
        for k in 0..3 {
            edges.remove(&(t[k], t[(k + 1) % 3]));
            edges.remove(&(nt[k], nt[(k + 1) % 3]));
        }
        // (c, a, d) becomes (c, b, d) and (b, a, d): b was on the line c–a.
        kept[n] = [c, b, d];
        kept.push([b, a, d]);
        kept_tag.push(kept_tag[n]);
        alive.push(true);
        for j in [n, kept.len() - 1] {
            let t = kept[j];
            for k in 0..3 {
                edges.insert((t[k], t[(k + 1) % 3]), j);
            }
            if flat(p, t) {
                work.push(j);
            }
        }
    }
    *triangles = kept.iter().zip(&alive).filter(|(_, &a)| a).map(|(t, _)| *t).collect();
    *tag = kept_tag.iter().zip(&alive).filter(|(_, &a)| a).map(|(m, _)| *m).collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every directed edge has its reverse exactly once: closed and consistently wound.
    fn closed(t: &[[u32; 3]]) -> bool {
        let mut e: HashMap<(u32, u32), i32> = HashMap::new();
        for t in t {
            for k in 0..3 {
                *e.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        e.iter().all(|(&(a, b), &n)| n == 1 && e.get(&(b, a)) == Some(&1))
    }

    /// A tetrahedron whose bottom face is split at a fifth vertex `mid` on its edge 0–1,
    /// closed by the flat triangle 0 4 1 (what rounding leaves when `mid` lands on the
    /// line, or on corner 1).
    fn tetrahedron_with(mid: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
            mid,
        ];
        let t = vec![[0, 2, 4], [4, 2, 1], [0, 4, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        (p, t)
    }

    #[test]
    fn a_cap_is_removed_by_splitting_its_neighbour_and_the_surface_stays_closed() {
        // 4 in the middle of 0–1: dropping the cap 0 4 1 would open 0→1 (held by 0 1 3).
        let (p, mut t) = tetrahedron_with(Vec3::new(1.0, 0.0, 0.0));
        assert!(closed(&t));
        let mut tag = vec![7; t.len()];
        let m = mend(&p, &mut t, &mut tag);
        assert_eq!(m, Mended { removed: 1, dropped: 0 });
        assert!(closed(&t), "{t:?}");
        assert!(t.iter().all(|&t| !flat(&p, t)));
        assert_eq!(t.len(), tag.len());
    }

    #[test]
    fn corners_that_round_together_are_welded() {
        // 4 at vertex 1's position: 0 4 1 has two corners at one point.
        let (p, mut t) = tetrahedron_with(Vec3::new(2.0, 0.0, 0.0));
        let mut tag = vec![0; t.len()];
        let m = mend(&p, &mut t, &mut tag);
        assert_eq!(m.dropped, 0);
        assert!(closed(&t), "{t:?}");
        assert!(t.iter().all(|&t| !flat(&p, t)));
    }

    #[test]
    fn corners_ulps_apart_are_welded_and_near_ones_kept() {
        // 4 an ulp beside corner 1: 0 4 1 and 4 2 1 have a short edge no 32-bit reader
        // orients (the isosurface mesher put two feature vertices there).
        let (p, mut t) = tetrahedron_with(Vec3::new(2.0, 2.0 * f32::EPSILON, 0.0));
        let mut tag = vec![0; t.len()];
        let m = mend(&p, &mut t, &mut tag);
        assert_eq!(m, Mended { removed: 2, dropped: 0 });
        assert!(closed(&t), "{t:?}");
        assert!(t.iter().all(|&t| !flat(&p, t)));
        // A corner a hundred thousandth from another is kept.
        let (p, mut t) = tetrahedron_with(Vec3::new(2.0, 1e-5, 0.0));
        let before = t.clone();
        assert_eq!(mend(&p, &mut t, &mut vec![0; 6]), Mended::default());
        assert_eq!(t, before);
    }

    /// A needle: a disc of radius 1e-12 extruded, every cap triangle flat in f32. Each
    /// split makes another flat triangle, so mending must stop by its bound (it once
    /// chased a bound that grew with every split, for ever) and drop what is left.
    #[test]
    fn a_needle_of_flat_triangles_is_mended_in_bounded_rounds() {
        let disc = crate::geom::region::Region::Circle { centre: glam::DVec2::ZERO, r: 1e-12 };
        let m = crate::geom::region::extrusion(&disc, 0.5, 50).expect("a needle");
        let p: Vec<Vec3> = m.positions.iter().map(|q| q.as_vec3()).collect();
        let (mut t, mut tag) = (m.triangles.clone(), vec![0; m.triangles.len()]);
        let before = t.len();
        let mended = mend(&p, &mut t, &mut tag);
        assert!(mended.removed + mended.dropped > 0 && t.len() <= 5 * before, "{mended:?}, {} left", t.len());
        assert!(t.iter().all(|&t| !flat(&p, t)));
    }
}
