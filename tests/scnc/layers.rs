//! The modules of `src/` stand in layers: no top-level module reaches, through any chain
//! of `crate::…` paths, back to itself. A cycle between two modules means neither can be
//! read, tested or changed alone (the tracer and the SDF back-end were one until the
//! tracer's vocabulary moved into `trace`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("reading src/") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`None` for the crate root and the binary).
fn module_of(path: &Path) -> Option<String> {
    let rel = path.strip_prefix("src").ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    match first {
        "lib.rs" | "main.rs" => None,
        f => Some(f.trim_end_matches(".rs").to_string()),
    }
}

/// The top-level modules a line of code names through `crate::` (comments left out:
/// a doc link is not a dependency of the code).
fn named(line: &str) -> Vec<String> {
    let code = line.split("//").next().unwrap_or("");
    code.match_indices("crate::")
        .filter(|(i, _)| !code[..*i].ends_with(|c: char| c.is_alphanumeric() || c == '_'))
        .filter_map(|(i, _)| {
            let rest = &code[i + "crate::".len()..];
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            (!name.is_empty()).then_some(name)
        })
        .collect()
}

/// A cycle in `graph`, if there is one, as the modules along it.
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    // Depth-first search with the path on a stack: an edge back into the path closes a cycle.
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|n| n == node) {
            let mut found = path[at..].to_vec();
            found.push(node.to_string());
            return Some(found);
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|n| visit(n, graph, &mut Vec::new(), &mut done))
}

#[test]
fn top_level_modules_form_no_cycle() {
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    // Where each edge was seen first, to name it in a failure.
    let mut seen: BTreeMap<(String, String), String> = BTreeMap::new();
    let roots = root_names(&files);
    for file in &files {
        let Some(from) = module_of(file) else { continue };
        let text = std::fs::read_to_string(file).expect("reading a source file");
        // Unit tests may reach anywhere; they are not part of the layering.
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for (n, line) in code.lines().enumerate() {
            // `crate::compile_source` is the crate root's re-export of `compile`'s, and
            // `crate::params!` the macro `sig` exports: the edge goes to where it lives.
            for to in named(line).into_iter().map(|m| roots.get(&m).cloned().unwrap_or(m)) {
                if to != from {
                    seen.entry((from.clone(), to.clone())).or_insert_with(|| format!("{}:{}", file.display(), n + 1));
                    graph.entry(from.clone()).or_default().insert(to);
                }
            }
        }
    }
    assert!(graph.len() > 10, "the layering test found too few modules: {graph:?}");
    if let Some(c) = cycle(&graph) {
        let ties: Vec<String> =
            c.windows(2).map(|w| format!("{} -> {} ({})", w[0], w[1], seen[&(w[0].clone(), w[1].clone())])).collect();
        panic!("the modules {} import each other in a cycle:\n{}", c.join(" -> "), ties.join("\n"));
    }
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let edges = [("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")];
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, b) in edges {
        graph.entry(a.into()).or_default().insert(b.into());
    }
    assert_eq!(cycle(&graph), Some(vec!["a".into(), "b".into(), "c".into(), "a".into()]));
    graph.get_mut("c").map(|s| s.remove("a"));
    assert_eq!(cycle(&graph), None);
    assert_eq!(named("use crate::render::{Frame}; // crate::sdf"), vec!["render".to_string()]);
}

/// What a path from the crate root can name besides a module: the names `src/lib.rs`
/// re-exports (`pub use compile::{…}`) and the macros a module exports
/// (`#[macro_export] macro_rules! params`), each with the module it lives in.
fn root_names(files: &[PathBuf]) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let lib = std::fs::read_to_string("src/lib.rs").expect("src/lib.rs");
    for item in lib.split(';').filter_map(|i| i.trim().strip_prefix("pub use ")) {
        let (module, names) = item.split_once("::").expect("pub use MODULE::…");
        for name in names.trim_matches(|c| c == '{' || c == '}' || char::is_whitespace(c)).split(',') {
            let name = name.trim();
            if !name.is_empty() {
                out.insert(name.to_string(), module.trim().to_string());
            }
        }
    }
    for file in files {
        let Some(module) = module_of(file) else { continue };
        let text = std::fs::read_to_string(file).expect("reading a source file");
        for (i, _) in text.match_indices("#[macro_export]") {
            let rest = &text[i..];
            if let Some(at) = rest.find("macro_rules!") {
                let name: String = rest[at + "macro_rules!".len()..]
                    .trim_start()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                out.insert(name, module.clone());
            }
        }
    }
    out
}

/// The crate root is a list of modules and the re-exports of a few of their items:
/// nothing of its own that a module could import upward.
#[test]
fn the_crate_root_is_a_module_list() {
    let lib = std::fs::read_to_string("src/lib.rs").expect("src/lib.rs");
    let mut in_use = false;
    for line in lib.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with("//")) {
        if in_use || line.starts_with("pub use ") {
            in_use = !line.ends_with(';');
            continue;
        }
        assert!(line.starts_with("pub mod ") && line.ends_with(';'), "src/lib.rs holds `{line}`");
    }
    let roots = root_names(&[]);
    assert_eq!(roots.get("compile_source").map(String::as_str), Some("compile"), "{roots:?}");
}

/// No two public types share a name anywhere in `src/`: a reader (and a search) meeting
/// `Expr` or `Body` must know which one it is without looking at the imports. (The IR's
/// field expression was `Expr` beside the syntax tree's, `Kind` beside the builtins'.)
#[test]
fn public_type_names_are_unique() {
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut by_name: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("reading a source file");
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        for line in code.lines() {
            let line = line.trim_start();
            for kind in ["pub struct ", "pub enum ", "pub type ", "pub trait "] {
                if let Some(rest) = line.strip_prefix(kind) {
                    let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                    by_name.entry(name).or_default().push(file.display().to_string());
                }
            }
        }
    }
    let shared: Vec<String> =
        by_name.iter().filter(|(_, at)| at.len() > 1).map(|(n, at)| format!("{n}: {}", at.join(", "))).collect();
    assert!(by_name.len() > 100, "only {} public types found: is the scan reading src/?", by_name.len());
    assert!(shared.is_empty(), "public types of one name:\n{}", shared.join("\n"));
}
