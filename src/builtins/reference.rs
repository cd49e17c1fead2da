//! The language's reference of builtins, written from the table: `docs/builtins.md` is
//! this text (a test keeps it so), so the reference says what the checker checks.

use std::fmt::Write as _;

use super::{Builtin, Ctor, BUILTINS, CONSTANTS};
use crate::sig::{Default, Ty};

/// The sections of the reference, in order.
const SECTIONS: [&str; 9] = [
    "Primitives",
    "Operators and modifiers",
    "Fields",
    "Profiles and sweeps",
    "Materials, colours and patterns",
    "Lights",
    "Numbers, vectors and lists",
    "Mesh generators (after `mesh`)",
    "Statements",
];

/// The section a builtin is listed in: a match over every kind of builtin, so a new
/// kind cannot be left out of the reference.
fn section(b: &Builtin) -> usize {
    match b.ctor {
        Ctor::Primitive(_) => 0,
        Ctor::Csg(_) | Ctor::Modifier(_) => 1,
        Ctor::Field(_) | Ctor::Dist | Ctor::Noise3 => 2,
        Ctor::Profile(_) => 3,
        Ctor::Material | Ctor::Rgb | Ctor::Pattern(_) => 4,
        Ctor::Light(_) => 5,
        Ctor::Math(_) | Ctor::Numeric(_) | Ctor::Vector(_) | Ctor::Extreme(_) | Ctor::Len => 6,
        Ctor::Generator(_) => 7,
        Ctor::Camera | Ctor::Render => 8,
    }
}

/// The reference in Markdown.
pub fn reference() -> String {
    let mut out = String::from(
        "# Builtins\n\nEvery builtin of the language, its parameters, their defaults and the values they take. \
         Written from the compiler's own table (`UPDATE_EXPECT=1 cargo test reference` rewrites it), so the values \
         listed are the values checked. Angles are in degrees.\n",
    );
    for (i, title) in SECTIONS.iter().enumerate() {
        let _ = write!(out, "\n## {title}\n");
        for b in BUILTINS.iter().filter(|b| section(b) == i) {
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
