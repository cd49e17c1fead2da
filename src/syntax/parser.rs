//! chumsky parsers over the token stream: statements, expressions (precedence climbing
//! with `foldl`), error recovery at delimiters and at statement starts.
//!
//! Precedence, loosest first (see `grammar/scn.ebnf`): postfix transforms
//! (`at rotate scale with`), `+ -`, `* / %`, unary `-` and `mesh`, indexing `x[i]` and
//! components `v.x`, atoms. A field literal `p => body` is an argument form only.

use chumsky::input::ValueInput;
use chumsky::prelude::*;

use super::ast::{
    Arg, BinOp, Expr, ExprKind, File, Generator, Ident, Iterable, ParamDecl, ParamDomain, Stmt, StmtKind, TransformOp,
};
use super::token::Token;
use crate::span::Span;

/// The parser's error type.
pub type ParseError<'t, 's> = Rich<'t, Token<'s>, SimpleSpan>;
type Extra<'t, 's> = extra::Err<ParseError<'t, 's>>;

const OTHER_DELIMS: [(Token<'static>, Token<'static>); 2] =
    [(Token::LBracket, Token::RBracket), (Token::LBrace, Token::RBrace)];

fn error_expr(span: SimpleSpan) -> Expr {
    Expr { kind: ExprKind::Error, span: span.into() }
}

fn ident<'t, 's: 't, I>() -> impl Parser<'t, I, Ident, Extra<'t, 's>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
{
    select! { Token::Ident(s) => s }
        .map_with(|s: &str, e| Ident { name: s.to_string(), span: Span::from(e.span()) })
        .labelled("identifier")
}

/// Resolves the escapes `\" \\ \n \t` of a string literal's body.
fn unescape(quoted: &str) -> String {
    let body = &quoted[1..quoted.len() - 1];
    let mut out = String::with_capacity(body.len());
    let mut chars = body.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => {}
            }
        } else {
            out.push(c);
        }
    }
    out
}

fn hex_color(s: &str) -> [u8; 3] {
    let byte = |i: usize| u8::from_str_radix(s.get(1 + 2 * i..3 + 2 * i).unwrap_or("00"), 16).unwrap_or(0);
    [byte(0), byte(1), byte(2)]
}

fn args<'t, 's: 't, I, P>(expr: P) -> impl Parser<'t, I, Vec<Arg>, Extra<'t, 's>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    P: Parser<'t, I, Expr, Extra<'t, 's>> + Clone,
{
    let arg = ident()
        .then_ignore(just(Token::Eq))
        .or_not()
        .then(field_literal(expr.clone()).or(expr))
        .map(|(name, value)| Arg { name, value });
    arg.separated_by(just(Token::Comma))
        .allow_trailing()
        .collect::<Vec<_>>()
        .delimited_by(just(Token::LParen), just(Token::RParen))
        .labelled("argument list")
        .recover_with(via_parser(nested_delimiters(
            Token::LParen,
            Token::RParen,
            OTHER_DELIMS,
            // One error argument tells the checker not to report arity on a list it never saw.
            |span| vec![Arg { name: None, value: error_expr(span) }],
        )))
}

/// `p => body`, a field literal. It is parsed only as an argument and as a `let`'s value
/// (where the checker refuses it with a clear error), never as an operand, so a
/// comprehension's `for x in xs => body` never reads as one.
fn field_literal<'t, 's: 't, I, P>(expr: P) -> impl Parser<'t, I, Expr, Extra<'t, 's>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    P: Parser<'t, I, Expr, Extra<'t, 's>> + Clone,
{
    ident()
        .then_ignore(just(Token::Arrow))
        .then(expr)
        .map_with(|(param, body), e| Expr {
            kind: ExprKind::Field { param, body: Box::new(body) },
            span: Span::from(e.span()),
        })
        .labelled("field literal")
}

/// What follows an atom: `[index]` or `.component`.
enum Postfix {
    Index(Expr),
    Component(Ident),
}

/// `var in start..end` or `var in list`, for loops and comprehensions.
fn generator<'t, 's: 't, I, P>(expr: P) -> impl Parser<'t, I, Generator, Extra<'t, 's>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
    P: Parser<'t, I, Expr, Extra<'t, 's>> + Clone,
{
    ident().then_ignore(just(Token::In)).then(expr.clone()).then(just(Token::DotDot).ignore_then(expr).or_not()).map(
        |((var, first), end)| {
            let over = match end {
                Some(end) => Iterable::Range { start: first, end },
                None => Iterable::List(first),
            };
            Generator { var, over }
        },
    )
}

