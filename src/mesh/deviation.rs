//! How far a mesh lies from the surface it was made of, measured on every triangle: at
//! its corners, its edges' midpoints, its centroid and three points inside.
//!
//! A distance bound's `|f|` only says how near the surface *cannot* be. What bounds the
//! distance from above is a sign change: a sample `p` lies within `t` of the surface
//! when `f` changes sign between `p` and a point `t` away, so each sample is probed
//! towards the surface along the triangle's normal, then along the field's gradient,
//! and within `t` is proved, not estimated. The distance reported is where the field's
//! linear interpolant between the two points crosses zero (exact for a distance field
//! whose surface is flat there): an estimate, inside the proved bracket.

use glam::DVec3;
use rayon::prelude::*;

use super::samples::IsoField;
use crate::geom::TriMesh;

/// Probes farther than the tolerance (doubling) before a sample is called unresolved.
const REACH_DOUBLINGS: i32 = 6;

/// The measured deviation of a mesh from its surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeasuredDeviation {
    /// The largest distance found from a sample to the surface.
    pub max: f64,
    /// The mean distance over the samples.
    pub mean: f64,
    /// Points probed.
    pub samples: usize,
    /// Samples not proved within their tolerance (the unresolved among them).
    pub over: usize,
    /// Samples where no sign change was found within 64 tolerances along the directions
    /// probed (a pinch where the gradient vanishes): their distance is not known, and
    /// they are left out of `max` and `mean`.
    pub unresolved: usize,
    /// Triangles proved within the tolerance everywhere, not only at their samples.
    pub proved: usize,
}

/// What a measurement found: the figures, and the triangles and vertices with a sample
/// found farther than its tolerance.
pub struct Found {
    /// The figures.
    pub measured: MeasuredDeviation,
    /// Triangles with a sample over its tolerance, each with its largest sample's
    /// distance over that tolerance (above 1).
    pub triangles: Vec<(u32, f64)>,
    /// Vertices over their tolerance, likewise.
    pub vertices: Vec<(u32, f64)>,
}

/// One probe's result: whether the surface lies within the tolerance, the distance
/// estimated, a proved upper bound on it, and whether a sign change was found at all.
#[derive(Clone, Copy)]
struct Probe {
    within: bool,
    distance: f64,
    bound: f64,
    found: bool,
}

/// How far `p` lies from the surface of `field`, looking along `normal` and then the
/// gradient, against the tolerance `t`; a bracket found within `t` is halved `halvings`
/// times for a tighter proved bound.
///
/// Long because it is one search in widening steps, each returning as soon as it finds a
/// sign change: the two directions, Newton steps into a crease's wedge, a star of
/// directions, and farther along the first two.
fn probe(field: IsoField, p: DVec3, normal: DVec3, t: f64, halvings: u32) -> Probe {
    let v = field.at(p);
    if v == 0.0 || !v.is_finite() {
        let on = v == 0.0;
        return Probe { within: on, distance: 0.0, bound: if on { 0.0 } else { f64::INFINITY }, found: on };
    }
    let towards = -v.signum();
    let at = |dir: DVec3, s: f64| field.at(p + dir * (towards * s));
    // The bracket [0, reach] along `dir` whose far end has the value `f_far` of the other
    // sign, halved until it is at most `t` wide (and `extra` times more): the proved bound
    // is its far end, the estimate where the linear interpolant in it is zero.
    let bracketed = |dir: DVec3, reach: f64, f_far: f64, extra: u32| {
        let (mut lo, mut f_lo, mut hi, mut f_hi) = (0.0, v, reach, f_far);
        let mut halved = 0;
        while hi - lo > t * 1.000_001 || halved < extra {
            let mid = 0.5 * (lo + hi);
            let fm = at(dir, mid);
            if fm * v > 0.0 {
                (lo, f_lo) = (mid, fm);
            } else {
                (hi, f_hi) = (mid, fm);
            }
            if hi - lo <= t * 1.000_001 {
                halved += 1;
            }
        }
        let estimate = lo + (hi - lo) * f_lo / (f_lo - f_hi);
        let distance = if estimate.is_finite() { estimate } else { hi };
        Probe { within: hi <= t * 1.000_001, distance, bound: hi, found: true }
    };
    // Opposite signs `reach` along `dir`: the surface lies between.
    let crosses = |dir: DVec3, reach: f64| {
        let f = at(dir, reach);
        (f * v <= 0.0).then(|| bracketed(dir, reach, f, halvings))
    };
    if let Some(found) = crosses(normal, t) {
        return found;
    }
    let gradient = field.normal(p);
    if let Some(found) = gradient.and_then(|g| crosses(g, t)) {
        return found;
    }
    // Where two surfaces meet at a crease (a `max` or `min` of fields), the solid beyond
    // it is a wedge that neither direction may enter: Newton steps, each overshooting
    // by half, alternate between the two sides' planes into it. The segment from `p` to
    // the first point of the other sign crosses the surface.
    let mut q = p;
    let far = t * 2f64.powi(REACH_DOUBLINGS);
    for step in 0..8 {
        let fq = if step == 0 { v } else { field.at(q) };
        if fq * v <= 0.0 {
            let reach = (q - p).length();
            let dir = (q - p) * (towards / reach);
            return bracketed(dir, reach, fq, halvings);
        }
        let g = (field.surf)(q.as_vec3a()).g.as_dvec3();
        let g2 = g.length_squared();
        if g2.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !fq.is_finite() {
            break;
        }
        q -= g * (1.5 * fq / g2);
        if (q - p).length() > far {
            break;
        }
    }
    // A wedge too thin for those steps: between the two normals, then every direction
    // to a cube's faces, edges and corners.
    let between = gradient.map(|g| (g + normal).normalize_or_zero()).into_iter();
    let star = (0..27)
        .filter(|&n| n != 13)
        .map(|n| DVec3::new((n % 3) as f64 - 1.0, (n / 3 % 3) as f64 - 1.0, (n / 9) as f64 - 1.0).normalize());
    for dir in between.chain(star) {
        if let Some(found) = crosses(dir, t) {
            return found;
        }
    }
    // Farther: the first doubling of the reach at which either direction crosses, the
    // crossing then bracketed to the tolerance.
    for k in 1..=REACH_DOUBLINGS {
        let reach = t * 2f64.powi(k);
        for dir in std::iter::once(normal).chain(gradient) {
            let f = at(dir, reach);
            if f * v <= 0.0 {
                return bracketed(dir, reach, f, 0);
            }
        }
    }
    Probe { within: false, distance: far, bound: f64::INFINITY, found: false }
}

