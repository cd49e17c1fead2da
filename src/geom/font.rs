//! Text laid out in a TrueType or OpenType font as an [`Outline`]: the font's units per
//! em scaled to `size`, each line's first glyph's ink starting at `u = 0`, the first
//! line's baseline at `v = 0` (POV-Ray's `text` layout), advances times `spacing`, pairs kerned from the font's
//! `kern` table, `\n` starting a line `line_spacing` times the font's line height below.
//! TrueType's quadratics are kept as they are; CFF's cubics become quadratics within
//! [`CUBIC_TOLERANCE_EM`] of them.

use glam::DVec2;
use ttf_parser::{Face, GlyphId, OutlineBuilder};

use super::outline::{Contour, Outline, Seg};

/// The font `text` uses when none is named: DejaVu Sans (`assets/LICENSE-DejaVu.txt`).
pub const DEFAULT_FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The default font's name, as diagnostics give it.
pub const DEFAULT_FONT_NAME: &str = "DejaVu Sans";

/// How far a cubic's quadratics may stray from it, in ems.
pub const CUBIC_TOLERANCE_EM: f64 = 1e-5;

/// Most characters one `text` lays out.
pub const MAX_CHARS: usize = 10_000;

/// Most segments one `text` may have once laid out (its distance reads the nearby ones).
pub const MAX_SEGMENTS: usize = 1_000_000;

/// Where the text sits across `u`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HAlign {
    /// Each line's ink starts at `u = 0`.
    Left,
    /// Each line's advance is centred on `u = 0`.
    Center,
    /// Each line ends at `u = 0`.
    Right,
}

/// Where the text sits across `v`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VAlign {
    /// The first line's baseline at `v = 0`.
    Baseline,
    /// The top of the ink at `v = 0`.
    Top,
    /// The middle of the ink at `v = 0`.
    Center,
    /// The bottom of the ink at `v = 0`.
    Bottom,
}

/// How text is laid out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// The em, in scene units.
    pub size: f64,
    /// Across `u`.
    pub halign: HAlign,
    /// Across `v`.
    pub valign: VAlign,
    /// Factor on each glyph's advance.
    pub spacing: f64,
    /// Factor on the font's line height.
    pub line_spacing: f64,
}

/// Why text could not be laid out: the font's fault, or the string's.
#[derive(Debug, PartialEq)]
pub enum LayoutError {
    /// The bytes are no font this reads.
    Font(String),
    /// The text is past a limit.
    Text(String),
}

impl std::fmt::Display for LayoutError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LayoutError::Font(why) | LayoutError::Text(why) => f.write_str(why),
        }
    }
}

/// Laid-out text.
#[derive(Debug)]
pub struct Laid {
    /// The glyphs' outline; `None` when nothing is drawn (spaces only).
    pub outline: Option<Outline>,
    /// Characters the font has no glyph for (drawn as its missing-glyph box), each once.
    pub missing: Vec<char>,
    /// The font's family name, if it states one.
    pub family: Option<String>,
}

/// Collects a glyph's contours in font units, moved to the pen by `at`.
struct Pen<'a> {
    at: &'a dyn Fn(f64, f64) -> DVec2,
    contours: Vec<Contour>,
    current: Contour,
    start: DVec2,
    last: DVec2,
    tolerance: f64,
}

