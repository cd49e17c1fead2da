//! `scnc fmt`: the canonical layout of a `.scn` file.
//!
//! The formatter works on the token stream, comments included, so nothing written is
//! lost: it re-spaces every token, puts each statement on its own line, indents blocks
//! and continuation lines by four spaces, and keeps the author's line breaks inside
//! expressions and one blank line where there were blank lines. It changes only
//! whitespace, so the formatted file evaluates to the same scene, and formatting a
//! formatted file changes nothing.

use crate::diag::Diagnostic;
use crate::syntax::{self, Token};

const INDENT: &str = "    ";

/// Formats `text`; a file with syntax errors is not formatted and its errors are returned.
pub fn format(text: &str) -> Result<String, Vec<Diagnostic>> {
    let (_, diags) = syntax::parse(text, 0);
    if !diags.is_empty() {
        return Err(diags);
    }
    let tokens = syntax::lex(text, 0);
    let mut out = Formatter::default();
    let mut prev_end = 0usize;
    for (i, (tok, span)) in tokens.iter().enumerate() {
        let gap = &text[prev_end..span.start as usize];
        let newlines = gap.matches('\n').count();
        out.token(tok, &text[span.range()], newlines, tokens.get(i + 1).map(|(t, _)| t));
        prev_end = span.end as usize;
    }
    Ok(out.finish())
}

#[derive(Default)]
struct Formatter<'t> {
    out: String,
    /// Open `(` and `[`, each with the output line it was opened on.
    brackets: Vec<usize>,
    /// Open `{` blocks.
    braces: usize,
    line: usize,
    /// The indentation level of each output line that was indented (0 otherwise).
    levels: Vec<usize>,
    /// The previous token (not a comment), for spacing.
    prev: Option<Token<'t>>,
    /// The last `-` was a negation.
    minus_was_unary: bool,
    /// The previous token was a comment, or nothing was written yet.
    after_comment: bool,
    at_line_start: bool,
    /// A statement is being written and has not ended; a line break inside it indents.
    in_statement: bool,
}

/// Whether `t`, after `prev`, begins a statement. `if` begins one unless an operand is
/// expected (`let x = if …`, `else if …`); `for` inside brackets is a comprehension,
/// which the callers tell by the bracket depth.
fn starts_statement(t: &Token<'_>, prev: Option<&Token<'_>>) -> bool {
    match t {
        Token::Let
        | Token::Param
        | Token::Object
        | Token::Light
        | Token::Camera
        | Token::Render
        | Token::For
        | Token::Include => true,
        Token::If => prev.is_none_or(|p| matches!(p, Token::LBrace | Token::RBrace)) || !operand_expected(prev),
        _ => false,
    }
}

/// A `-` after these is a negation, not a subtraction.
fn operand_expected(prev: Option<&Token<'_>>) -> bool {
    match prev {
        None => true,
        Some(t) => !matches!(
            t,
            Token::Number(_)
                | Token::Ident(_)
                | Token::Str(_)
                | Token::HexColor(_)
                | Token::Bool(_)
                | Token::RParen
                | Token::RBracket
        ),
    }
}

impl<'t> Formatter<'t> {
    /// Ends the line (once), then adds a blank line if asked and none is there yet.
    fn newline(&mut self, blank: bool) {
        while self.out.ends_with(' ') {
            self.out.pop();
        }
        if self.out.is_empty() {
            return;
        }
        if !self.out.ends_with('\n') {
            self.out.push('\n');
            self.line += 1;
        }
        // No blank line right after an opening brace.
        if blank && !self.out.ends_with("\n\n") && !self.out.ends_with("{\n") {
            self.out.push('\n');
            self.line += 1;
        }
        self.at_line_start = true;
    }