/// How far `p` lies from the surface of `field`: the nearest sign change along `normal`,
/// the gradient and 27 other directions (between the two, and to a cube's faces, edges
/// and corners), looked for at a reach that starts at `|f(p)|` (nothing nearer can
/// change sign where `f` is a distance bound) and doubles up to 64 times `reach`, each
/// found bisected to a thousandth of the reach it was found at. Starting small matters at
/// a sharp edge of a thin part: every direction can step over its wedge at `reach`,
/// while a point on the edge is on the surface. Where the surface is locally flat the
/// nearest of those directions lies within about 20° of the true one, so this is at most
/// about 7 % over the distance, and never under the nearest crossing found. For
/// measuring a mesh made elsewhere; `None` when no sign change was found.
pub fn distance(field: IsoField, p: DVec3, normal: DVec3, reach: f64) -> Option<(f64, DVec3)> {
    let v = field.at(p);
    if v == 0.0 {
        return Some((0.0, normal));
    }
    if !v.is_finite() {
        return None;
    }
    let towards = -v.signum();
    let gradient = field.normal(p);
    let mut dirs = vec![normal];
    dirs.extend(gradient);
    dirs.extend(gradient.map(|g| (g + normal).normalize_or_zero()));
    dirs.extend(
        (0..27)
            .filter(|&n| n != 13)
            .map(|n| DVec3::new((n % 3) as f64 - 1.0, (n / 3 % 3) as f64 - 1.0, (n / 9) as f64 - 1.0).normalize()),
    );
    dirs.retain(|d| d.length_squared() > 0.0);
    let at = |dir: DVec3, s: f64| field.at(p + dir * (towards * s));
    let farthest = reach * 2f64.powi(REACH_DOUBLINGS);
    let mut r = v.abs().clamp(reach * 1e-9, farthest);
    loop {
        let nearest = dirs
            .iter()
            .filter_map(|&dir| crossing(&at, v, dir, r).map(|d| (d, dir)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((d, dir)) = nearest {
            return Some((d, towards * dir));
        }
        if r >= farthest {
            return None;
        }
        r = (2.0 * r).min(farthest);
    }
}

/// The first sign change of `at` along `dir` within `r` (its value `v` at 0), bisected
/// to a thousandth of `r`.
fn crossing(at: &dyn Fn(DVec3, f64) -> f64, v: f64, dir: DVec3, r: f64) -> Option<f64> {
    if at(dir, r) * v > 0.0 {
        return None;
    }
    let (mut lo, mut hi) = (0.0, r);
    while hi - lo > r * 1e-3 {
        let mid = 0.5 * (lo + hi);
        if at(dir, mid) * v > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

/// [`distance`]'s `d`, found along `dir`, brought nearer the true distance by a pattern
/// search over directions around it (steps of 0.2 rad halved down to 0.006): at a crease
/// or a thin wedge none of the fixed directions may point near the nearest point, and a
/// direction a few degrees off can reach twice as far. Still never under a crossing found.
pub fn nearer(field: IsoField, p: DVec3, d: f64, dir: DVec3) -> f64 {
    let v = field.at(p);
    if d == 0.0 || !v.is_finite() {
        return d;
    }
    let at = |dir: DVec3, s: f64| field.at(p + dir * s);
    let (mut d, mut dir) = (d, dir.normalize_or_zero());
    let mut step = 0.2f64;
    while step > 0.006 {
        let mut moved = 0;
        while moved < 16 {
            let (e1, e2) = dir.any_orthonormal_pair();
            let better = (0..8)
                .map(|k| {
                    let phi = std::f64::consts::FRAC_PI_4 * f64::from(k);
                    (dir + (e1 * phi.cos() + e2 * phi.sin()) * step.tan()).normalize()
                })
                .filter_map(|u| crossing(&at, v, u, d).map(|c| (c, u)))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .filter(|&(c, _)| c < d * (1.0 - 1e-3));
            let Some((c, u)) = better else { break };
            (d, dir) = (c, u);
            moved += 1;
        }
        step *= 0.5;
    }
    d
}

/// Halvings of a vertex's bracket: its proved bound within an eighth of the tolerance.
const VERTEX_HALVINGS: u32 = 3;

/// Measures `mesh` against `field`, each sample against `tolerance` at it.
///
/// Every vertex is probed and its bound proved to an eighth of the tolerance. A triangle
/// whose vertices' bounds plus its circumradius stay within the tolerance is within it
/// everywhere (the distance to a surface is 1-Lipschitz, and every point of a triangle
/// lies within its circumradius of a corner); the others are probed at their edges'
/// midpoints (each edge once), their centroids and three points inside.
///
/// Long because it is one measurement's passes over the vertices, the triangles and the
/// edges, each in parallel over arrays it sizes once.
pub fn measure(mesh: &TriMesh, field: IsoField, tolerance: &(dyn Fn(DVec3) -> f64 + Sync)) -> Found {
    let normals = vertex_normals(mesh);
    // Vertices no triangle uses are not part of the surface.
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let corners: Vec<Option<Probe>> = (0..mesh.positions.len())
        .into_par_iter()
        .map(|v| {
            let p = mesh.positions[v];
            used[v].then(|| probe(field, p, normals[v], tolerance(p), VERTEX_HALVINGS))
        })
        .collect();
    let bound = |v: u32| corners[v as usize].map_or(f64::INFINITY, |p| p.bound);
    // Triangles not proved whole by their corners.
    let open: Vec<u32> = (0..mesh.triangles.len() as u32)
        .into_par_iter()
        .filter(|&t| {
            let tri = mesh.triangles[t as usize];
            let [a, b, c] = tri.map(|i| mesh.positions[i as usize]);
            let reach = circumradius(a, b, c) + tri.iter().map(|&v| bound(v)).fold(0.0, f64::max);
            let t = tri.iter().map(|&v| tolerance(mesh.positions[v as usize])).fold(f64::INFINITY, f64::min);
            reach.partial_cmp(&t).is_none_or(|o| o == std::cmp::Ordering::Greater)
        })
        .collect();
    let normal = |t: u32| {
        let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.positions[i as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    };
    // Their edges, each once, with the triangles on them.
    let mut edges: Vec<((u32, u32), u32)> = open
        .par_iter()
        .flat_map_iter(|&t| {
            let tri = mesh.triangles[t as usize];
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                ((a.min(b), a.max(b)), t)
            })
        })
        .collect();
    edges.par_sort_unstable();
    let mut starts: Vec<usize> =
        (0..edges.len()).into_par_iter().filter(|&i| i == 0 || edges[i - 1].0 != edges[i].0).collect();
    starts.push(edges.len());
    let midpoints: Vec<(Probe, f64, u32, Option<u32>)> = starts
        .par_windows(2)
        .map(|w| {
            let ((a, b), t) = edges[w[0]];
            let other = (w[1] - w[0] > 1).then(|| edges[w[0] + 1].1);
            let n = (normal(t) + other.map_or(DVec3::ZERO, normal)).normalize_or_zero();
            let p = (mesh.positions[a as usize] + mesh.positions[b as usize]) * 0.5;
            let t_here = tolerance(p);
            (probe(field, p, n, t_here, 0), t_here, t, other)
        })
        .collect();
    // The centroid and the three points halfway from each corner to the opposite edge's
    // middle: where a triangle laid across a crease bulges farthest between its corners
    // and midpoints (the gyroid sheet's rim, `examples/deviation`).
    const INTERIOR: [[f64; 3]; 4] = [[1.0 / 3.0; 3], [0.5, 0.25, 0.25], [0.25, 0.5, 0.25], [0.25, 0.25, 0.5]];
    let centroids: Vec<(Probe, f64)> = open
        .par_iter()
        .flat_map_iter(|&t| {
            let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.positions[i as usize]);
            let n = normal(t);
            INTERIOR.iter().map(move |w| {
                let p = a * w[0] + b * w[1] + c * w[2];
                let t_here = tolerance(p);
                (probe(field, p, n, t_here, 0), t_here)
            })
        })
        .collect();

    let mut m = MeasuredDeviation { proved: mesh.triangles.len() - open.len(), ..MeasuredDeviation::default() };
    let mut sum = 0.0;
    let mut add = |p: &Probe| {
        m.samples += 1;
        m.over += usize::from(!p.within);
        if p.found {
            m.max = m.max.max(p.distance);
            sum += p.distance;
        } else {
            m.unresolved += 1;
        }
    };
    corners.iter().flatten().for_each(&mut add);
    midpoints.iter().for_each(|(p, ..)| add(p));
    centroids.iter().for_each(|(p, _)| add(p));
    let resolved = m.samples - m.unresolved;
    m.mean = if resolved > 0 { sum / resolved as f64 } else { 0.0 };
    let far = |p: &Probe| p.found && !p.within;
    let mut triangles: Vec<(u32, f64)> = open
        .iter()
        .flat_map(|t| std::iter::repeat_n(t, INTERIOR.len()))
        .zip(&centroids)
        .filter(|(_, (p, _))| far(p))
        .map(|(&t, (p, tol))| (t, p.distance / tol))
        .collect();
    for (p, tol, t, other) in &midpoints {
        if far(p) {
            triangles.push((*t, p.distance / tol));
            triangles.extend(other.map(|o| (o, p.distance / tol)));
        }
    }
    triangles.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
    triangles.dedup_by_key(|t| t.0);
    let vertices = (0..corners.len() as u32)
        .filter_map(|v| {
            let p = corners[v as usize].filter(far)?;
            let tol = tolerance(mesh.positions[v as usize]);
            Some((v, p.distance / tol))
        })
        .collect();
    Found { measured: m, triangles, vertices }
}

/// The circumradius of a triangle: no point of it lies farther from its nearest corner.
fn circumradius(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, bc, ca) = ((b - a).length(), (c - b).length(), (a - c).length());
    let twice_area = (b - a).cross(c - a).length();
    if twice_area > 0.0 {
        ab * bc * ca / (2.0 * twice_area)
    } else {
        f64::INFINITY
    }
}

/// Area-weighted unit normals of a mesh's vertices.
fn vertex_normals(mesh: &TriMesh) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &v in t {
            n[v as usize] += face;
        }
    }
    n.into_iter().map(|v| v.normalize_or_zero()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sdf::Surf;
    use glam::Vec3A;

    /// An octahedron inscribed in the unit sphere lies up to 1 − 1/√3 inside it: its
    /// face centres are found that far, its corners on the surface.
    #[test]
    fn an_inscribed_octahedron_is_measured_from_its_sphere() {
        let dist = |p: Vec3A| p.length() - 1.0;
        let surf = |p: Vec3A| Surf { d: p.length() - 1.0, g: p.normalize_or_zero(), mat: 0 };
        let field = IsoField { dist: &dist, surf: &surf };
        let mesh = TriMesh {
            positions: vec![DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z],
            triangles: vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
        };
        let loose = measure(&mesh, field, &|_| 0.5);
        let deepest = 1.0 - 1.0 / 3f64.sqrt();
        assert!((loose.measured.max - deepest).abs() < 1e-6, "{:?}", loose.measured);
        assert_eq!(loose.measured.over, 0);
        // The corners, then (the triangles' circumradius, 0.82, being over the
        // tolerance) the twelve edges' midpoints and the eight faces' four inner points.
        assert_eq!(loose.measured.samples, 6 + 12 + 8 * 4);
        assert_eq!(loose.measured.proved, 0);
        let tight = measure(&mesh, field, &|_| 0.3);
        // Every face's centre and its three other inner points (0.39 deep; an edge's
        // midpoint is 1 − 1/√2 = 0.29 deep, within).
        assert_eq!(tight.measured.over, 8 * 4);
        assert_eq!(tight.triangles.len(), 8);
        // Found by a Newton step, estimated on the segment to it: the centroid's depth.
        let depth = 1.0 - 1.0 / 3f64.sqrt();
        assert!(tight.triangles.iter().all(|&(_, r)| (r - depth / 0.3).abs() < 1e-6), "{:?}", tight.triangles);
        assert!(tight.vertices.is_empty());
        // With a tolerance over the circumradius every triangle is proved by its corners.
        let wide = measure(&mesh, field, &|_| 0.9);
        assert_eq!((wide.measured.proved, wide.measured.samples), (8, 6));
    }
}