impl<'a> Pen<'a> {
    /// A pen placing points by `at`, turning cubics into quadratics within `tolerance`.
    fn new(at: &'a dyn Fn(f64, f64) -> DVec2, tolerance: f64) -> Pen<'a> {
        Pen { at, contours: Vec::new(), current: Vec::new(), start: DVec2::ZERO, last: DVec2::ZERO, tolerance }
    }

    fn finish(&mut self) {
        if self.last != self.start {
            self.current.push(Seg::Line(self.last, self.start));
        }
        if !self.current.is_empty() {
            self.contours.push(std::mem::take(&mut self.current));
        }
        self.last = self.start;
    }

    /// A cubic as quadratics: the single quadratic `(3(p1 + p2) − p0 − p3) / 4` strays at
    /// most `√3/36 · |p3 − 3p2 + 3p1 − p0|` from it; halves until that is within tolerance.
    fn cubic(&mut self, p: [DVec2; 4], depth: u32) {
        let error = 3f64.sqrt() / 36.0 * (p[3] - 3.0 * p[2] + 3.0 * p[1] - p[0]).length();
        if error <= self.tolerance || depth >= 16 {
            let control = (3.0 * (p[1] + p[2]) - p[0] - p[3]) / 4.0;
            self.current.push(Seg::Quad(p[0], control, p[3]));
            return;
        }
        let (a, b, c) = (p[0].lerp(p[1], 0.5), p[1].lerp(p[2], 0.5), p[2].lerp(p[3], 0.5));
        let (ab, bc) = (a.lerp(b, 0.5), b.lerp(c, 0.5));
        let mid = ab.lerp(bc, 0.5);
        self.cubic([p[0], a, ab, mid], depth + 1);
        self.cubic([mid, bc, c, p[3]], depth + 1);
    }
}

impl OutlineBuilder for Pen<'_> {
    fn move_to(&mut self, x: f32, y: f32) {
        self.finish();
        self.start = (self.at)(f64::from(x), f64::from(y));
        self.last = self.start;
    }

    fn line_to(&mut self, x: f32, y: f32) {
        let to = (self.at)(f64::from(x), f64::from(y));
        if to != self.last {
            self.current.push(Seg::Line(self.last, to));
        }
        self.last = to;
    }

    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        let (b, to) = ((self.at)(f64::from(x1), f64::from(y1)), (self.at)(f64::from(x), f64::from(y)));
        self.current.push(Seg::Quad(self.last, b, to));
        self.last = to;
    }

    fn curve_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        let at = |x: f32, y: f32| (self.at)(f64::from(x), f64::from(y));
        let p = [self.last, at(x1, y1), at(x2, y2), at(x, y)];
        self.cubic(p, 0);
        self.last = p[3];
    }

    fn close(&mut self) {
        self.finish();
    }
}

/// The advance adjustment of the first glyph of the pair `l`, `r` in the font's GPOS
/// `kern` feature (pair adjustment lookups, by glyph pair or by class), in font units.
fn gpos_kerning(face: &Face, l: GlyphId, r: GlyphId) -> Option<i16> {
    use ttf_parser::gpos::{PairAdjustment, PositioningSubtable};
    let table = face.tables().gpos?;
    let kern = ttf_parser::Tag::from_bytes(b"kern");
    for feature in table.features.into_iter().filter(|f| f.tag == kern) {
        for index in feature.lookup_indices {
            let Some(lookup) = table.lookups.get(index) else { continue };
            for sub in lookup.subtables.into_iter::<PositioningSubtable>() {
                let PositioningSubtable::Pair(pair) = sub else { continue };
                let found = match pair {
                    PairAdjustment::Format1 { coverage, sets } => {
                        coverage.get(l).and_then(|i| sets.get(i)).and_then(|set| set.get(r))
                    }
                    PairAdjustment::Format2 { coverage, classes, matrix } => {
                        coverage.contains(l).then(|| matrix.get((classes.0.get(l), classes.1.get(r)))).flatten()
                    }
                };
                if let Some((first, _)) = found {
                    return Some(first.x_advance);
                }
            }
        }
    }
    None
}

/// One glyph placed on a line.
struct Placed {
    glyph: GlyphId,
    /// The pen's `u` at its origin, before alignment.
    u: f64,
}

