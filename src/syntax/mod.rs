//! Syntax: source text to an [`ast::File`] plus diagnostics. Parsing never fails: bad
//! tokens and bad statements are reported and skipped, so one run finds many mistakes.

pub mod ast;
pub mod parser;
pub mod token;

use chumsky::error::RichPattern;
use chumsky::input::Input as _;
use chumsky::prelude::*;
use logos::Logos;

use crate::diag::{codes, guesses, Diagnostic};
use crate::span::Span;
pub use token::Token;

/// Deepest bracket nesting accepted; deeper input is rejected before parsing so that
/// the recursive-descent parser and the evaluator cannot exhaust the stack.
pub const MAX_NESTING: usize = 128;

/// Lexes `text`, whose first byte sits at global offset `base`. Never fails: bad input
/// becomes error tokens (see [`Token::is_error`]), and comments are kept as tokens.
pub fn lex(text: &str, base: u32) -> Vec<(Token<'_>, Span)> {
    Token::lexer(text)
        .spanned()
        .map(|(tok, r)| {
            let span = Span::new(base as usize + r.start, base as usize + r.end);
            match tok {
                Ok(tok) => (tok, span),
                Err(()) => (Token::Error(&text[r]), span),
            }
        })
        .collect()
}

/// Reports lexical errors, replaces each bad token by the nearest good one (so the parser
/// reports no second error for the same mistake) and drops comments.
///
/// Long because it is one pass over the tokens with a match over each kind of lexical error
/// and its replacement.
fn clean_tokens<'s>(tokens: Vec<(Token<'s>, Span)>, diags: &mut Vec<Diagnostic>) -> Vec<(Token<'s>, Span)> {
    let mut out: Vec<(Token<'s>, Span)> = Vec::with_capacity(tokens.len());
    let mut tokens = tokens.into_iter().peekable();
    while let Some((tok, span)) = tokens.next() {
        // `1.` glued to a number and not followed by a component name is a number
        // missing its digits, not a component read.
        let glued_dot = tok == Token::Dot
            && matches!(out.last(), Some((Token::Number(_), prev)) if prev.end == span.start)
            && !matches!(tokens.peek(), Some((Token::Ident(_), next)) if next.start == span.end);
        let tok = if glued_dot { Token::Error(".") } else { tok };
        match tok {
            Token::BlockComment(true) | Token::LineComment => {}
            Token::BlockComment(false) => diags.push(
                Diagnostic::error(
                    codes::UNTERMINATED_COMMENT,
                    Span::new(span.start as usize, span.start as usize + 2),
                    "unterminated block comment",
                    "this comment is never closed",
                )
                .with_hint("try adding `*/` where the comment should end"),
            ),
            Token::UnterminatedStr(s) => {
                diags.push(
                    Diagnostic::error(
                        codes::UNTERMINATED_STRING,
                        span,
                        "unterminated string",
                        "this string has no closing `\"`",
                    )
                    .with_note("strings end on the line they start"),
                );
                let _ = s;
                out.push((Token::Str("\"\""), span));
            }
            Token::BadNumber(s) => {
                diags.push(
                    Diagnostic::error(codes::BAD_NUMBER, span, format!("malformed number `{s}`"), "not a valid number")
                        .with_note("numbers look like `12`, `0.5` or `1.5e-3`"),
                );
                // An empty number evaluates to poison: no second error for the same mistake.
                out.push((Token::Number(""), span));
            }
            Token::BadColor(s) => {
                diags.push(
                    Diagnostic::error(
                        codes::BAD_COLOR,
                        span,
                        format!("malformed colour `{s}`"),
                        "expected `#` and six hex digits",
                    )
                    .with_hint("try `#rrggbb`, e.g. `#ff8800`, or `rgb(255, 136, 0)`"),
                );
                out.push((Token::HexColor("#000000"), span));
            }
            Token::Error(s) => {
                // `1.` directly after a number: report the number as malformed, not the dot.
                let glued = s == "." && matches!(out.last(), Some((Token::Number(_), prev)) if prev.end == span.start);
                if glued {
                    let prev = out.last().map_or(span, |(_, s)| *s);
                    diags.push(
                        Diagnostic::error(
                            codes::BAD_NUMBER,
                            prev.to(span),
                            "malformed number",
                            "a decimal point needs digits after it",
                        )
                        .with_hint("try writing `.0` after the point, or removing the point"),
                    );
                } else {
                    let mut d = Diagnostic::error(
                        codes::UNEXPECTED_CHAR,
                        span,
                        format!("unexpected character `{}`", s.escape_debug()),
                        "no token starts with this",
                    );
                    if s == ";" {
                        d = d.with_note("statements need no separator");
                    } else if s == "." {
                        d = d.with_hint("ranges are written `a..b`");
                    }
                    diags.push(d);
                }
            }
            Token::ForeignLogic(s) => {
                let (word, tok) = match s {
                    "&&" => ("and", Token::And),
                    "||" => ("or", Token::Or),
                    _ => ("not", Token::Not),
                };
                diags.push(
                    Diagnostic::error(
                        codes::FOREIGN_OPERATOR,
                        span,
                        format!("`{s}` is not an operator in scnc"),
                        format!("scnc writes this `{word}`"),
                    )
                    .with_replacement(span, word),
                );
                // Parsed as the word meant, so the rest of the expression is still checked.
                out.push((tok, span));
            }
            tok => out.push((tok, span)),
        }
    }
    out
}

/// Rejects bracket nesting deeper than [`MAX_NESTING`].
fn check_nesting(tokens: &[(Token<'_>, Span)]) -> Option<Diagnostic> {
    let mut depth = 0usize;
    for (tok, span) in tokens {
        match tok {
            Token::LParen | Token::LBracket | Token::LBrace => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Some(
                        Diagnostic::error(
                            codes::TOO_DEEP,
                            *span,
                            "brackets nest too deeply",
                            format!("nesting depth {MAX_NESTING} is exceeded here"),
                        )
                        .with_note(format!("scnc accepts at most {MAX_NESTING} levels of `(`, `[` and `{{`")),
                    );
                }
            }
            Token::RParen | Token::RBracket | Token::RBrace => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

fn describe(p: &RichPattern<'_, Token<'_>>) -> String {
    match p {
        RichPattern::Token(t) => format!("`{}`", &**t),
        RichPattern::Label(l) => l.to_string(),
        RichPattern::Identifier(i) => format!("`{i}`"),
        RichPattern::Any => "any token".into(),
        RichPattern::SomethingElse => "something else".into(),
        RichPattern::EndOfInput => "end of input".into(),
        _ => "something else".into(),
    }
}

fn list_alternatives(mut items: Vec<String>) -> String {
    items.sort();
    items.dedup();
    match items.len() {
        0 => "something else".into(),
        1 => items.remove(0),
        n => format!("{} or {}", items[..n - 1].join(", "), items[n - 1]),
    }
}

fn to_diagnostic(err: &parser::ParseError<'_, '_>) -> Diagnostic {
    let span = Span::from(*err.span());
    let found = err.found().map_or("end of input".to_string(), |t| format!("`{t}`"));
    match err.reason() {
        chumsky::error::RichReason::Custom(msg) => {
            Diagnostic::error(codes::SYNTAX, span, msg.clone(), "not expected here")
        }
        chumsky::error::RichReason::ExpectedFound { .. } => {
            let mut items: Vec<String> =
                err.expected().filter(|p| !matches!(p, RichPattern::SomethingElse)).map(describe).collect();
            // The pieces an expression may start with read better as one word.
            const STARTS: [&str; 11] = [
                "`(`",
                "`-`",
                "`not`",
                "`if`",
                "identifier",
                "literal",
                "mesh",
                "vector or list",
                "list comprehension",
                "if expression",
                "expression",
            ];
            if items.iter().filter(|i| STARTS.contains(&i.as_str())).count() > 1 {
                items.retain(|i| !STARTS.contains(&i.as_str()));
                items.push("expression".into());
            }
            let expected = list_alternatives(items);
            let mut d = Diagnostic::error(
                codes::SYNTAX,
                span,
                format!("expected {expected}, found {found}"),
                format!("unexpected {found}"),
            );
            for (label, ctx_span) in err.contexts() {
                d = d.with_label(Span::from(*ctx_span), format!("while parsing this {}", describe(label)));
            }
            if let Some(Token::Ident(word @ ("elif" | "elsif" | "elseif"))) = err.found() {
                d = d.with_hint(format!("scnc writes `else if`, not `{word}`"));
            }
            // A word from another tool where scnc wants its own (`translate` for `at`).
            if let Some(Token::Ident(word)) = err.found() {
                if let Some(g) = guesses::guess(word) {
                    d = d.with_hint(g.hint);
                    if let Some(r) = g.replacement.filter(|r| *r == "at") {
                        d = d.with_fix(span, r);
                    }
                }
            }
            // OpenSCAD's `rotate([…]) shape`: a transform where an expression must start.
            if let Some(kw @ (Token::Rotate | Token::Scale | Token::At | Token::With)) = err.found() {
                if expected.contains("expression") {
                    d = d.with_hint(guesses::postfix_hint(&kw.to_string()));
                }
            }
            let keyword = err.found().map(|t| t.to_string()).filter(|t| Token::KEYWORDS.contains(&t.as_str()));
            if let (Some(kw), true) = (keyword, expected.contains("identifier")) {
                d = d.with_note(format!("`{kw}` is a keyword and cannot be used as a name"));
            }
            d
        }
    }
}

/// Lexes and parses one file. Always returns a file (possibly with error nodes) and the
/// diagnostics found; an empty `Vec` means the syntax is clean.
pub fn parse(text: &str, base: u32) -> (ast::File, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let tokens = clean_tokens(lex(text, base), &mut diags);
    if let Some(d) = check_nesting(&tokens) {
        diags.push(d);
        return (ast::File::default(), diags);
    }
    // "End of input" points just after the last token, not past trailing blank lines:
    // that is where an editor shows it, and a line every renderer agrees exists.
    let end = base as usize + text.trim_end().len();
    let eoi = SimpleSpan::from(end..end);
    // The parser works on chumsky's span type; ours convert back from it.
    let tokens_ss: Vec<(Token<'_>, SimpleSpan)> =
        tokens.iter().map(|(t, s)| (t.clone(), SimpleSpan::from(s.range()))).collect();
    let input = tokens_ss.as_slice().map(eoi, |(t, s)| (t, s));
    let (file, errs) = parser::file().parse(input).into_output_errors();
    diags.extend(errs.iter().map(to_diagnostic));
    (file.unwrap_or_default(), diags)
}
