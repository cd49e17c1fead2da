//! The TextMate grammar and the VS Code extension: valid JSON, the expected scopes, and
//! exactly the keywords and builtins the compiler knows, so the two cannot drift apart.

use std::collections::BTreeSet;

use scnc::builtins::{self, Kind};
use scnc::syntax::Token;
use serde_json::Value;

fn json(path: &str) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path} is not valid JSON: {e}"))
}

/// Every `(scope, match)` pair in the grammar, scopes of captures included.
fn rules(v: &Value, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(map) => {
            let pattern = map.get("match").or_else(|| map.get("begin")).and_then(Value::as_str);
            if let Some(pattern) = pattern {
                let mut scopes: Vec<&str> = map.get("name").and_then(Value::as_str).into_iter().collect();
                if let Some(Value::Object(caps)) = map.get("captures") {
                    scopes.extend(caps.values().filter_map(|c| c["name"].as_str()));
                }
                out.extend(scopes.iter().map(|s| (s.to_string(), pattern.to_string())));
            }
            map.values().for_each(|v| rules(v, out));
        }
        Value::Array(items) => items.iter().for_each(|v| rules(v, out)),
        _ => {}
    }
}

/// The words of every `\b(?:a|b|c)\b` alternation in rules whose scope starts with `scope`.
fn words(rules: &[(String, String)], scope: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (_, pattern) in rules.iter().filter(|(s, _)| s.starts_with(scope)) {
        for group in pattern.split("\\b(?:").skip(1) {
            let Some(end) = group.find(")\\b") else { continue };
            out.extend(group[..end].split('|').map(str::to_string));
        }
    }
    out
}

#[test]
fn grammar_knows_exactly_the_compilers_words() {
    // The builtins' alternations are generated from the table: `UPDATE_EXPECT=1` rewrites
    // them, so a new builtin is highlighted without anyone editing the grammar by hand.
    if crate::support::updating() {
        regenerate_builtin_words("grammar/scn.tmLanguage.json");
    }
    let grammar = json("grammar/scn.tmLanguage.json");
    assert_eq!(grammar["scopeName"], "source.scn");
    let mut all = Vec::new();
    rules(&grammar, &mut all);
    for scope in [
        "comment.line.double-slash.scn",
        "comment.block.scn",
        "string.quoted.double.scn",
        "constant.numeric.scn",
        "constant.other.color.rgb-value.scn",
        "keyword.operator.arithmetic.scn",
        "entity.name.function.scn",
        "variable.parameter.scn",
        "variable.parameter.field.scn",
        "keyword.operator.arrow.field.scn",
        "variable.other.property.component.scn",
    ] {
        assert!(all.iter().any(|(s, _)| s == scope), "no rule has scope {scope}");
    }
    // Every `#name` include has its repository entry.
    let mut includes = Vec::new();
    collect_includes(&grammar, &mut includes);
    for name in includes {
        assert!(grammar["repository"].get(name.trim_start_matches('#')).is_some(), "`{name}` is not defined");
    }

    let set = |it: &mut dyn Iterator<Item = &str>| it.map(str::to_string).collect::<BTreeSet<String>>();
    let keywords: BTreeSet<String> =
        ["keyword", "storage", "constant.language.boolean"].iter().flat_map(|s| words(&all, s)).collect();
    assert_eq!(keywords, set(&mut Token::KEYWORDS.iter().copied()), "keywords");
    assert_eq!(words(&all, "support.function.builtin"), set(&mut builtins::names(Kind::Function)), "builtins");
    assert_eq!(words(&all, "support.function.mesh"), set(&mut builtins::names(Kind::MeshGenerator)), "mesh generators");
    let constants = set(&mut builtins::CONSTANTS.iter().map(|c| c.name));
    assert_eq!(words(&all, "constant.language.scn"), constants, "constants");
}

/// Rewrites the alternations of builtin names in the grammar at `path` (the rules
/// `builtins` and `mesh`) from the table, in table order, each name once.
fn regenerate_builtin_words(path: &str) {
    let text = std::fs::read_to_string(path).expect("reading the grammar");
    let alternation = |kind: Kind| {
        let mut seen = BTreeSet::new();
        let names: Vec<&str> = builtins::names(kind).filter(|n| seen.insert(*n)).collect();
        // As the JSON file spells the regex `\b(?:a|b)\b(?=\s*\()`.
        format!(r#""match": "\\b(?:{})\\b(?=\\s*\\()""#, names.join("|"))
    };
    let mut rule = None;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            let trimmed = line.trim_start();
            if trimmed.starts_with(r#""builtins": {"#) {
                rule = Some(Kind::Function);
            } else if trimmed.starts_with(r#""mesh": {"#) {
                rule = Some(Kind::MeshGenerator);
            }
            match rule {
                Some(kind) if trimmed.starts_with(r#""match": "#) => {
                    rule = None;
                    format!("{}{}", &line[..line.len() - trimmed.len()], alternation(kind))
                }
                _ => line.to_string(),
            }
        })
        .collect();
    std::fs::write(path, lines.join("\n") + "\n").expect("writing the grammar");
}

fn collect_includes(v: &Value, out: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            if let Some(Value::String(s)) = map.get("include") {
                out.push(s.clone());
            }
            map.values().for_each(|v| collect_includes(v, out));
        }
        Value::Array(items) => items.iter().for_each(|v| collect_includes(v, out)),
        _ => {}
    }
}

#[test]
fn vscode_extension_uses_the_grammar_and_the_server() {
    let package = json("editors/vscode/package.json");
    let grammar = &package["contributes"]["grammars"][0];
    assert_eq!(grammar["scopeName"], "source.scn");
    let path = format!("editors/vscode/{}", grammar["path"].as_str().expect("grammar path"));
    // The extension's grammar is a link to grammar/, not a copy that could go stale.
    assert_eq!(
        std::fs::read(&path).expect("reading the extension's grammar"),
        std::fs::read("grammar/scn.tmLanguage.json").expect("reading the grammar")
    );
    assert_eq!(package["contributes"]["languages"][0]["extensions"][0], ".scn");
    let config = json("editors/vscode/language-configuration.json");
    assert_eq!(config["comments"]["lineComment"], "//");
    let main = std::fs::read_to_string("editors/vscode/extension.js").expect("reading extension.js");
    assert!(main.contains("args: [\"lsp\"]"), "the extension must start `scnc lsp`");
}
