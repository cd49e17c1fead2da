//! The language's reference of builtins, written from the table: `docs/builtins.md` is
//! this text (a test keeps it so), so the reference says what the checker checks.

use std::fmt::Write as _;

use super::{Builtin, Ctor, Kind, BUILTINS, CONSTANTS};
use crate::sig::{Default, Ty};

/// Whether a builtin belongs in a section.
type Holds = fn(&Builtin) -> bool;

/// The sections of the reference, each with the builtins it holds.
const SECTIONS: &[(&str, Holds)] = &[
    ("Primitives", |b| matches!(b.ctor, Ctor::Primitive(_))),
    ("Operators and modifiers", |b| matches!(b.ctor, Ctor::Csg(_) | Ctor::Modifier(_))),
    ("Materials, colours and patterns", |b| matches!(b.ctor, Ctor::Material | Ctor::Rgb | Ctor::Pattern(_))),
    ("Lights", |b| matches!(b.ctor, Ctor::Light(_))),
    ("Numbers, vectors and lists", |b| {
        matches!(b.ctor, Ctor::Math(_) | Ctor::Numeric(_) | Ctor::Vector(_) | Ctor::Extreme(_) | Ctor::Len)
    }),
    ("Mesh generators (after `mesh`)", |b| b.kind() == Kind::MeshGenerator),
    ("Statements", |b| matches!(b.kind(), Kind::Camera | Kind::Render)),
];

/// The reference in Markdown.
pub fn reference() -> String {
    let mut out = String::from(
        "# Builtins\n\nEvery builtin of the language, its parameters, their defaults and the values they take. \
         Written from the compiler's own table (`UPDATE_EXPECT=1 cargo test reference` rewrites it), so the values \
         listed are the values checked. Angles are in degrees.\n",
    );
    for (title, holds) in SECTIONS {
        let _ = write!(out, "\n## {title}\n");
        for b in BUILTINS.iter().filter(|b| holds(b)) {
            let _ = write!(out, "\n### `{}`\n\n{}", b.signature(), sentence(b.doc));
            if let Some(ty) = b.variadic {
                let _ = write!(out, " Takes any number of `{ty}` arguments first (a list stands for its elements).");
            }
            out.push('\n');
            if !b.params.is_empty() {
                out.push_str("\n| parameter | type | default | values | |\n|---|---|---|---|---|\n");
                for p in b.params {
                    let default = match p.default {
                        Default::Required => "required".to_string(),
                        Default::Derived => "derived".to_string(),
                        _ => format!("`{}`", p.describe().split(" = ").nth(1).unwrap_or_default()),
                    };
                    let values = if p.range.is_any() { String::new() } else { p.range.rule(p.is_vector()) };
                    let _ = writeln!(out, "| `{}` | {} | {default} | {values} | {} |", p.name, ty(p.ty), p.doc);
                }
            }
        }
    }
    out.push_str("\n## Constants\n\n| name | type | |\n|---|---|---|\n");
    for c in CONSTANTS {
        let _ = writeln!(out, "| `{}` | {} | {} |", c.name, ty(c.ty), c.doc.replace('\n', " "));
    }
    out
}

fn ty(t: Ty) -> String {
    format!("`{t}`")
}

/// A doc line as a sentence: capitalised, ending in a full stop.
fn sentence(doc: &str) -> String {
    let mut chars = doc.chars();
    let first = chars.next().map(|c| c.to_uppercase().collect::<String>()).unwrap_or_default();
    let rest: String = chars.collect();
    let end = if rest.ends_with('.') { "" } else { "." };
    format!("{first}{rest}{end}")
}