/// The expression parser.
///
/// Long because it is one combinator chain, a level per precedence in the order
/// `grammar/scn.ebnf` lists them; split, the levels would no longer read top to bottom as
/// the grammar does.
pub fn expr<'t, 's: 't, I>() -> impl Parser<'t, I, Expr, Extra<'t, 's>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
{
    recursive(|expr| {
        let literal = select! {
            Token::Number(s) => ExprKind::Number((!s.is_empty()).then(|| s.parse::<f64>().unwrap_or(f64::INFINITY))),
            Token::Bool(b) => ExprKind::Bool(b),
            Token::Str(s) => ExprKind::Str(unescape(s)),
            Token::HexColor(s) => ExprKind::HexColor(hex_color(s)),
        }
        .labelled("literal");

        let call = ident().then(args(expr.clone())).map(|(callee, args)| ExprKind::Call { callee, args });

        let list = expr
            .clone()
            .separated_by(just(Token::Comma))
            .allow_trailing()
            .collect::<Vec<_>>()
            .delimited_by(just(Token::LBracket), just(Token::RBracket))
            .map(ExprKind::List)
            .labelled("vector or list");

        let comprehension = just(Token::For)
            .ignore_then(generator(expr.clone()).separated_by(just(Token::Comma)).at_least(1).collect::<Vec<_>>())
            .then(just(Token::If).ignore_then(expr.clone()).or_not())
            .then_ignore(just(Token::Arrow))
            .then(expr.clone())
            .delimited_by(just(Token::LBracket), just(Token::RBracket))
            .map(|((generators, filter), body)| ExprKind::Comprehension {
                generators,
                filter: filter.map(Box::new),
                body: Box::new(body),
            })
            .labelled("list comprehension");

        let mesh = just(Token::Mesh)
            .ignore_then(ident().labelled("mesh generator"))
            .then(args(expr.clone()))
            .map(|(generator, args)| ExprKind::Mesh { generator, args })
            .labelled("mesh");

        let atom = choice((
            literal,
            call,
            // A name followed by `(` is a call or nothing: never fall back to a bare name.
            ident().then_ignore(just(Token::LParen).not()).map(ExprKind::Ident),
            comprehension,
            list,
            mesh,
        ))
        .map_with(|kind, e| Expr { kind, span: Span::from(e.span()) })
        .or(expr.clone().delimited_by(just(Token::LParen), just(Token::RParen)))
        .recover_with(via_parser(nested_delimiters(Token::LParen, Token::RParen, OTHER_DELIMS, error_expr)))
        .recover_with(via_parser(nested_delimiters(
            Token::LBracket,
            Token::RBracket,
            [(Token::LParen, Token::RParen), (Token::LBrace, Token::RBrace)],
            error_expr,
        )))
        .boxed();

        // Indexing and components bind tightest, left to right: `ps[0].x`.
        let postfix = choice((
            expr.clone().delimited_by(just(Token::LBracket), just(Token::RBracket)).map(Postfix::Index),
            just(Token::Dot).ignore_then(ident().labelled("component (x, y or z)")).map(Postfix::Component),
        ));
        let index = atom.foldl_with(postfix.repeated(), |base, post, e| Expr {
            kind: match post {
                Postfix::Index(index) => ExprKind::Index { base: Box::new(base), index: Box::new(index) },
                Postfix::Component(axis) => ExprKind::Component { base: Box::new(base), axis },
            },
            span: Span::from(e.span()),
        });

        let unary = just(Token::Minus)
            .to_span()
            .repeated()
            .foldr_with(index, |_, operand, e| Expr {
                kind: ExprKind::Neg(Box::new(operand)),
                span: Span::from(e.span()),
            })
            .boxed();

        let binary = |ops: &'static [(Token<'static>, BinOp)]| {
            move |operand: chumsky::Boxed<'t, 't, I, Expr, Extra<'t, 's>>| {
                let op = select! { t if ops.iter().any(|(o, _)| *o == t) => t }
                    .map(move |t| ops.iter().find(|(o, _)| *o == t).map_or(BinOp::Add, |(_, b)| *b));
                operand
                    .clone()
                    .foldl_with(op.then(operand).repeated(), |lhs, (op, rhs), e| Expr {
                        kind: ExprKind::Binary { op, lhs: Box::new(lhs), rhs: Box::new(rhs) },
                        span: Span::from(e.span()),
                    })
                    .boxed()
            }
        };
        let product =
            binary(&[(Token::Star, BinOp::Mul), (Token::Slash, BinOp::Div), (Token::Percent, BinOp::Rem)])(unary);
        let sum = binary(&[(Token::Plus, BinOp::Add), (Token::Minus, BinOp::Sub)])(product);

        // One comparison at most: `a < b < c` is a syntax error, not `(a < b) < c`.
        let compare_op = select! {
            Token::EqEq => BinOp::Eq,
            Token::NotEq => BinOp::Ne,
            Token::Lt => BinOp::Lt,
            Token::Le => BinOp::Le,
            Token::Gt => BinOp::Gt,
            Token::Ge => BinOp::Ge,
        };
        let comparison = sum
            .clone()
            .then(compare_op.map_with(|op, e| (op, e.span())).then(sum).repeated().at_most(8).collect::<Vec<_>>())
            .validate(|(lhs, rest), e, emitter| {
                if let Some(((_, second), _)) = rest.get(1) {
                    emitter.emit(Rich::custom(
                        *second,
                        "comparisons do not chain: `a < b < c` is written `a < b and b < c`",
                    ));
                }
                match rest.into_iter().next() {
                    None => lhs,
                    Some(((op, _), rhs)) => Expr {
                        kind: ExprKind::Binary { op, lhs: Box::new(lhs), rhs: Box::new(rhs) },
                        span: Span::from(e.span()),
                    },
                }
            })
            .boxed();
        let negation = just(Token::Not)
            .to_span()
            .repeated()
            .foldr_with(comparison, |_, operand, e| Expr {
                kind: ExprKind::Not(Box::new(operand)),
                span: Span::from(e.span()),
            })
            .boxed();
        let conjunction = binary(&[(Token::And, BinOp::And)])(negation);
        let disjunction = binary(&[(Token::Or, BinOp::Or)])(conjunction);

        let transform_op = select! {
            Token::At => TransformOp::At,
            Token::Rotate => TransformOp::Rotate,
            Token::Scale => TransformOp::Scale,
            Token::With => TransformOp::With,
        }
        .map_with(|op, e| (op, Span::from(e.span())));

        let transformed = disjunction.clone().foldl_with(
            transform_op.then(disjunction).repeated(),
            |target, ((op, op_span), arg), e| Expr {
                kind: ExprKind::Transform { op, op_span, target: Box::new(target), arg: Box::new(arg) },
                span: Span::from(e.span()),
            },
        );

        // `if` reaches as far right as it can: `if c then a else b at p` places `b` only.
        // A missing `else` is reported here, where it is missing, rather than failing
        // the statement (whose recovery would take the `if` for an `if` statement).
        let conditional = just(Token::If)
            .ignore_then(expr.clone())
            .then_ignore(just(Token::Then))
            .then(expr.clone())
            .then(just(Token::Else).ignore_then(expr.clone()).or_not())
            .validate(|((cond, then), otherwise), e, emitter| {
                let span = Span::from(e.span());
                let otherwise = otherwise.unwrap_or_else(|| {
                    emitter.emit(Rich::custom(
                        e.span(),
                        "an `if` used as a value needs an `else`: which value is it otherwise?",
                    ));
                    Expr { kind: ExprKind::Error, span }
                });
                Expr {
                    kind: ExprKind::If { cond: Box::new(cond), then: Box::new(then), otherwise: Box::new(otherwise) },
                    span,
                }
            })
            .labelled("if expression");

        conditional.or(transformed).labelled("expression")
    })
}

