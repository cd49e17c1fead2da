//! Diagnostics as data, and the one place that turns them into text (ariadne) or JSON.
//!
//! Every stage reports problems as [`Diagnostic`] values: a stable code from [`codes`], a
//! message, labelled spans, notes and hints. Only this module knows about ariadne.

use std::collections::HashMap;
use std::fmt::Write as _;

use ariadne::{Config, IndexType, Label as ALabel, Report, ReportKind};

pub mod guesses;

use crate::source::SourceMap;
use crate::span::Span;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// The file cannot be compiled.
    Error,
    /// The file compiles, but something is probably not what the author meant.
    Warning,
}

/// A labelled span; the primary label says what is wrong here, secondary ones point elsewhere.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// Where.
    pub span: Span,
    /// What to say there.
    pub message: String,
    /// Whether this is the main location.
    pub primary: bool,
}

/// One problem found in the input.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// A stable code such as `E0200`, documented in `docs/errors.md`.
    pub code: &'static str,
    /// One line, lowercase start, no trailing period.
    pub message: String,
    /// The primary label first, then secondary ones.
    pub labels: Vec<Label>,
    /// Extra facts.
    pub notes: Vec<String>,
    /// Suggested fixes, phrased "try …" or "did you mean …".
    pub hints: Vec<String>,
    /// Machine-applicable replacements behind the hints (editor quick-fixes).
    pub fixes: Vec<Fix>,
}

/// A replacement an editor can apply: put `text` where `span` is.
#[derive(Clone, Debug, PartialEq)]
pub struct Fix {
    /// What to replace.
    pub span: Span,
    /// The replacement.
    pub text: String,
}

impl Diagnostic {
    /// An error with a primary label.
    pub fn error(code: &'static str, span: Span, message: impl Into<String>, label: impl Into<String>) -> Diagnostic {
        Diagnostic::new(Severity::Error, code, span, message, label)
    }

    /// A warning with a primary label.
    pub fn warning(code: &'static str, span: Span, message: impl Into<String>, label: impl Into<String>) -> Diagnostic {
        Diagnostic::new(Severity::Warning, code, span, message, label)
    }

    fn new(
        severity: Severity,
        code: &'static str,
        span: Span,
        message: impl Into<String>,
        label: impl Into<String>,
    ) -> Diagnostic {
        Diagnostic {
            severity,
            code,
            message: message.into(),
            labels: vec![Label { span, message: label.into(), primary: true }],
            notes: Vec::new(),
            hints: Vec::new(),
            fixes: Vec::new(),
        }
    }

