//! Tokens of the `.scn` language, produced by logos.

use std::fmt;

use logos::Logos;

/// One token. Bad input becomes one of the error variants; the lexer never fails.
#[derive(Logos, Clone, Debug, PartialEq)]
// A byte-order mark (Windows Notepad starts files with one) is skipped like whitespace.
#[logos(skip r"[ \t\r\n\f\u{feff}]+")]
pub enum Token<'src> {
    /// `let`
    #[token("let")]
    Let,
    /// `object`
    #[token("object")]
    Object,
    /// `light`
    #[token("light")]
    Light,
    /// `for`
    #[token("for")]
    For,
    /// `in`
    #[token("in")]
    In,
    /// `include`
    #[token("include")]
    Include,
    /// `param`
    #[token("param")]
    Param,
    /// `camera`
    #[token("camera")]
    Camera,
    /// `render`
    #[token("render")]
    Render,
    /// `at`
    #[token("at")]
    At,
    /// `rotate`
    #[token("rotate")]
    Rotate,
    /// `scale`
    #[token("scale")]
    Scale,
    /// `with`
    #[token("with")]
    With,
    /// `mesh`
    #[token("mesh")]
    Mesh,
    /// `if`
    #[token("if")]
    If,
    /// `then`
    #[token("then")]
    Then,
    /// `else`
    #[token("else")]
    Else,
    /// `and`
    #[token("and")]
    And,
    /// `or`
    #[token("or")]
    Or,
    /// `not`
    #[token("not")]
    Not,
    /// `true` or `false`
    #[token("true", |_| true)]
    #[token("false", |_| false)]
    Bool(bool),
    /// A number literal, as written.
    #[regex(r"[0-9]+(\.[0-9]+)?([eE][+-]?[0-9]+)?", priority = 10)]
    Number(&'src str),
    /// An identifier.
    #[regex(r"[A-Za-z_][A-Za-z0-9_]*")]
    Ident(&'src str),
    /// A string literal including its quotes.
    #[regex(r#""([^"\\\n]|\\[^\n])*""#)]
    Str(&'src str),
    /// A `#rrggbb` colour literal.
    #[regex(r"#[0-9a-fA-F]{6}", priority = 10)]
    HexColor(&'src str),
    /// `(`
    #[token("(")]
    LParen,
    /// `)`
    #[token(")")]
    RParen,
    /// `[`
    #[token("[")]
    LBracket,
    /// `]`
    #[token("]")]
    RBracket,
    /// `{`
    #[token("{")]
    LBrace,
    /// `}`
    #[token("}")]
    RBrace,
    /// `,`
    #[token(",")]
    Comma,
    /// `=`
    #[token("=")]
    Eq,
    /// `+`
    #[token("+")]
    Plus,
    /// `-`
    #[token("-")]
    Minus,
    /// `*`
    #[token("*")]
    Star,
    /// `/`
    #[token("/")]
    Slash,
    /// `%`
    #[token("%")]
    Percent,
    /// `..`
    #[token("..")]
    DotDot,
    /// `.`, before a vector's component (`v.x`)
    #[token(".")]
    Dot,
    /// `==`
    #[token("==")]
    EqEq,
    /// `!=`
    #[token("!=")]
    NotEq,
    /// `<`
    #[token("<")]
    Lt,
    /// `<=`
    #[token("<=")]
    Le,
    /// `>`
    #[token(">")]
    Gt,
    /// `>=`
    #[token(">=")]
    Ge,
    /// `=>`
    #[token("=>")]
    Arrow,
    /// `&&`, `||` or `!`: other languages' logic operators, lexed so the error can name
    /// the word scnc uses.
    #[token("&&")]
    #[token("||")]
    #[token("!")]
    ForeignLogic(&'src str),
    /// A `// …` comment to the end of the line.
    #[regex(r"//[^\n]*", allow_greedy = true)]
    LineComment,
    /// A `/* … */` comment; `false` when it runs to the end of the file unclosed.
    #[token("/*", block_comment)]
    BlockComment(bool),
    /// A number with trailing letters or an exponent without digits, e.g. `12ab`, `1e`.
    #[regex(r"[0-9]+(\.[0-9]+)?([eE][+-]?)?[A-Za-z_][A-Za-z0-9_]*|[0-9]+(\.[0-9]+)?[eE][+-]?")]
    // A second dot followed by a digit (`1.2.3`); `0.0..3` is a number and a range.
    #[regex(r"[0-9]+\.[0-9]+\.[0-9][0-9.]*")]
    BadNumber(&'src str),
    /// A `#` not followed by exactly six hex digits.
    #[regex(r"#[0-9A-Za-z_]*")]
    BadColor(&'src str),
    /// A string literal missing its closing quote on the same line.
    #[regex(r#""([^"\\\n]|\\[^\n])*"#)]
    UnterminatedStr(&'src str),
    /// Any character no token starts with.
    Error(&'src str),
}

fn block_comment<'src>(lex: &mut logos::Lexer<'src, Token<'src>>) -> bool {
    let rest = lex.remainder();
    match rest.find("*/") {
        Some(i) => {
            lex.bump(i + 2);
            true
        }
        None => {
            lex.bump(rest.len());
            false
        }
    }
}

impl Token<'_> {
    /// True for the error variants the lexer emits for bad input.
    pub fn is_error(&self) -> bool {
        matches!(
            self,
            Token::BadNumber(_)
                | Token::BadColor(_)
                | Token::UnterminatedStr(_)
                | Token::Error(_)
                | Token::BlockComment(false)
        )
    }

    /// The keywords of the language, as written (the highlighting grammar must list them all).
    pub const KEYWORDS: &'static [&'static str] = &[
        "let", "param", "object", "light", "for", "in", "include", "camera", "render", "at", "rotate", "scale", "with",
        "mesh", "true", "false", "if", "then", "else", "and", "or", "not",
    ];
}

impl fmt::Display for Token<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            Token::Let => "let",
            Token::Object => "object",
            Token::Light => "light",
            Token::For => "for",
            Token::In => "in",
            Token::Include => "include",
            Token::Param => "param",
            Token::Camera => "camera",
            Token::Render => "render",
            Token::At => "at",
            Token::Rotate => "rotate",
            Token::Scale => "scale",
            Token::With => "with",
            Token::Mesh => "mesh",
            Token::If => "if",
            Token::Then => "then",
            Token::Else => "else",
            Token::And => "and",
            Token::Or => "or",
            Token::Not => "not",
            Token::Bool(true) => "true",
            Token::Bool(false) => "false",
            Token::Number(s)
            | Token::Ident(s)
            | Token::Str(s)
            | Token::HexColor(s)
            | Token::BadNumber(s)
            | Token::BadColor(s)
            | Token::UnterminatedStr(s)
            | Token::ForeignLogic(s)
            | Token::Error(s) => s,
            Token::LParen => "(",
            Token::RParen => ")",
            Token::LBracket => "[",
            Token::RBracket => "]",
            Token::LBrace => "{",
            Token::RBrace => "}",
            Token::Comma => ",",
            Token::Eq => "=",
            Token::Plus => "+",
            Token::Minus => "-",
            Token::Star => "*",
            Token::Slash => "/",
            Token::Percent => "%",
            Token::DotDot => "..",
            Token::Dot => ".",
            Token::EqEq => "==",
            Token::NotEq => "!=",
            Token::Lt => "<",
            Token::Le => "<=",
            Token::Gt => ">",
            Token::Ge => ">=",
            Token::Arrow => "=>",
            Token::BlockComment(_) => "/*",
            Token::LineComment => "//",
        };
        write!(f, "{s}")
    }
}
