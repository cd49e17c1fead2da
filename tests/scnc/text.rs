//! `text(…)`: glyphs as a profile, exact on the SDF back-end and meshed from their
//! outlines, in the bundled font or a font file beside the scene.

use crate::support::{files, path, scene, scnc};

/// The signed area of the glyph of `c` in DejaVu Sans, in ems², read by ttf-parser and
/// the shoelace formula: an answer that shares no code with scnc's outlines.
fn straight_glyph_area(c: char) -> f64 {
    struct Shoelace {
        area: f64,
        start: (f64, f64),
        last: (f64, f64),
        curved: bool,
    }
    impl ttf_parser::OutlineBuilder for Shoelace {
        fn move_to(&mut self, x: f32, y: f32) {
            self.start = (f64::from(x), f64::from(y));
            self.last = self.start;
        }
        fn line_to(&mut self, x: f32, y: f32) {
            let to = (f64::from(x), f64::from(y));
            self.area += 0.5 * (self.last.0 * to.1 - to.0 * self.last.1);
            self.last = to;
        }
        fn quad_to(&mut self, _: f32, _: f32, _: f32, _: f32) {
            self.curved = true;
        }
        fn curve_to(&mut self, _: f32, _: f32, _: f32, _: f32, _: f32, _: f32) {
            self.curved = true;
        }
        fn close(&mut self) {
            let (x, y) = self.start;
            self.line_to(x as f32, y as f32);
        }
    }
    let face = ttf_parser::Face::parse(include_bytes!("../../assets/DejaVuSans.ttf"), 0).unwrap();
    let mut s = Shoelace { area: 0.0, start: (0.0, 0.0), last: (0.0, 0.0), curved: false };
    face.outline_glyph(face.glyph_index(c).unwrap(), &mut s).unwrap();
    assert!(!s.curved, "{c} has curves");
    let upem = f64::from(face.units_per_em());
    s.area.abs() / (upem * upem)
}