    /// Adds a secondary label.
    pub fn with_label(mut self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.labels.push(Label { span, message: message.into(), primary: false });
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Diagnostic {
        self.notes.push(note.into());
        self
    }

    /// Adds a hint.
    pub fn with_hint(mut self, hint: impl Into<String>) -> Diagnostic {
        self.hints.push(hint.into());
        self
    }

    /// Adds a "did you mean `text`?" hint with the replacement of `span` by `text`.
    pub fn with_replacement(mut self, span: Span, text: &str) -> Diagnostic {
        self.hints.push(format!("did you mean `{text}`?"));
        self.fixes.push(Fix { span, text: text.to_string() });
        self
    }

    /// Adds a replacement without a hint of its own (when one hint offers several).
    pub fn with_fix(mut self, span: Span, text: &str) -> Diagnostic {
        self.fixes.push(Fix { span, text: text.to_string() });
        self
    }

    /// The primary span.
    pub fn span(&self) -> Span {
        self.labels[0].span
    }

    /// True for errors.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Renders with ariadne, as `rustc` would print it; `color` for a terminal.
    pub fn render(&self, map: &SourceMap, color: bool) -> String {
        self.render_with(&mut Sources::new(map), color)
    }

    /// Renders like [`Diagnostic::render`], with files prepared once for many diagnostics.
    pub fn render_with(&self, sources: &mut Sources<'_>, color: bool) -> String {
        let map = sources.map;
        let name = |span: Span| map.file(map.file_of(span)).name.clone();
        let (_, primary) = map.local_range(self.span());
        let kind = match self.severity {
            Severity::Error => ReportKind::Error,
            Severity::Warning => ReportKind::Warning,
        };
        let mut report = Report::build(kind, (name(self.span()), primary))
            .with_config(Config::default().with_color(color).with_index_type(IndexType::Byte))
            .with_code(self.code)
            .with_message(&self.message);
        // ariadne starts a new source group whenever a label lies above the previous one,
        // so labels go in source order.
        let mut labels: Vec<&Label> = self.labels.iter().collect();
        labels.sort_by_key(|l| (l.span.start, l.span.end));
        for label in labels {
            let (_, range) = map.local_range(label.span);
            let mut l = ALabel::new((name(label.span), range)).with_message(&label.message);
            if color {
                l = l.with_color(if label.primary {
                    match self.severity {
                        Severity::Error => ariadne::Color::Red,
                        Severity::Warning => ariadne::Color::Yellow,
                    }
                } else {
                    ariadne::Color::Blue
                });
            }
            report = report.with_label(l);
        }
        for note in &self.notes {
            report = report.with_note(note);
        }
        for hint in &self.hints {
            report = report.with_help(hint);
        }
        let mut out = Vec::new();
        // Writing to a Vec cannot fail, and every span was clamped into its file above.
        let _ = report.finish().write(sources, &mut out);
        String::from_utf8_lossy(&out).into_owned()
    }

    /// One JSON object (one line) for editors and tests.
    pub fn to_json(&self, map: &SourceMap) -> String {
        let loc = |span: Span| {
            let (id, r) = map.local_range(span);
            let (line, col) = map.line_col(id, r.start);
            let (end_line, end_col) = map.line_col(id, r.end);
            serde_json::json!({
                "file": map.file(id).name,
                "byte_start": r.start, "byte_end": r.end,
                "line_start": line, "column_start": col,
                "line_end": end_line, "column_end": end_col,
            })
        };
        let mut primary = loc(self.span());
        primary["label"] = self.labels[0].message.clone().into();
        let related: Vec<_> = self.labels[1..]
            .iter()
            .map(|l| {
                let mut v = loc(l.span);
                v["label"] = l.message.clone().into();
                v
            })
            .collect();
        let fixes: Vec<_> = self
            .fixes
            .iter()
            .map(|f| {
                let mut v = loc(f.span);
                v["replacement"] = f.text.clone().into();
                v
            })
            .collect();
        let json = serde_json::json!({
            "severity": match self.severity { Severity::Error => "error", Severity::Warning => "warning" },
            "code": self.code,
            "message": self.message,
            "span": primary,
            "related": related,
            "notes": self.notes,
            "hints": self.hints,
            "fixes": fixes,
        });
        json.to_string()
    }
}

/// Renders many diagnostics, one after another, without colour (for golden tests).
pub fn render_all(diags: &[Diagnostic], map: &SourceMap) -> String {
    let mut sources = Sources::new(map);
    let mut out = String::new();
    for d in diags {
        let _ = write!(out, "{}", d.render_with(&mut sources, false));
    }
    out
}

/// The files of a source map as ariadne reads them, each indexed on first use and then
/// kept: indexing every file again for each diagnostic made many warnings quadratic.
pub struct Sources<'m> {
    map: &'m SourceMap,
    indexed: HashMap<String, ariadne::Source<&'m str>>,
}

impl<'m> Sources<'m> {
    /// Nothing indexed yet.
    pub fn new(map: &'m SourceMap) -> Sources<'m> {
        Sources { map, indexed: HashMap::new() }
    }
}

impl<'m> ariadne::Cache<String> for Sources<'m> {
    type Storage = &'m str;