fn stmt_start<'t, 's: 't, I>() -> impl Parser<'t, I, (), Extra<'t, 's>> + Clone
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
{
    one_of([
        Token::Let,
        Token::Param,
        Token::Object,
        Token::Light,
        Token::For,
        Token::If,
        Token::Include,
        Token::Camera,
        Token::Render,
        Token::RBrace,
    ])
    .ignored()
}

/// The file parser: statements until the end of input.
///
/// Long because it is one combinator chain over the statement forms, in the order
/// `grammar/scn.ebnf` lists them.
pub fn file<'t, 's: 't, I>() -> impl Parser<'t, I, File, Extra<'t, 's>>
where
    I: ValueInput<'t, Token = Token<'s>, Span = SimpleSpan>,
{
    let stmt = recursive(|stmt| {
        let e = expr();
        let settings =
            |kw: Token<'static>, name: &'static str| just(kw).ignore_then(args(expr())).labelled(name).as_context();
        let camera = settings(Token::Camera, "camera statement").map(StmtKind::Camera);
        let render = settings(Token::Render, "render statement").map(StmtKind::Render);
        let light =
            just(Token::Light).ignore_then(e.clone()).map(StmtKind::Light).labelled("light statement").as_context();
        let object =
            just(Token::Object).ignore_then(e.clone()).map(StmtKind::Object).labelled("object statement").as_context();
        let params = ident()
            .separated_by(just(Token::Comma))
            .allow_trailing()
            .collect::<Vec<_>>()
            .delimited_by(just(Token::LParen), just(Token::RParen))
            .labelled("parameter list");
        let let_ = just(Token::Let)
            .ignore_then(ident())
            .then(params.or_not())
            .then_ignore(just(Token::Eq))
            .then(field_literal(e.clone()).or(e.clone()))
            .map(|((name, params), value)| StmtKind::Let { name, params, value })
            .labelled("let statement")
            .as_context();
        let string = select! { Token::Str(s) => unescape(s) }.labelled("string");
        // `step` and `group` are words only here, so scenes may still name values so.
        let word = |w: &'static str| select! { Token::Ident(s) if s == w => () }.labelled(w);
        let domain = just(Token::In)
            .ignore_then(e.clone().then(just(Token::DotDot).ignore_then(e.clone()).or_not()))
            .map(|(first, last)| match last {
                Some(last) => ParamDomain::Range(first, last),
                None => ParamDomain::Choices(first),
            });
        let param = just(Token::Param)
            .ignore_then(ident())
            .then_ignore(just(Token::Eq))
            .then(e.clone())
            .then(domain.or_not())
            .then(word("step").ignore_then(e.clone()).or_not())
            .then(string.or_not())
            .then(word("group").ignore_then(string).or_not())
            .map(|(((((name, default), domain), step), description), group)| {
                StmtKind::Param(Box::new(ParamDecl { name, default, domain, step, description, group }))
            })
            .labelled("param statement")
            .as_context();
        // A body left open at the end of the file ends there (its missing `}` is still
        // reported): failing the whole loop instead made every enclosing open loop parse
        // what follows twice, once inside and once after recovery, 2ⁿ times for n levels.
        let close = just(Token::RBrace).ignored().recover_with(via_parser(end()));
        let body = stmt.repeated().collect::<Vec<_>>().delimited_by(just(Token::LBrace), close);
        let for_ = just(Token::For)
            .ignore_then(generator(e.clone()))
            .then(body.clone())
            .map(|(each, body)| StmtKind::For { each, body })
            .labelled("for loop")
            .as_context();
        let else_if = just(Token::Else).ignore_then(just(Token::If)).ignore_then(e.clone()).then(body.clone());
        let if_ = just(Token::If)
            .ignore_then(e.clone())
            .then(body.clone())
            .then(else_if.repeated().collect::<Vec<_>>())
            .then(just(Token::Else).ignore_then(body).or_not())
            .map(|(((cond, then), more), otherwise)| {
                let mut branches = vec![(cond, then)];
                branches.extend(more);
                StmtKind::If { branches, otherwise }
            })
            .labelled("if statement")
            .as_context();
        let include = just(Token::Include)
            .ignore_then(
                select! { Token::Str(s) => s }
                    .map_with(|s: &str, e| (unescape(s), Span::from(e.span())))
                    .labelled("string"),
            )
            .map(|(path, path_span)| StmtKind::Include { path, path_span })
            .labelled("include statement")
            .as_context();

        choice((camera, render, light, object, let_, param, for_, if_, include))
            .map_with(|kind, e| {
                #[cfg(test)]
                tests::STATEMENTS_BUILT.with(|c| c.set(c.get() + 1));
                Stmt { kind, span: Span::from(e.span()) }
            })
            .labelled("statement")
            // Skip the bad statement up to the next one, so later mistakes are reported too.
            .recover_with(via_parser(
                any()
                    .and_is(just(Token::RBrace).not())
                    .ignored()
                    .then(any().and_is(stmt_start().not()).repeated())
                    .map_with(|_, e| Stmt { kind: StmtKind::Error, span: Span::from(e.span()) }),
            ))
    });
    // A `}` with no `for` to close is reported and skipped at the top level.
    let stray_brace = just(Token::RBrace).validate(|_, e, emitter| {
        emitter.emit(Rich::custom(e.span(), "unmatched `}`"));
        Stmt { kind: StmtKind::Error, span: Span::from(e.span()) }
    });
    stmt.or(stray_brace).repeated().collect::<Vec<_>>().then_ignore(end()).map(|stmts| File { stmts })
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    thread_local! {
        /// Statements the parser has built, failed attempts included: the parser's work.
        pub(super) static STATEMENTS_BUILT: Cell<u64> = const { Cell::new(0) };
    }

    /// Loops left open down to the end of the file are parsed once each: the work grows
    /// with the input, not 2ⁿ with the depth (judged by statements built, not by time).
    #[test]
    fn unclosed_loops_are_parsed_in_linear_work() {
        for depth in [4u64, 16, 100] {
            let text = "for i in 0..1 {\nobject sphere(1)\n".repeat(depth as usize);
            STATEMENTS_BUILT.with(|c| c.set(0));
            let (file, diags) = crate::syntax::parse(&text, 0);
            let built = STATEMENTS_BUILT.with(Cell::get);
            assert!(built <= 2 * depth, "depth {depth}: {built} statements built");
            assert_eq!(file.stmts.len(), 1, "one outer loop holding the rest");
            assert!(!diags.is_empty(), "the missing braces are reported");
        }
    }
}