/// The mesh an export of `scene` writes at `tolerance`, read back.
fn exported(scene_text: &str, tolerance: &str) -> scnc::geom::TriMesh {
    let dir = files(&[("t.scn", scene_text.as_bytes())]);
    let out = dir.path().join("t.obj");
    let run = scnc(&["export", path(&dir.path().join("t.scn")), "-o", path(&out), "--tolerance", tolerance]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    scnc::meshfile::Format::Obj.read(&std::fs::read(&out).unwrap()).expect("reads")
}

/// Extruded text exports closed and manifold at every tolerance, as a prism per glyph:
/// all-straight glyphs (`H`, `I`) hold their outlines' area times the height (to the OBJ's
/// digits), and
/// curved ones (`o`, `g`, `@`) converge on it as the tolerance shrinks, from below (a
/// flattened convex arc cuts the corner), staying inside the interval `measure` proves.
#[test]
fn extruded_text_meshes_closed_with_the_glyphs_area() {
    let straight = exported("object extrude(text(\"HI\", size = 2), 0.25)\n", "0.01");
    assert_eq!(straight.open_edges(), (0, 0));
    let want = (straight_glyph_area('H') + straight_glyph_area('I')) * 4.0 * 0.5;
    // To the digits the OBJ prints (f32's).
    assert!((straight.signed_volume() - want).abs() < 1e-6 * want, "{} not {want}", straight.signed_volume());

    let curved = "object extrude(text(\"og@\\nHi\", size = 2), 0.25)\n";
    let mut volumes = Vec::new();
    for tolerance in ["0.01", "0.001", "0.0001"] {
        let m = exported(curved, tolerance);
        assert_eq!(m.open_edges(), (0, 0), "tolerance {tolerance}");
        volumes.push(m.signed_volume());
    }
    let changes = [(volumes[1] - volumes[0]).abs(), (volumes[2] - volumes[1]).abs()];
    assert!(changes[1] < changes[0] / 4.0, "converges: {volumes:?}");
    let dir = files(&[("t.scn", curved.as_bytes())]);
    let run = scnc(&["measure", path(&dir.path().join("t.scn")), "--cells", "2000000", "--message-format", "json"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let line = String::from_utf8_lossy(&run.stdout).lines().next().unwrap_or("").to_string();
    let m: serde_json::Value = serde_json::from_str(&line).unwrap();
    let (lo, hi) = (m["proved"]["volume"][0].as_f64().unwrap(), m["proved"]["volume"][1].as_f64().unwrap());
    assert!(lo <= volumes[2] && volumes[2] <= hi, "{} outside [{lo}, {hi}]", volumes[2]);
}

/// Seen head-on, both back-ends cover the same pixels but at the glyphs' edges, and the
/// counter of `o` is a hole in each: the ray through its middle misses.
#[test]
fn both_back_ends_draw_the_glyphs_with_their_holes() {
    use scnc::world::Mode;
    const SIZE: u32 = 96;
    let text = "camera(position = [0, 0, -4], look_at = [0, 0, 0])\nlight ambient(1)\n\
                object extrude(text(\"o\", size = 3, halign = \"center\", valign = \"center\"), 0.2) rotate [-90, 0, 0]\n";
    let s = scene(text);
    let sdf = crate::support::coverage(&s, Mode::Sdf, SIZE);
    let mesh = crate::support::coverage(&s, Mode::Mesh(scnc::mesh::Detail::High), SIZE);
    let centre = (SIZE / 2 * SIZE + SIZE / 2) as usize;
    assert!(!sdf[centre] && !mesh[centre], "the counter of o is open");
    let hits = sdf.iter().filter(|&&h| h).count();
    assert!(hits > (SIZE * SIZE / 16) as usize, "{hits}");
    let differing = sdf.iter().zip(&mesh).filter(|(a, b)| a != b).count();
    assert!(differing * 50 < hits, "{differing} of {hits} pixels differ");
}

/// A font file beside the scene lays out as the same font built in does; a missing
/// file, a file that is no font and an alignment word that is not one are coded errors
/// at their argument, and nothing is written.
#[test]
fn fonts_beside_the_scene_and_bad_fonts() {
    let font = std::fs::read("assets/DejaVuSans.ttf").unwrap();
    let scene_with = |font: &str| {
        format!(
            "camera(position = [1, 0.4, -3], look_at = [1, 0.4, 0])\nrender(width = 64, height = 32)\n\
             light ambient(1)\nobject extrude(text(\"Ab\"{font}), 0.1) rotate [-90, 0, 0]\n"
        )
    };
    let (built_in, beside) = (scene_with(""), scene_with(", font = \"fonts/mine.ttf\""));
    let bad = scene_with(", font = \"t.scn\"");
    let missing = scene_with(", font = \"nowhere.ttf\"");
    let dir = files(&[
        ("a.scn", built_in.as_bytes()),
        ("b.scn", beside.as_bytes()),
        ("fonts/mine.ttf", &font),
        ("t.scn", bad.as_bytes()),
        ("m.scn", missing.as_bytes()),
    ]);
    let render = |name: &str| {
        let out = dir.path().join(format!("{name}.png"));
        let run = scnc(&["render", path(&dir.path().join(name)), "-o", path(&out)]);
        (run, out)
    };
    let (a, a_png) = render("a.scn");
    let (b, b_png) = render("b.scn");
    assert!(a.status.success() && b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    assert_eq!(std::fs::read(a_png).unwrap(), std::fs::read(b_png).unwrap());
    for (name, says) in [("t.scn", "not a TrueType or OpenType font"), ("m.scn", "cannot read font `nowhere.ttf`")] {
        let (run, png) = render(name);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{err}");
        assert!(err.contains("E0602") && err.contains(says), "{err}");
        assert!(!png.exists());
    }
}

/// A glyph's distance at random points equals the distance to its outline flattened
/// densely and independently (ttf-parser's points, each quadratic at 2,000 points) within
/// 10⁻⁴ em, and its sign is the non-zero winding of those polygons, for glyphs with
/// holes, several contours and tight curves.
#[test]
fn glyph_distances_match_a_dense_flattening() {
    use glam::DVec2;
    use scnc::geom::font::{lay_out, HAlign, Layout, VAlign, DEFAULT_FONT};
    struct Dense {
        rings: Vec<Vec<DVec2>>,
        last: DVec2,
        scale: f64,
    }
    impl ttf_parser::OutlineBuilder for Dense {
        fn move_to(&mut self, x: f32, y: f32) {
            self.last = DVec2::new(f64::from(x), f64::from(y)) * self.scale;
            self.rings.push(vec![self.last]);
        }
        fn line_to(&mut self, x: f32, y: f32) {
            self.last = DVec2::new(f64::from(x), f64::from(y)) * self.scale;
            self.rings.last_mut().unwrap().push(self.last);
        }
        fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
            let (a, b) = (self.last, DVec2::new(f64::from(x1), f64::from(y1)) * self.scale);
            let c = DVec2::new(f64::from(x), f64::from(y)) * self.scale;
            for i in 1..=2000 {
                let t = f64::from(i) / 2000.0;
                let s = 1.0 - t;
                self.rings.last_mut().unwrap().push(a * (s * s) + b * (2.0 * s * t) + c * (t * t));
            }
            self.last = c;
        }
        fn curve_to(&mut self, _: f32, _: f32, _: f32, _: f32, _: f32, _: f32) {
            unreachable!("DejaVu Sans is TrueType");
        }
        fn close(&mut self) {}
    }
    let face = ttf_parser::Face::parse(DEFAULT_FONT, 0).unwrap();
    let layout = Layout { size: 1.0, halign: HAlign::Left, valign: VAlign::Baseline, spacing: 1.0, line_spacing: 1.0 };
    let mut rng = crate::support::Rng(0x7e47);
    for c in ['g', '@', 'B', '8', '&', 'ß'] {
        let outline = lay_out(DEFAULT_FONT, &c.to_string(), &layout).unwrap().outline.unwrap();
        let glyph = face.glyph_index(c).unwrap();
        let mut dense = Dense { rings: Vec::new(), last: DVec2::ZERO, scale: 1.0 / f64::from(face.units_per_em()) };
        face.outline_glyph(glyph, &mut dense).unwrap();
        // The layout starts the ink at u = 0.
        let shift = DVec2::new(f64::from(face.glyph_bounding_box(glyph).unwrap().x_min) * dense.scale, 0.0);
        let rings: Vec<Vec<DVec2>> = dense.rings.iter().map(|r| r.iter().map(|p| *p - shift).collect()).collect();
        let segment = |p: DVec2, a: DVec2, b: DVec2| {
            let d = b - a;
            let t = ((p - a).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
            (p - (a + d * t)).length()
        };
        for _ in 0..200 {
            let p =
                outline.min - 0.2 + DVec2::new(rng.f32() as f64, rng.f32() as f64) * (outline.max - outline.min + 0.4);
            let mut near = f64::INFINITY;
            let mut winding = 0;
            for r in &rings {
                for i in 0..r.len() {
                    let (a, b) = (r[i], r[(i + 1) % r.len()]);
                    near = near.min(segment(p, a, b));
                    if a.y <= p.y && p.y < b.y && (b - a).perp_dot(p - a) > 0.0 {
                        winding += 1;
                    } else if b.y <= p.y && p.y < a.y && (b - a).perp_dot(p - a) < 0.0 {
                        winding -= 1;
                    }
                }
            }
            let d = outline.nearest(p).d;
            assert!((d.abs() - near).abs() < 1e-4, "{c} at {p}: {d} against {near}");
            if near > 1e-3 {
                assert_eq!(d < 0.0, winding != 0, "{c} at {p}: sign");
            }
        }
    }
}
