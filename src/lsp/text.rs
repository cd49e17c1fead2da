//! Positions and URIs as the Language Server Protocol has them: lines and UTF-16 code
//! units, and `file://` URIs with percent-encoding.

use std::path::{Path, PathBuf};

use lsp_types::{Position, Range};

/// Converts between byte offsets and LSP positions in one text.
#[derive(Debug)]
pub struct LineIndex<'t> {
    text: &'t str,
    starts: Vec<usize>,
}

impl<'t> LineIndex<'t> {
    /// Indexes the line starts of `text`.
    pub fn new(text: &'t str) -> LineIndex<'t> {
        LineIndex { text, starts: crate::source::line_starts(text) }
    }

    /// The position of a byte offset (clamped to the text).
    pub fn position(&self, offset: usize) -> Position {
        let offset = offset.min(self.text.len());
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let start = self.starts[line];
        let mut end = offset;
        while !self.text.is_char_boundary(end) {
            end -= 1;
        }
        let character = self.text[start..end].encode_utf16().count();
        Position::new(line as u32, character as u32)
    }

    /// The byte offset of a position; past the end of a line means its end.
    pub fn offset(&self, pos: Position) -> usize {
        let Some(&start) = self.starts.get(pos.line as usize) else {
            return self.text.len();
        };
        // The line ends before its break: `\n`, `\r\n` or a lone `\r`.
        let line_end = self.starts.get(pos.line as usize + 1).map_or(self.text.len(), |&next| {
            let body = &self.text[start..next];
            next - (body.len() - body.trim_end_matches(['\n', '\r']).len()).min(2)
        });
        let mut units = 0u32;
        for (i, c) in self.text[start..line_end].char_indices() {
            if units >= pos.character {
                return start + i;
            }
            units += c.len_utf16() as u32;
        }
        line_end
    }

    /// The range of a byte range.
    pub fn range(&self, r: std::ops::Range<usize>) -> Range {
        Range::new(self.position(r.start), self.position(r.end))
    }
}

/// The path of a `file://` URI; `None` for other schemes or malformed escapes.
pub fn uri_to_path(uri: &str) -> Option<PathBuf> {
    let rest = uri.strip_prefix("file://")?;
    // `file://host/path` names a host; only the local form (empty host) is a path here.
    let path = rest.strip_prefix("localhost").unwrap_or(rest);
    if !path.starts_with('/') {
        return None;
    }
    let bytes = path.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok().map(PathBuf::from)
}

/// The `file://` URI of an absolute path.
pub fn path_to_uri(path: &Path) -> String {
    let mut out = String::from("file://");
    for b in path.to_string_lossy().bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_utf16_units() {
        // `é` is one UTF-16 unit and two bytes; `𝄞` is two units and four bytes.
        let text = "let é = 1\nlet 𝄞x = 2\n";
        let ix = LineIndex::new(text);
        let x = text.find('x').unwrap();
        assert_eq!(ix.position(x), Position::new(1, 6));
        assert_eq!(ix.offset(Position::new(1, 6)), x);
        let eq = text.find(" = 1").unwrap() + 1;
        assert_eq!(ix.position(eq), Position::new(0, 6));
        assert_eq!(ix.offset(Position::new(0, 6)), eq);
        assert_eq!(ix.offset(Position::new(0, 99)), text.find('\n').unwrap());
        assert_eq!(ix.offset(Position::new(9, 0)), text.len());
        assert_eq!(ix.position(text.len()), Position::new(2, 0));
    }

    #[test]
    fn uris_round_trip() {
        let path = Path::new("/tmp/a dir/scène #1.scn");
        let uri = path_to_uri(path);
        assert_eq!(uri, "file:///tmp/a%20dir/sc%C3%A8ne%20%231.scn");
        assert_eq!(uri_to_path(&uri).as_deref(), Some(path));
        assert_eq!(uri_to_path("untitled:Untitled-1"), None);
        assert_eq!(uri_to_path("file:///bad%zz"), None);
    }
}
