//! The README works as written on a fresh clone: every command of its `sh` blocks runs
//! in a copy of the repository's files (what a clone has) and succeeds, and every link
//! of the README and the docs points at a file that is there.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The files a clone would have: tracked, and new ones not ignored (so a file about to
/// be committed counts, and a build product never does).
fn clone_files() -> Vec<PathBuf> {
    let out = Command::new("git")
        .args(["ls-files", "--cached", "--others", "--exclude-standard", "-z"])
        .output()
        .expect("running git ls-files");
    assert!(out.status.success(), "git ls-files: {}", String::from_utf8_lossy(&out.stderr));
    out.stdout
        .split(|&b| b == 0)
        .filter(|p| !p.is_empty())
        .map(|p| PathBuf::from(String::from_utf8_lossy(p).into_owned()))
        .filter(|p| p.exists())
        .collect()
}

/// A fresh copy of the repository's files in a temporary directory.
fn fresh_clone() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    for file in clone_files() {
        let to = dir.path().join(&file);
        std::fs::create_dir_all(to.parent().expect("a parent")).expect("making a directory");
        // Links are copied as links (the VS Code extension's grammar is one).
        match std::fs::read_link(&file) {
            Ok(target) => {
                #[cfg(unix)]
                std::os::unix::fs::symlink(target, &to).expect("copying a link");
            }
            Err(_) => {
                std::fs::copy(&file, &to).expect("copying a file");
            }
        }
    }
    dir
}

/// The command lines of the `sh` blocks of a Markdown text, comments removed.
fn shell_commands(markdown: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    for line in markdown.lines() {
        if let Some(lang) = line.strip_prefix("```") {
            in_sh = !in_sh && lang.trim() == "sh";
            continue;
        }
        if in_sh {
            let command = line.split(" #").next().unwrap_or("").trim();
            if !command.is_empty() && !command.starts_with('#') {
                out.push(command.to_string());
            }
        }
    }
    out
}

/// Commands the test does not run itself, and why: it is one (`cargo test`), and an
/// install builds the release binary the test already has.
const NOT_RUN: &[&str] = &["cargo test --release", "cargo install --locked --path ."];