    fn indent(&mut self, tok: &Token<'_>) {
        let mut lines: Vec<usize> = self.brackets.clone();
        let closes = if matches!(tok, Token::RParen | Token::RBracket) { lines.pop() } else { None };
        lines.dedup();
        let mut level = self.braces + lines.len();
        let continues = self.in_statement && lines.is_empty() && !starts_statement(tok, self.prev.as_ref());
        if continues && !matches!(tok, Token::RBrace | Token::LineComment | Token::BlockComment(_)) {
            level += 1;
        }
        if matches!(tok, Token::RBrace) {
            level = level.saturating_sub(1);
        }
        // A closing bracket that begins a line lines up with the line that opened it.
        if let Some(opened) = closes {
            level = self.levels.get(opened).copied().unwrap_or(0);
        }
        if self.levels.len() <= self.line {
            self.levels.resize(self.line + 1, 0);
        }
        self.levels[self.line] = level;
        for _ in 0..level {
            self.out.push_str(INDENT);
        }
        self.at_line_start = false;
    }

    fn token(&mut self, tok: &Token<'t>, text: &str, newlines: usize, next: Option<&Token<'_>>) {
        let comment = matches!(tok, Token::LineComment | Token::BlockComment(_));
        let depth0 = self.brackets.is_empty();
        let forced = !self.out.is_empty()
            && ((starts_statement(tok, self.prev.as_ref()) && depth0)
                || matches!(tok, Token::RBrace) && !matches!(self.prev, Some(Token::LBrace))
                || matches!(self.prev, Some(Token::LBrace)) && !self.after_comment && !matches!(tok, Token::RBrace));
        // A block's `{` ends its header's line, and `else` follows the `}` it continues.
        let joined = !self.after_comment
            && (matches!(tok, Token::LBrace) || matches!(tok, Token::Else) && matches!(self.prev, Some(Token::RBrace)));
        if (newlines > 0 && !joined) || forced {
            self.newline(newlines > 1);
        }
        // No blank line right before a closing brace.
        if matches!(tok, Token::RBrace) && self.out.ends_with("\n\n") {
            self.out.pop();
            self.line -= 1;
        }
        if self.at_line_start {
            self.indent(tok);
        } else if !self.out.is_empty() && self.space_before(tok) {
            self.out.push(' ');
        }
        self.out.push_str(text);
        if comment {
            self.after_comment = true;
            if matches!(tok, Token::LineComment) {
                self.newline(false);
            }
            return;
        }
        self.after_comment = false;
        match tok {
            Token::LParen | Token::LBracket => self.brackets.push(self.line),
            Token::RParen | Token::RBracket => {
                self.brackets.pop();
            }
            Token::LBrace => {
                self.braces += 1;
                self.in_statement = false;
            }
            Token::RBrace => {
                self.braces = self.braces.saturating_sub(1);
                self.in_statement = false;
            }
            _ => {}
        }
        if starts_statement(tok, self.prev.as_ref()) {
            self.in_statement = true;
        }
        // A `for` header ends at its `{`; other statements end where the next begins.
        if matches!(tok, Token::LBrace)
            || next.is_some_and(|n| starts_statement(n, Some(tok)) && self.brackets.is_empty())
        {
            self.in_statement = false;
        }
        if matches!(tok, Token::Minus) {
            self.minus_was_unary = operand_expected(self.prev.as_ref());
        }
        self.prev = Some(tok.clone());
    }

    fn space_before(&self, tok: &Token<'_>) -> bool {
        let prev = self.prev.as_ref();
        if self.after_comment {
            return true;
        }
        match prev {
            Some(Token::LParen | Token::LBracket | Token::DotDot | Token::Dot) => return false,
            // Negation binds to its operand.
            Some(Token::Minus) if self.minus_was_unary => return false,
            _ => {}
        }
        match tok {
            Token::RParen | Token::RBracket | Token::Comma | Token::DotDot | Token::Dot => false,
            Token::RBrace => !matches!(prev, Some(Token::LBrace)),
            Token::LParen => !matches!(prev, Some(Token::Ident(_) | Token::Camera | Token::Render)),
            // Directly after a value, `[` indexes it.
            Token::LBracket => !matches!(prev, Some(Token::Ident(_) | Token::RParen | Token::RBracket | Token::Str(_))),
            _ => true,
        }
    }

    fn finish(mut self) -> String {
        self.newline(false);
        if self.out.is_empty() {
            return String::new();
        }
        self.out
    }
}
