//! What `render --stats` prints: rays by kind, work per ray, and memory by structure.

use scnc::source::SourceMap;
use scnc::trace::Counters;
use scnc::world::World;

/// The statistics of one render, for stderr.
///
/// Long because it is mostly one format string, a line per group of counters, laid out as
/// the output reads.
pub(crate) fn stats_text(c: &Counters, g: &World, map: &SourceMap, lower_s: f64, trace_s: f64) -> String {
    let mem = g.memory();
    let rays = c.rays().max(1) as f64;
    let mut out = format!(
        "stats:
  time            lower {:.3} s (tessellation and BVH builds), trace {:.3} s
  rays            {} primary, {} shadow, {} reflection, {} refraction, {} occlusion ({} total, {:.2} M/s)
  sdf evaluations {} marching ({:.1} per ray, max {} on one ray), {} for normals and materials
  primitives      {} evaluations ({:.1} per ray), inside those
  step budget     {} marches ran out of steps (counted as misses)
  ray trees       {} reflected or refracted rays pruned (below {:.4} of a pixel), {} samples at the {}-ray budget
  bvh             {} node visits ({:.2} per ray), {} triangle tests ({:.2} per ray)
  memory          {} bytes in total: {} SDF objects with {} bytes of closures, {} bytes of top-level BVH
",
        lower_s,
        trace_s,
        c.primary_rays,
        c.shadow_rays,
        c.reflection_rays,
        c.refraction_rays,
        c.occlusion_rays,
        c.rays(),
        c.rays() as f64 / trace_s.max(1e-9) / 1e6,
        c.sdf_evals,
        c.sdf_evals as f64 / rays,
        c.max_evals_per_ray,
        c.sdf_shading_evals,
        c.leaf_evals,
        c.leaf_evals as f64 / rays,
        c.budget_misses,
        c.pruned_rays,
        scnc::render::MIN_WEIGHT,
        c.tree_budget_hits,
        scnc::render::MAX_TREE_RAYS,
        c.node_visits,
        c.node_visits as f64 / rays,
        c.triangle_tests,
        c.triangle_tests as f64 / rays,
        mem.total(),
        mem.sdf_objects,
        mem.closure_bytes,
        mem.top_bvh_bytes,
    );
    if c.paths > 0 {
        let lengths: Vec<String> = c
            .path_lengths
            .iter()
            .enumerate()
            .filter(|(_, &n)| n > 0)
            .map(|(i, n)| {
                let last = i + 1 == scnc::trace::PATH_BINS;
                format!("{i}{}: {n}", if last { "+" } else { "" })
            })
            .collect();
        out.push_str(&format!(
            "  light transport {} paths ({:.1} samples per pixel), {} light (next-event) rays, {} bounce rays ({:.2} per path)
    surfaces met per path: {}
{}",
            c.paths,
            c.paths as f64 / c.path_pixels.max(1) as f64,
            c.light_rays,
            c.bounce_rays,
            c.bounce_rays as f64 / c.paths as f64,
            lengths.join(", "),
            if c.noise_pixels > 0 {
                format!(
                    "    estimated noise: {:.3} % mean relative standard error per pixel\n",
                    c.noise_ppm as f64 / c.noise_pixels as f64 / 1e4
                )
            } else {
                "    estimated noise: none (a pixel needs two samples for an estimate)\n".to_string()
            },
        ));
        if c.clamped_samples > 0 {
            out.push_str(&format!(
                "    clamped: {} samples scaled down to `clamp` ({:.3} % of paths; their excess light is lost)\n",
                c.clamped_samples,
                100.0 * c.clamped_samples as f64 / c.paths.max(1) as f64
            ));
        }
    }
    if c.segment_bounds > 0 {
        out.push_str(&format!(
            "  fields          {} bounds along stretches of rays ({:.1} per ray), for segment tracing\n",
            c.segment_bounds,
            c.segment_bounds as f64 / rays
        ));
    }
    if !mem.meshes.is_empty() {
        let tri = mem.triangles();
        let bytes = mem.mesh_bytes();
        out.push_str(&format!(
            "  meshes          {} objects, {} triangles, {} bytes ({:.1} bytes per triangle)\n",
            mem.meshes.len(),
            tri,
            bytes,
            bytes as f64 / tri.max(1) as f64
        ));
        for (span, m) in mem.meshes.iter().take(20) {
            let (id, r) = map.local_range(*span);
            let (line, _) = map.line_col(id, r.start);
            out.push_str(&format!(
                "    {}:{line}: {} triangles; vertices {} B, indices {} B, BVH {} B ({} nodes, depth {})",
                map.file(id).name,
                m.triangles,
                m.vertex_bytes,
                m.index_bytes,
                m.bvh_bytes,
                m.bvh_nodes,
                m.bvh_depth
            ));
            if let Some(iso) = m.isosurface {
                if iso.coarsest > iso.cell {
                    out.push_str(&format!("; isosurface cells {:.3e} to {:.3e}", iso.cell, iso.coarsest));
                } else {
                    out.push_str(&format!("; isosurface cell {:.3e}", iso.cell));
                }
                out.push_str(&format!(", farthest vertex {:.3e} ({:.3} cell)", iso.farthest, iso.farthest / iso.cell));
                if let Some(d) = iso.deviation {
                    out.push_str(&format!(
                        "; deviation from the surface max {:.3e}, mean {:.3e} ({} points sampled, {} of {} triangles proved)",
                        d.max, d.mean, d.samples, d.proved, m.triangles
                    ));
                }
            }
            out.push('\n');
        }
        if mem.meshes.len() > 20 {
            out.push_str(&format!("    … and {} more mesh objects\n", mem.meshes.len() - 20));
        }
    }
    out
}
