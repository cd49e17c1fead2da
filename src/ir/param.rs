//! A scene's parameters: the `param` statements a customizer shows and `-D` sets.

use crate::span::Span;

/// One `param` of the scene, with the value this evaluation gave it.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneParam {
    /// Its name.
    pub name: String,
    /// The value written in the file.
    pub default: ParamValue,
    /// The value used: the default, or what `-D`, a parameter set or the studio set.
    pub value: ParamValue,
    /// `in lo .. hi`: the numbers it may take, both ends included.
    pub range: Option<(f64, f64)>,
    /// `in [a, b, …]`: the values it may take (empty when any value of its type may be).
    pub choices: Vec<ParamValue>,
    /// A slider's step.
    pub step: Option<f64>,
    /// What it means, for people.
    pub description: Option<String>,
    /// The heading a customizer shows it under.
    pub group: Option<String>,
    /// The whole statement.
    pub span: Span,
    /// The default's expression: what a customizer rewrites to write a value back.
    pub default_span: Span,
}

/// A parameter's value: the types a customizer can offer a control for.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    /// A number: a slider, a spin box, or a drop-down of choices.
    Num(f64),
    /// A checkbox.
    Bool(bool),
    /// A text box, or a drop-down of choices.
    Str(String),
    /// A colour, 0–255 per channel.
    Color([f64; 3]),
}

impl ParamValue {
    /// The type's name as `scnc params` writes it.
    pub fn ty(&self) -> &'static str {
        match self {
            ParamValue::Num(_) => "num",
            ParamValue::Bool(_) => "bool",
            ParamValue::Str(_) => "str",
            ParamValue::Color(_) => "color",
        }
    }

    /// The value as JSON: a number, a boolean, a string, or `[r, g, b]`.
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            ParamValue::Num(x) => serde_json::json!(x),
            ParamValue::Bool(b) => serde_json::json!(b),
            ParamValue::Str(s) => serde_json::json!(s),
            ParamValue::Color(c) => serde_json::json!(c),
        }
    }

    /// The value as `.scn` source: what writing it back into the file puts there.
    pub fn source(&self) -> String {
        match self {
            ParamValue::Num(x) => super::dump_num(*x),
            ParamValue::Bool(b) => b.to_string(),
            ParamValue::Str(s) => {
                let mut out = String::from('"');
                for c in s.chars() {
                    match c {
                        '"' => out.push_str("\\\""),
                        '\\' => out.push_str("\\\\"),
                        '\n' => out.push_str("\\n"),
                        '\t' => out.push_str("\\t"),
                        c => out.push(c),
                    }
                }
                out.push('"');
                out
            }
            ParamValue::Color(c) => format!("rgb({}, {}, {})", c[0], c[1], c[2]),
        }
    }

    /// Reads `text` as a value of `like`'s type: a number, `true`/`false`, a string
    /// (quoted or not) or a colour (`#rrggbb` or `rgb(r, g, b)`); what was wrong otherwise.
    pub fn parse(text: &str, like: &ParamValue) -> Result<ParamValue, String> {
        let t = text.trim();
        match like {
            ParamValue::Num(_) => match t.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(ParamValue::Num(x)),
                _ => Err(format!("`{t}` is not a number")),
            },
            ParamValue::Bool(_) => match t {
                "true" => Ok(ParamValue::Bool(true)),
                "false" => Ok(ParamValue::Bool(false)),
                _ => Err(format!("`{t}` is not `true` or `false`")),
            },
            ParamValue::Str(_) => {
                let unquoted = t.strip_prefix('"').and_then(|s| s.strip_suffix('"'));
                Ok(ParamValue::Str(unquoted.unwrap_or(t).to_string()))
            }
            ParamValue::Color(_) => parse_color(t).map(ParamValue::Color).ok_or_else(|| {
                format!("`{t}` is not a colour: write `#rrggbb` or `rgb(r, g, b)` with channels from 0 to 255")
            }),
        }
    }
}

fn parse_color(t: &str) -> Option<[f64; 3]> {
    if let Some(hex) = t.strip_prefix('#').filter(|h| h.len() == 6 && h.is_ascii()) {
        let channel = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok().map(f64::from);
        return Some([channel(0)?, channel(2)?, channel(4)?]);
    }
    let inner = t.strip_prefix("rgb(")?.strip_suffix(')')?;
    let parts: Vec<f64> = inner.split(',').map(|p| p.trim().parse::<f64>()).collect::<Result<_, _>>().ok()?;
    match parts[..] {
        [r, g, b] if parts.iter().all(|c| (0.0..=255.0).contains(c)) => Some([r, g, b]),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::ParamValue;

    #[test]
    fn values_read_by_their_type_and_write_back_as_source() {
        let num = ParamValue::Num(0.0);
        assert_eq!(ParamValue::parse(" 2.5 ", &num), Ok(ParamValue::Num(2.5)));
        assert!(ParamValue::parse("inf", &num).is_err());
        assert!(ParamValue::parse("ten", &num).is_err());
        assert_eq!(ParamValue::parse("false", &ParamValue::Bool(true)), Ok(ParamValue::Bool(false)));
        assert!(ParamValue::parse("no", &ParamValue::Bool(true)).is_err());
        let s = ParamValue::Str(String::new());
        assert_eq!(ParamValue::parse("\"round\"", &s), Ok(ParamValue::Str("round".into())));
        assert_eq!(ParamValue::parse("round", &s), Ok(ParamValue::Str("round".into())));
        let c = ParamValue::Color([0.0; 3]);
        assert_eq!(ParamValue::parse("#ff8000", &c), Ok(ParamValue::Color([255.0, 128.0, 0.0])));
        assert_eq!(ParamValue::parse("rgb(1, 2, 3)", &c), Ok(ParamValue::Color([1.0, 2.0, 3.0])));
        assert!(ParamValue::parse("rgb(1, 2, 300)", &c).is_err());
        assert!(ParamValue::parse("#ff80", &c).is_err());
        assert_eq!(ParamValue::Str("a \"b\"".into()).source(), "\"a \\\"b\\\"\"");
        assert_eq!(ParamValue::Color([1.0, 2.0, 3.0]).source(), "rgb(1, 2, 3)");
    }
}
