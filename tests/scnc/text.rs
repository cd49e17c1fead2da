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
