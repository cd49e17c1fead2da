//! What the page is told about the text: diagnostics as it shows them, the parameters
//! its controls take, and positions,
//! which the page counts in UTF-16 code units (JavaScript strings) and the compiler in
//! bytes. Every position crosses [`to_byte`] or [`to_utf16`].

use scnc::diag::{Diagnostic, Severity};
use scnc::source::{FileId, SourceMap};

/// The byte offset of UTF-16 position `pos` in `text` (clamped to its end).
pub(crate) fn to_byte(text: &str, pos: u32) -> u32 {
    let mut units = 0u32;
    for (i, c) in text.char_indices() {
        if units >= pos {
            return i as u32;
        }
        units += c.len_utf16() as u32;
    }
    text.len() as u32
}

/// The UTF-16 position of byte offset `byte` in `text`.
pub(crate) fn to_utf16(text: &str, byte: usize) -> usize {
    let byte = byte.min(text.len());
    text.char_indices().take_while(|(i, _)| *i < byte).map(|(_, c)| c.len_utf16()).sum()
}

/// Where `span` is in the editor's text, in UTF-16 units; `None` for a span in an
/// included file.
pub(crate) fn page_range(map: &SourceMap, span: scnc::span::Span) -> Option<(usize, usize)> {
    let (id, range) = map.local_range(span);
    let root = &map.file(FileId(0)).text;
    (id == FileId(0)).then(|| (to_utf16(root, range.start), to_utf16(root, range.end)))
}

/// Diagnostics as the page shows them: a span in the editor's text (a diagnostic in an
/// include points at the start, its place named in the message), and the message with
/// its notes and help as `scnc check` prints them.
pub(crate) fn diagnostics_json(map: &SourceMap, diagnostics: &[Diagnostic]) -> serde_json::Value {
    let list: Vec<_> = diagnostics
        .iter()
        .map(|d| {
            // The primary label says what is wrong at the span, which an editor's squiggle
            // cannot show beside the message.
            let mut message = match d.labels.first().map(|l| l.message.as_str()) {
                Some(label) if !label.is_empty() => format!("{} ({label})", d.message),
                _ => d.message.clone(),
            };
            let (from, to) = page_range(map, d.span()).unwrap_or_else(|| {
                let (id, range) = map.local_range(d.span());
                let (line, col) = map.line_col(id, range.start);
                message = format!("{}:{line}:{col}: {message}", map.file(id).name);
                (0, 0)
            });
            for note in &d.notes {
                message.push_str(&format!("\nnote: {note}"));
            }
            for hint in &d.hints {
                message.push_str(&format!("\nhelp: {hint}"));
            }
            serde_json::json!({
                "from": from, "to": to, "code": d.code, "message": message,
                "severity": match d.severity { Severity::Error => "error", Severity::Warning => "warning" },
            })
        })
        .collect();
    serde_json::Value::Array(list)
}

/// `scene`'s parameters as the page's controls take them: each as `scnc params` prints
/// it, with the UTF-16 range of its default in the root file of `map`.
pub(crate) fn param_list(map: &SourceMap, scene: &scnc::ir::Scene) -> Vec<serde_json::Value> {
    let root = map.file(FileId(0)).text.as_str();
    scene
        .params
        .iter()
        .map(|p| {
            let mut j = crate::cli::param_json(p);
            let (_, range) = map.local_range(p.default_span);
            j["from"] = to_utf16(root, range.start).into();
            j["to"] = to_utf16(root, range.end).into();
            j["source"] = p.value.source().into();
            j
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_cross_between_utf16_and_bytes() {
        let t = "a€b😀c";
        // a=1 unit/1 byte, €=1 unit/3 bytes, b, 😀=2 units/4 bytes, c.
        assert_eq!(to_byte(t, 0), 0);
        assert_eq!(to_byte(t, 2), 4);
        assert_eq!(to_byte(t, 5), 9);
        assert_eq!(to_byte(t, 99), t.len() as u32);
        assert_eq!(to_utf16(t, 4), 2);
        assert_eq!(to_utf16(t, 9), 5);
        assert_eq!(to_utf16(t, t.len()), 6);
    }
}