#[test]
fn every_readme_command_works_on_a_fresh_clone() {
    let readme = std::fs::read_to_string("README.md").expect("reading README.md");
    let commands = shell_commands(&readme);
    assert!(commands.len() >= 4, "{commands:?}");
    let clone = fresh_clone();
    let bin = Path::new(env!("CARGO_BIN_EXE_scnc")).parent().expect("the binary's directory");
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    for command in commands {
        if NOT_RUN.contains(&command.as_str()) {
            continue;
        }
        // `cargo run --release --` is the binary under test (already built).
        let line = command.replacen("cargo run --release --", "scnc", 1);
        assert!(line.starts_with("scnc "), "a README command the test cannot run: `{command}`");
        if line.starts_with("scnc studio ") {
            serves_its_page(&line, clone.path(), &path);
            continue;
        }
        let out = Command::new("sh")
            .args(["-c", &line])
            .current_dir(clone.path())
            .env("PATH", &path)
            .env("NO_COLOR", "1")
            .output()
            .expect("running a README command");
        assert!(
            out.status.success(),
            "`{command}` failed on a fresh clone ({}):\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        // What it says it writes, it writes.
        let words: Vec<&str> = line.split_whitespace().collect();
        if let Some(i) = words.iter().position(|w| *w == "-o") {
            let written = clone.path().join(words[i + 1]);
            assert!(written.exists(), "`{command}` did not write {}", written.display());
        }
    }
}

/// A server command (`scnc studio …`) runs until stopped: it must say where it listens,
/// and answer there with its page.
fn serves_its_page(line: &str, dir: &Path, path: &str) {
    use std::io::{BufRead as _, Read as _, Write as _};
    let words: Vec<&str> = line.split_whitespace().collect();
    let mut child = Command::new(words[0])
        .args(&words[1..])
        .current_dir(dir)
        .env("PATH", path)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starting the studio");
    let stderr = child.stderr.take().expect("its stderr");
    let first = std::io::BufReader::new(stderr).lines().next().and_then(Result::ok).unwrap_or_default();
    let served = first.split_whitespace().find_map(|w| w.strip_prefix("http://")).map(|a| a.trim_end_matches('/'));
    let page = served.and_then(|addr| {
        let mut s = std::net::TcpStream::connect(addr).ok()?;
        s.set_read_timeout(Some(std::time::Duration::from_secs(20))).ok()?;
        write!(s, "GET / HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").ok()?;
        let mut reply = String::new();
        s.read_to_string(&mut reply).ok()?;
        Some(reply)
    });
    let _ = child.kill();
    let _ = child.wait();
    let page = page.unwrap_or_default();
    assert!(
        page.starts_with("HTTP/1.1 200") && page.contains("scnc studio"),
        "`{line}` said `{first}` and served:\n{page}"
    );
}

/// Relative links of a Markdown file (`[text](target)`, anchors dropped).
fn links(markdown: &str) -> Vec<String> {
    markdown
        .match_indices("](")
        .filter_map(|(i, _)| {
            let rest = &markdown[i + 2..];
            let target = &rest[..rest.find(')')?];
            let target = target.split('#').next().unwrap_or("");
            (!target.is_empty() && !target.contains("://") && !target.starts_with("mailto:"))
                .then(|| target.to_string())
        })
        .collect()
}

#[test]
fn every_link_of_the_readme_and_docs_is_in_a_clone() {
    let files = clone_files();
    let pages = doc_pages();
    let mut missing = Vec::new();
    for page in &pages {
        let text = std::fs::read_to_string(page).expect("reading a page");
        let dir = page.parent().unwrap_or(Path::new(""));
        for link in links(&text) {
            let target = dir.join(&link);
            // Normalise `docs/../x` lexically, as a browser does.
            let mut parts: Vec<&std::ffi::OsStr> = Vec::new();
            for c in target.components() {
                match c {
                    std::path::Component::ParentDir => {
                        parts.pop();
                    }
                    std::path::Component::CurDir => {}
                    c => parts.push(c.as_os_str()),
                }
            }
            let target: PathBuf = parts.iter().collect();
            let present = files.iter().any(|f| *f == target || f.starts_with(&target));
            if !present {
                missing.push(format!("{}: `{link}` is not in a clone", page.display()));
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// The README and the pages of `docs/` a clone has.
fn doc_pages() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = clone_files()
        .into_iter()
        .filter(|p| p.starts_with("docs") && p.extension().is_some_and(|e| e == "md"))
        .collect();
    pages.push(PathBuf::from("README.md"));
    pages
}

/// A `scn` block of the README or the docs that names its file on its first line
/// (`// examples/tour.scn: …`) is that file, word for word, so the tour shown is the
/// tour that runs.
#[test]
fn every_scene_shown_is_the_file_it_names() {
    let pages = doc_pages();
    let mut shown = 0;
    for page in pages {
        let text = std::fs::read_to_string(&page).expect("reading a page");
        for block in text.split("```scn\n").skip(1) {
            let block = &block[..block.find("```").expect("a closed block")];
            let Some(name) =
                block.strip_prefix("// ").and_then(|l| l.split(':').next()).filter(|n| n.ends_with(".scn"))
            else {
                continue;
            };
            let file = std::fs::read_to_string(name).unwrap_or_else(|e| panic!("{}: {name}: {e}", page.display()));
            assert_eq!(block, file, "{} shows {name} other than it is", page.display());
            shown += 1;
        }
    }
    assert!(shown >= 2, "the README's and the language's tours name their files");
}

/// Every `scn` block of the README and the docs is a scene that compiles without errors
/// where it stands (an `include` is read from beside the page), so a snippet
/// pasted into a file works. A block that is only part of a scene says so on the line
/// before it, `<!-- scn fragment: PREAMBLE -->`, and is checked after that preamble.
/// A block that names its file (`// examples/tour.scn: …`) is compiled where that file
/// is, as its includes are relative to it.
#[test]
fn every_scene_snippet_compiles() {
    let pages = doc_pages();
    let (mut checked, mut failures) = (0, Vec::new());
    for page in pages {
        let text = std::fs::read_to_string(&page).expect("reading a page");
        let mut rest = text.as_str();
        while let Some(at) = rest.find("```scn\n") {
            let before = rest[..at].trim_end().lines().last().unwrap_or("");
            let preamble = before
                .strip_prefix("<!-- scn fragment:")
                .and_then(|p| p.strip_suffix("-->"))
                .map(|p| format!("{}\n", p.trim()))
                .unwrap_or_default();
            let body = &rest[at + 7..];
            let end = body.find("```").expect("a closed block");
            let block = &body[..end];
            rest = &body[end + 3..];
            let line = text[..text.len() - rest.len()].lines().count() - block.lines().count();
            // A block that names its file is compiled where that file is (its includes
            // are relative to it); any other as if it stood beside its page.
            let named = block.strip_prefix("// ").and_then(|l| l.split(':').next()).filter(|n| n.ends_with(".scn"));
            let path = named.map_or_else(|| page.with_file_name("snippet.scn"), PathBuf::from);
            let source = format!("{preamble}{block}");
            let name = format!("{}:{line}", page.display());
            let c = scnc::compile_file(&name, &path, source, &scnc::source::FsLoader);
            if c.diagnostics.iter().any(|d| d.is_error()) || c.scene.is_none() {
                failures.push(scnc::diag::render_all(&c.diagnostics, &c.map));
            }
            checked += 1;
        }
    }
    assert!(failures.is_empty(), "snippets that do not compile:\n{}", failures.join("\n"));
    assert!(checked >= 3, "only {checked} snippets found");
}