    fn fetch(&mut self, id: &String) -> Result<&ariadne::Source<&'m str>, impl std::fmt::Debug> {
        if !self.indexed.contains_key(id) {
            // The last file of a name wins, as it did when all were indexed up front.
            if let Some((_, f)) = self.map.files().filter(|(_, f)| f.name == *id).last() {
                self.indexed.insert(id.clone(), ariadne::Source::from(f.text.as_str()));
            }
        }
        self.indexed.get(id).ok_or_else(|| format!("no file named `{id}`"))
    }

    fn display<'a>(&self, id: &'a String) -> Option<impl std::fmt::Display + 'a> {
        Some(id)
    }
}

/// Every diagnostic code with a one-line summary; `docs/errors.md` explains each.
pub mod codes {
    /// Unexpected character.
    pub const UNEXPECTED_CHAR: &str = "E0001";
    /// Unterminated string literal.
    pub const UNTERMINATED_STRING: &str = "E0002";
    /// Unterminated block comment.
    pub const UNTERMINATED_COMMENT: &str = "E0003";
    /// Malformed number literal.
    pub const BAD_NUMBER: &str = "E0004";
    /// Malformed colour literal.
    pub const BAD_COLOR: &str = "E0005";
    /// `&&`, `||` or `!` where scnc writes `and`, `or`, `not`.
    pub const FOREIGN_OPERATOR: &str = "E0006";
    /// Syntax error.
    pub const SYNTAX: &str = "E0100";
    /// Unknown name.
    pub const UNKNOWN_NAME: &str = "E0200";
    /// Unknown function.
    pub const UNKNOWN_FUNCTION: &str = "E0201";
    /// Duplicate parameter name.
    pub const DUPLICATE_PARAM: &str = "E0202";
    /// A function used as a value, or a value called.
    pub const NOT_A_VALUE: &str = "E0203";
    /// Type mismatch.
    pub const TYPE_MISMATCH: &str = "E0300";
    /// Wrong number of arguments.
    pub const ARITY: &str = "E0301";
    /// Unknown named argument.
    pub const UNKNOWN_ARG: &str = "E0302";
    /// Argument given twice.
    pub const DUPLICATE_ARG: &str = "E0303";
    /// Required argument missing.
    pub const MISSING_ARG: &str = "E0304";
    /// Operator not defined for these operand types.
    pub const BAD_OPERANDS: &str = "E0305";
    /// List index out of bounds.
    pub const INDEX_OUT_OF_BOUNDS: &str = "E0306";
    /// A whole number was expected.
    pub const NOT_INTEGER: &str = "E0307";
    /// `mesh` applied to something that is not a mesh generator.
    pub const NOT_A_MESH_GENERATOR: &str = "E0308";
    /// Transform not allowed on this value.
    pub const BAD_TRANSFORM: &str = "E0309";
    /// A condition that is not a boolean.
    pub const NOT_A_BOOL: &str = "E0310";
    /// The branches of an `if` expression have different types.
    pub const BRANCH_MISMATCH: &str = "E0311";
    /// A `for` over something that is neither a range nor a list.
    pub const NOT_ITERABLE: &str = "E0312";
    /// Something that must be known before rendering depends on a field's point.
    pub const DEPENDS_ON_POINT: &str = "E0313";
    /// A field literal `p => …` where no field is taken.
    pub const MISPLACED_FIELD: &str = "E0314";
    /// Value out of its allowed range.
    pub const OUT_OF_RANGE: &str = "E0400";
    /// Arithmetic produced a non-finite number (division by zero, overflow).
    pub const NOT_FINITE: &str = "E0401";
    /// Degenerate camera.
    pub const BAD_CAMERA: &str = "E0402";
    /// Beyond the renderable range.
    pub const OUT_OF_REACH: &str = "E0403";
    /// A field whose slope has no bound the checker can find.
    pub const UNBOUNDED_SLOPE: &str = "E0404";
    /// A domain operation (`twist`, `bend`, `polar`) of a shape with no finite extent.
    pub const NEEDS_BOUNDED: &str = "E0405";
    /// `camera` or `render` given twice.
    pub const DUPLICATE_STATEMENT: &str = "E0500";
    /// `object` of something that is not a shape or mesh.
    pub const NOT_AN_OBJECT: &str = "E0501";
    /// `light` of something that is not a light.
    pub const NOT_A_LIGHT: &str = "E0502";
    /// An animation's frame count, rate or looping differ between its frames.
    pub const ANIMATION_CHANGES: &str = "E0503";
    /// A `param` declared where it cannot be, or with a default, range or step it cannot have.
    pub const BAD_PARAM: &str = "E0504";
    /// A value given for a parameter (`-D`, a parameter set, the studio) that it cannot take.
    pub const BAD_PARAM_VALUE: &str = "E0505";
    /// Included file cannot be read.
    pub const INCLUDE_READ: &str = "E0600";
    /// Include cycle.
    pub const INCLUDE_CYCLE: &str = "E0601";
    /// A font that cannot be read, or text it cannot lay out.
    pub const BAD_FONT: &str = "E0602";
    /// Nesting too deep (brackets or expressions).
    pub const TOO_DEEP: &str = "E0700";
    /// Too many loop iterations in total.
    pub const TOO_MANY_ITERATIONS: &str = "E0701";
    /// Function calls nested too deeply.
    pub const CALL_DEPTH: &str = "E0702";
    /// Includes nested too deeply.
    pub const INCLUDE_DEPTH: &str = "E0703";
    /// Too many objects or lights.
    pub const TOO_MANY_OBJECTS: &str = "E0704";
    /// A list or file too large.
    pub const TOO_LARGE: &str = "E0705";
    /// Evaluation ran out of fuel.
    pub const OUT_OF_FUEL: &str = "E0706";
    /// A shape that expands to too many nodes, or a pattern holding too many patterns.
    pub const SHAPE_TOO_LARGE: &str = "E0707";
    /// Too many errors: evaluation stopped.
    pub const TOO_MANY_ERRORS: &str = "E0708";
    /// The operating system refused what a compile needs (its thread's stack).
    pub const NO_RESOURCES: &str = "E0709";
    /// A shape whose one distance evaluation is estimated past the work ceiling.
    pub const TOO_COSTLY: &str = "E0710";
    /// A render-time failure traced back to the source (e.g. a mesh file that cannot be read).
    pub const LOWERING: &str = "E0800";
    /// Unused `let` binding.
    pub const UNUSED: &str = "W0001";
    /// Scene without lights.
    pub const NO_LIGHTS: &str = "W0002";
    /// Light that cannot affect anything.
    pub const USELESS_LIGHT: &str = "W0003";
    /// Scene without objects.
    pub const NO_OBJECTS: &str = "W0004";
    /// Object entirely behind the camera.
    pub const BEHIND_CAMERA: &str = "W0005";
    /// A material argument that does nothing (`ior` or `absorption` without `transparency`).
    pub const NO_EFFECT: &str = "W0006";
    /// A field far from a distance (its slope bound far from 1): it is marched slowly.
    pub const STEEP_FIELD: &str = "W0007";
    /// A `polar` shape reaching out of its sector: the distance is only a bound there.
    pub const CROSSES_SECTOR: &str = "W0008";
    /// A CSG node whose parts crowd one place: every step of a ray there evaluates them all.
    pub const CROWDED_CSG: &str = "W0009";
    /// Trigonometry in a field body whose argument barely turns: radians written for degrees.
    pub const SMALL_TURN: &str = "W0010";
    /// A shape whose one distance evaluation is estimated to do a great deal of work.
    pub const COSTLY: &str = "W0011";
    /// Characters the font has no glyph for.
    pub const MISSING_GLYPH: &str = "W0012";
    /// Parts of a shape too small for its isosurface's cell, left out of the mesh.
    pub const LOST_PARTS: &str = "W0801";
    /// An unbounded object left out of an export.
    pub const SKIPPED_UNBOUNDED: &str = "W0803";
    /// An object with no triangles, left out of an export.
    pub const SKIPPED_EMPTY: &str = "W0805";
    /// An isosurface whose volume is far from the volume its shape's samples measure.
    pub const LOST_VOLUME: &str = "W0804";
    /// An isosurface left farther than its tolerance from its shape in places.
    pub const TOLERANCE_UNMET: &str = "W0806";
}

