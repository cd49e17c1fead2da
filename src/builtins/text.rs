//! `text(string, …)`: a line (or lines) of glyphs as a 2D profile, laid out in the bundled
//! DejaVu Sans or a font file beside the scene (`geom::font`), its distance exact to the
//! glyphs' outlines (`geom::outline`) and its region those outlines, so an extrusion of
//! it meshes as a prism per glyph.

use std::sync::Arc;

use super::{BoundArgs, Host, Profile};
use crate::diag::{codes, Diagnostic};
use crate::geom::font::{self, HAlign, Layout, VAlign};
use crate::geom::region::Region;
use crate::ir::field::{FieldExpr, FieldKind, FieldTy};
use crate::sig::Range;

crate::params! {
    /// `text(string, …)`.
    pub struct TextArgs {
        /// the characters; `\n` starts a new line
        string: String as Str = required;
        /// the em: the font's units per em scale to it (the first glyph starts at `u = 0` on the baseline `v = 0`)
        size: f64 as Num = 1.0, Range::POSITIVE;
        /// a TrueType or OpenType file, relative to this file ("" for the bundled DejaVu Sans)
        font: String as Str = "";
        /// "left", "center" or "right": where each line sits about `u = 0`
        halign: String as Str = "left";
        /// "baseline", "top", "center" or "bottom": what of the text sits at `v = 0`
        valign: String as Str = "baseline";
        /// factor on each glyph's advance
        spacing: f64 as Num = 1.0, Range::POSITIVE;
        /// factor on the font's line height between lines
        line_spacing: f64 as Num = 1.0, Range::NONNEG;
    }
}

/// The words `halign` takes, with their meaning.
const HALIGN: [(&str, HAlign); 3] = [("left", HAlign::Left), ("center", HAlign::Center), ("right", HAlign::Right)];

/// The words `valign` takes, with their meaning.
const VALIGN: [(&str, VAlign); 4] =
    [("baseline", VAlign::Baseline), ("top", VAlign::Top), ("center", VAlign::Center), ("bottom", VAlign::Bottom)];

impl dyn Host + '_ {
    /// `text(…)`'s profile, or `None` after reporting why there is none.
    pub(crate) fn text(&mut self, a: &BoundArgs) -> Option<Profile> {
        let args = TextArgs::from_args(a);
        let halign = self.word(&HALIGN, &args.halign, "halign", a)?;
        let valign = self.word(&VALIGN, &args.valign, "valign", a)?;
        let (bytes, font_name) = if args.font.is_empty() {
            (std::borrow::Cow::Borrowed(font::DEFAULT_FONT), font::DEFAULT_FONT_NAME.to_string())
        } else {
            let path = self.file_dir().join(&args.font);
            match self.read_file(&path, crate::source::MAX_MESH_FILE_BYTES) {
                Ok(b) => (std::borrow::Cow::Owned(b), args.font.clone()),
                Err(e) => {
                    self.report(
                        Diagnostic::error(
                            codes::BAD_FONT,
                            a.span_of("font"),
                            format!("cannot read font `{}`", args.font),
                            crate::source::io_reason(&e),
                        )
                        .with_note(format!("looked for {}", path.display())),
                    );
                    return None;
                }
            }
        };
        let layout = Layout { size: args.size, halign, valign, spacing: args.spacing, line_spacing: args.line_spacing };
        let laid = match font::lay_out(&bytes, &args.string, &layout) {
            Ok(l) => l,
            Err(why) => {
                let blamed = match why {
                    font::LayoutError::Font(_) => "font",
                    font::LayoutError::Text(_) => "string",
                };
                self.report(Diagnostic::error(
                    codes::BAD_FONT,
                    a.span_of(blamed),
                    format!("cannot lay out the text in `{font_name}`"),
                    why.to_string(),
                ));
                return None;
            }
        };
        let shown = laid.family.clone().unwrap_or_else(|| font_name.clone());
        if !laid.missing.is_empty() {
            let chars: Vec<String> = laid.missing.iter().map(|c| format!("{c:?} (U+{:04X})", u32::from(*c))).collect();
            self.report(
                Diagnostic::warning(
                    codes::MISSING_GLYPH,
                    a.span_of("string"),
                    format!("the font `{shown}` has no glyph for {}", chars.join(", ")),
                    "drawn as the font's missing-glyph box",
                )
                .with_note(if args.font.is_empty() {
                    "the bundled font is DejaVu Sans; name another with `font = \"file.ttf\"`".to_string()
                } else {
                    format!("the font is read from `{font_name}`")
                }),
            );
        }
        let Some(outline) = laid.outline else {
            self.report(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    a.span_of("string"),
                    "the text draws nothing",
                    "no glyph with an outline",
                )
                .with_note("a profile needs some area: spaces and empty strings have none"),
            );
            return None;
        };
        // A few steps per segment: laying out and splitting cost that much.
        if !self.burn(outline.pieces() as u64, a.call) {
            return None;
        }
        let (min, max) = (outline.min, outline.max);
        let outline = Arc::new(outline);
        let body = FieldExpr::new(FieldKind::Outline(outline.clone(), FieldExpr::point()), FieldTy::Num);
        Some(Profile { body, region: Some(Arc::new(Region::Outline(outline))), min, max })
    }

    /// The meaning of a word argument `name` among `words`, or `None` after reporting it.
    fn word<T: Copy>(&mut self, words: &[(&str, T)], given: &str, name: &str, a: &BoundArgs) -> Option<T> {
        if let Some((_, v)) = words.iter().find(|(w, _)| *w == given) {
            return Some(*v);
        }
        let list: Vec<String> = words.iter().map(|(w, _)| format!("{w:?}")).collect();
        self.report(Diagnostic::error(
            codes::OUT_OF_RANGE,
            a.span_of(name),
            format!("`{name}` must be one of {}", list.join(", ")),
            format!("this is {given:?}"),
        ));
        None
    }
}