/// `text` laid out in the font `font` (the bytes of a TrueType or OpenType file).
///
/// Long because it is the layout in order: the face, each line's pen with its kerning,
/// the alignment of lines and of the whole, and the outlines.
pub fn lay_out(font: &[u8], text: &str, layout: &Layout) -> Result<Laid, LayoutError> {
    let face = Face::parse(font, 0).map_err(|e| LayoutError::Font(format!("not a TrueType or OpenType font ({e})")))?;
    let upem = f64::from(face.units_per_em());
    if upem <= 0.0 {
        return Err(LayoutError::Font("the font states no units per em".into()));
    }
    if text.chars().count() > MAX_CHARS {
        return Err(LayoutError::Text(format!("more than {MAX_CHARS} characters")));
    }
    let scale = layout.size / upem;
    let line_height =
        f64::from(i32::from(face.ascender()) - i32::from(face.descender()) + i32::from(face.line_gap())) * scale;
    let kern = face.tables().kern;
    // The `kern` table's pair first (POV-Ray reads that one), GPOS's `kern` feature for
    // a pair it lacks (the only kerning many OpenType fonts have).
    let kerning = |l: GlyphId, r: GlyphId| -> f64 {
        kern.and_then(|k| {
            k.subtables
                .into_iter()
                .filter(|s| s.horizontal && !s.variable && !s.has_cross_stream)
                .find_map(|s| s.glyphs_kerning(l, r))
        })
        .or_else(|| gpos_kerning(&face, l, r))
        .map_or(0.0, f64::from)
    };
    let mut missing = Vec::new();
    // Each line's glyphs, its advance, and its first glyph's ink start.
    let mut lines: Vec<(Vec<Placed>, f64, f64)> = Vec::new();
    for line in text.split('\n') {
        let mut pen = 0.0;
        let mut placed = Vec::new();
        let mut prev: Option<GlyphId> = None;
        for ch in line.chars().filter(|c| *c != '\r') {
            let glyph = face.glyph_index(ch).unwrap_or_else(|| {
                if !missing.contains(&ch) {
                    missing.push(ch);
                }
                GlyphId(0)
            });
            if let Some(p) = prev {
                pen += kerning(p, glyph) * scale;
            }
            placed.push(Placed { glyph, u: pen });
            pen += f64::from(face.glyph_hor_advance(glyph).unwrap_or(0)) * scale * layout.spacing;
            prev = Some(glyph);
        }
        let lead =
            placed.first().and_then(|g| face.glyph_bounding_box(g.glyph)).map_or(0.0, |b| f64::from(b.x_min) * scale);
        lines.push((placed, pen, lead));
    }
    let mut contours: Vec<(u32, Contour)> = Vec::new();
    let mut segments = 0usize;
    for (k, (placed, advance, lead)) in lines.iter().enumerate() {
        // As POV-Ray's `text`, a line starts where its first glyph's ink does.
        let width = advance - lead;
        let shift = -lead
            + match layout.halign {
                HAlign::Left => 0.0,
                HAlign::Center => -width / 2.0,
                HAlign::Right => -width,
            };
        let baseline = -(k as f64) * line_height * layout.line_spacing;
        for g in placed {
            let origin = DVec2::new(g.u + shift, baseline);
            let at = move |x: f64, y: f64| origin + DVec2::new(x, y) * scale;
            let mut pen = Pen::new(&at, CUBIC_TOLERANCE_EM * layout.size);
            if face.outline_glyph(g.glyph, &mut pen).is_some() {
                pen.finish();
            }
            let group = contours.last().map_or(0, |(i, _)| i + 1);
            for c in pen.contours {
                segments += c.len();
                contours.push((group, c));
            }
            if segments > MAX_SEGMENTS {
                return Err(LayoutError::Text(format!("more than {MAX_SEGMENTS} outline segments")));
            }
        }
    }
    let mut outline = Outline::new(contours, text.to_string());
    if let Some(o) = &mut outline {
        let dv = match layout.valign {
            VAlign::Baseline => 0.0,
            VAlign::Top => -o.max.y,
            VAlign::Center => -(o.min.y + o.max.y) / 2.0,
            VAlign::Bottom => -o.min.y,
        };
        o.translate(DVec2::new(0.0, dv));
    }
    let family = face
        .names()
        .into_iter()
        .find(|n| n.name_id == ttf_parser::name_id::FAMILY && n.is_unicode())
        .and_then(|n| n.to_string());
    Ok(Laid { outline, missing, family })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn laid(text: &str) -> Outline {
        let layout =
            Layout { size: 1.0, halign: HAlign::Left, valign: VAlign::Baseline, spacing: 1.0, line_spacing: 1.0 };
        lay_out(DEFAULT_FONT, text, &layout).expect("lays out").outline.expect("draws")
    }

    /// `A` and `V` kerned closer than their advances; `o` has a hole: its centre is
    /// outside the glyph though inside its box; `H` sits on the baseline, 0.729 em tall
    /// (DejaVu Sans's cap height, 1493 of 2048 units).
    #[test]
    fn kerning_holes_and_the_baseline() {
        let face = Face::parse(DEFAULT_FONT, 0).unwrap();
        let adv = |c: char| f64::from(face.glyph_hor_advance(face.glyph_index(c).unwrap()).unwrap()) / 2048.0;
        let av = laid("AV");
        assert!(av.min.x.abs() < 1e-12, "the ink starts at 0: {}", av.min.x);
        assert!(av.max.x < adv('A') + adv('V') - 0.01, "kerned: {}", av.max.x);
        let o = laid("o");
        let centre = (o.min + o.max) * 0.5;
        assert!(o.nearest(centre).d > 0.0, "the counter of o is a hole");
        assert!(o.nearest(DVec2::new(centre.x, o.min.y + 0.03)).d < 0.0, "its bowl is ink");
        let h = laid("H");
        assert!(h.min.y.abs() < 1e-12 && (h.max.y - 1493.0 / 2048.0).abs() < 1e-12, "{} .. {}", h.min.y, h.max.y);
    }

    /// GPOS's pair adjustments, read where a font has no `kern` table, agree with
    /// DejaVu's `kern` table (fontTools reads both: A V −131, W o −120, T o −348 units).
    #[test]
    fn gpos_kerning_agrees_with_the_kern_table() {
        let face = Face::parse(DEFAULT_FONT, 0).unwrap();
        let g = |c: char| face.glyph_index(c).unwrap();
        for (a, b, want) in [('A', 'V', -131), ('W', 'o', -120), ('T', 'o', -348)] {
            assert_eq!(gpos_kerning(&face, g(a), g(b)), Some(want), "{a}{b}");
        }
        assert_eq!(gpos_kerning(&face, g('H'), g('H')).unwrap_or(0), 0);
    }

    /// A second line sits one line height lower; centring puts each line's middle at 0.
    #[test]
    fn lines_and_alignment() {
        let two = laid("H\nH");
        let face = Face::parse(DEFAULT_FONT, 0).unwrap();
        let height = f64::from(face.ascender() - face.descender() + face.line_gap()) / 2048.0;
        assert!((two.min.y + height).abs() < 1e-12);
        let layout =
            Layout { size: 2.0, halign: HAlign::Center, valign: VAlign::Center, spacing: 1.0, line_spacing: 1.0 };
        let c = lay_out(DEFAULT_FONT, "HH", &layout).unwrap().outline.unwrap();
        assert!((c.min.y + c.max.y).abs() < 1e-12, "centred across v");
        assert!((c.min.x + c.max.x).abs() < 0.2, "about centred across u: {} {}", c.min.x, c.max.x);
    }

    /// A character the font lacks is reported once; spaces draw nothing; bytes that are
    /// not a font are an error.
    #[test]
    fn missing_glyphs_spaces_and_bad_fonts() {
        let layout =
            Layout { size: 1.0, halign: HAlign::Left, valign: VAlign::Baseline, spacing: 1.0, line_spacing: 1.0 };
        let l = lay_out(DEFAULT_FONT, "a\u{10FFFD}b\u{10FFFD}", &layout).unwrap();
        assert_eq!(l.missing, vec!['\u{10FFFD}']);
        assert_eq!(l.family.as_deref(), Some("DejaVu Sans"));
        assert!(lay_out(DEFAULT_FONT, "   ", &layout).unwrap().outline.is_none());
        assert!(lay_out(b"not a font", "a", &layout).is_err());
    }

    /// A cubic becomes quadratics within the stated tolerance of it.
    #[test]
    fn cubics_become_close_quadratics() {
        let at = |x: f64, y: f64| DVec2::new(x, y);
        let mut pen = Pen::new(&at, 1e-5);
        pen.move_to(0.0, 0.0);
        pen.curve_to(0.0, 1.0, 1.0, 1.0, 1.0, 0.0);
        pen.close();
        let o = Outline::new(pen.contours.into_iter().map(|c| (0, c)).collect(), String::new()).unwrap();
        let cubic = |t: f64| {
            let s = 1.0 - t;
            DVec2::new(3.0 * s * t * t + t * t * t, 3.0 * s * s * t + 3.0 * s * t * t)
        };
        for i in 0..=1000 {
            let d = o.nearest(cubic(f64::from(i) / 1000.0)).d.abs();
            assert!(d < 1e-5, "{d}");
        }
    }
}