/// Edit distance for "did you mean" suggestions.
pub fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let cost = usize::from(ca != *cb);
            cur[j + 1] = (prev[j] + cost).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The closest candidate within a distance that scales with the word's length.
pub fn suggest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (word.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .filter(|c| *c != word)
        // The distance is at least the difference in length: most candidates of a big
        // scope are dismissed without the quadratic comparison.
        .filter(|c| c.chars().count().abs_diff(word.chars().count()) <= limit)
        .map(|c| (levenshtein(word, c), c))
        .filter(|(d, _)| *d <= limit)
        .min()
        .map(|(_, c)| c)
}

/// A byte count for people, in the largest binary unit it fills (`1 KiB`, `3.5 GiB`,
/// `512 B`): a limit given as `1K` is reported as 1 KiB, not as 0 MiB.
pub fn bytes(n: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = n as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 || value >= 10.0 || value.fract() == 0.0 {
        format!("{value:.0} {}", UNITS[unit])
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod position_tests {
    use std::path::Path;

    use crate::lsp::text::LineIndex;
    use crate::source::FsLoader;

    /// The line and column a diagnostic is shown at agree between the human rendering
    /// (ariadne), the JSON fields and the language server's positions, for `\n`, `\r\n`
    /// and lone `\r` line endings, and at the end of input.
    #[test]
    fn human_json_and_lsp_positions_agree_for_every_line_ending() {
        for nl in ["\n", "\r\n", "\r"] {
            let texts = [
                format!("light ambient(1){nl}{nl}object spher(1) at [0, 0, 5]{nl}"),
                format!("light ambient(1){nl}object sphere(1{nl}{nl}"),
                format!("light ambient(1){nl}for i in 0..2 {{{nl}  object sphere(1){nl}"),
            ];
            for text in texts {
                let c = crate::compile_source("t.scn", Path::new("t.scn"), text.clone(), &FsLoader);
                assert!(!c.diagnostics.is_empty(), "{text:?} has an error");
                for d in &c.diagnostics {
                    let human = d.render(&c.map, false);
                    let header = human.split("t.scn:").nth(1).and_then(|h| h.split(' ').next()).unwrap_or_default();
                    let json: serde_json::Value = serde_json::from_str(&d.to_json(&c.map)).expect("JSON");
                    let from_json = format!("{}:{}", json["span"]["line_start"], json["span"]["column_start"]);
                    let (_, r) = c.map.local_range(d.span());
                    let p = LineIndex::new(&text).position(r.start);
                    let from_lsp = format!("{}:{}", p.line + 1, p.character + 1);
                    assert_eq!(header, from_json, "{text:?}: human vs JSON\n{human}");
                    assert_eq!(from_json, from_lsp, "{text:?}: JSON vs LSP");
                }
            }
        }
    }
}

#[cfg(test)]
mod bytes_tests {
    #[test]
    fn byte_counts_read_in_the_unit_they_fill() {
        assert_eq!(super::bytes(512), "512 B");
        assert_eq!(super::bytes(1024), "1 KiB");
        assert_eq!(super::bytes(1536), "1.5 KiB");
        assert_eq!(super::bytes(4 << 30), "4 GiB");
        assert_eq!(super::bytes(100 << 20), "100 MiB");
        assert_eq!(super::bytes(0), "0 B");
    }
}
