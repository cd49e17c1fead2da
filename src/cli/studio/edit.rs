//! The editor's questions, answered by the same code `scnc check`, the language server,
//! `scnc fmt` and `scnc export` run: diagnostics, hover, completion, formatting, saving,
//! the camera line, and mesh downloads.
//!
//! Positions cross between the page's UTF-16 units and the compiler's bytes in
//! [`super::diagnostics`].

use scnc::check::Overrides;
use scnc::lsp::analysis::{Analysis, CandidateKind};
use scnc::meshfile::{Format, WriteOptions};
use scnc::source::{FileId, SourceMap};

use super::diagnostics::{diagnostics_json, param_list, to_byte, to_utf16};
use super::http::Reply;
use super::preview::View;
use super::Studio;

/// The file on disk.
pub(crate) fn file(studio: &Studio) -> Reply {
    match studio.files.text() {
        Ok(text) => Reply::json(&serde_json::json!({
            // A new or empty file opens with a scene to start from (unsaved until saved).
            "starter": text.trim().is_empty().then_some(super::examples::STARTER),
            "text": text,
            "name": studio.files.root.file_name().map(|n| n.to_string_lossy().into_owned()),
            "path": studio.files.root.display().to_string(),
        })),
        Err(e) => Reply::text(500, &e),
    }
}

fn analyse(studio: &Studio, text: String) -> Analysis {
    let loader = studio.files.loader();
    Analysis::new(&studio.files.root, text, &loader, &|| false).expect("an analysis that is never cancelled completes")
}

/// `scnc check` of the editor's text; the files it read are watched from now on.
pub(crate) fn check(studio: &Studio, text: String) -> Reply {
    let a = analyse(studio, text);
    studio.files.watch_read(&a.map);
    Reply::json(&serde_json::json!({ "diagnostics": diagnostics_json(&a.map, &a.diagnostics) }))
}

/// The scene's parameters with the values the page's controls (`set`) give them, each
/// with the UTF-16 range of its default in the text (where writing a value back puts
/// it); or the diagnostics that keep it from compiling.
pub(crate) fn params(studio: &Studio, text: String, set: &Overrides) -> Reply {
    let compiled = studio.files.compile(text, set);
    let Some(scene) = &compiled.scene else {
        return Reply::json(&serde_json::json!({
            "diagnostics": diagnostics_json(&compiled.map, &compiled.diagnostics),
        }));
    };
    Reply::json(&serde_json::json!({ "params": param_list(&compiled.map, scene) }))
}

/// The hover text at UTF-16 position `pos`.
pub(crate) fn hover(studio: &Studio, text: String, pos: u32) -> Reply {
    let at = to_byte(&text, pos);
    let a = analyse(studio, text);
    let answer = a.hover(at).map(|(span, doc)| {
        let root = a.text();
        serde_json::json!({
            "from": to_utf16(root, span.start as usize), "to": to_utf16(root, span.end as usize), "text": doc,
        })
    });
    Reply::json(&answer.unwrap_or(serde_json::Value::Null))
}

/// The signature of the builtin call at UTF-16 position `pos`: its label, doc, each
/// parameter's text and doc, and the one the cursor is at; `null` outside a call.
pub(crate) fn signature(studio: &Studio, text: String, pos: u32) -> Reply {
    let at = to_byte(&text, pos);
    let a = analyse(studio, text);
    let answer = a.signature_help(at).map(|h| {
        serde_json::json!({
            "label": h.label, "doc": h.doc, "active": h.active,
            "params": h.params.iter().map(|(p, doc)| serde_json::json!({ "label": p, "doc": doc })).collect::<Vec<_>>(),
        })
    });
    Reply::json(&answer.unwrap_or(serde_json::Value::Null))
}

/// Completion at UTF-16 position `pos`.
pub(crate) fn complete(studio: &Studio, text: String, pos: u32) -> Reply {
    let at = to_byte(&text, pos);
    let a = analyse(studio, text);
    let items: Vec<_> = a
        .complete(at)
        .into_iter()
        .map(|c| {
            // CodeMirror's names for the icons.
            let kind = match c.kind {
                CandidateKind::Argument => "property",
                CandidateKind::Variable => "variable",
                CandidateKind::Function | CandidateKind::Builtin => "function",
                CandidateKind::Constant => "constant",
                CandidateKind::Keyword => "keyword",
            };
            serde_json::json!({ "label": c.label, "detail": c.detail, "doc": c.doc, "kind": kind })
        })
        .collect();
    Reply::json(&serde_json::Value::Array(items))
}

/// `scnc fmt` of the text: the formatted text, or the syntax errors that stop it.
pub(crate) fn format(text: String) -> Reply {
    match scnc::fmt::format(&text) {
        Ok(formatted) => Reply::json(&serde_json::json!({ "text": formatted })),
        Err(diagnostics) => {
            let mut map = SourceMap::new();
            let _ = map.add("scene", std::path::Path::new("scene"), text);
            Reply::json(&serde_json::json!({ "diagnostics": diagnostics_json(&map, &diagnostics) }))
        }
    }
}

/// Writes the text to the file, whole or not at all, as `fmt` and `render` write.
pub(crate) fn save(studio: &Studio, text: String) -> Reply {
    match studio.files.save(text) {
        Ok(()) => Reply::json(&serde_json::json!({ "saved": studio.files.root.display().to_string() })),
        Err(e) => Reply::text(500, &crate::cli::files::cannot_write(&studio.files.root, &e)),
    }
}

/// The text with its camera statement (or a new one) set to the page's view, formatted.
pub(crate) fn camera_line(studio: &Studio, text: String, view: &View) -> Reply {
    let compiled = studio.files.compile(text.clone(), &Overrides::default());
    let Some(scene) = &compiled.scene else {
        return Reply::json(&serde_json::json!({
            "diagnostics": diagnostics_json(&compiled.map, &compiled.diagnostics),
        }));
    };
    let c = view.apply(&scene.camera);
    let v = |p: glam::DVec3| format!("[{}, {}, {}]", short(p.x), short(p.y), short(p.z));
    let mut line = format!("camera(position = {}, look_at = {}", v(c.position), v(c.look_at));
    if (c.up.normalize() - glam::DVec3::Y).length() > 1e-9 {
        line.push_str(&format!(", up = {}", v(c.up)));
    }
    if (c.fov - scnc::ir::SEED_FOV).abs() > 1e-9 {
        line.push_str(&format!(", fov = {}", short(c.fov)));
    }
    line.push(')');
    let in_root = scene.camera.span.map(|s| compiled.map.local_range(s)).filter(|(id, _)| *id == FileId(0));
    let edited = match in_root {
        Some((_, range)) => format!("{}{line}{}", &text[..range.start], &text[range.end..]),
        None => insert_before_first_statement(&text, &line),
    };
    // The formatter lays the line out as the rest of the file; if it cannot (it can
    // only fail on a syntax error, and the text compiled), the text is kept as edited.
    let formatted = scnc::fmt::format(&edited).unwrap_or(edited);
    Reply::json(&serde_json::json!({ "text": formatted }))
}

/// A number short enough to read, exact to 1e-4.
fn short(x: f64) -> String {
    let s = format!("{:.4}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// `line` before the first line that is not a comment, blank or an `include`.
fn insert_before_first_statement(text: &str, line: &str) -> String {
    let mut at = 0;
    for l in text.split_inclusive('\n') {
        let t = l.trim();
        if !(t.is_empty() || t.starts_with("//") || t.starts_with("include")) {
            break;
        }
        at += l.len();
    }
    let sep = if at > 0 && !text[..at].ends_with('\n') { "\n" } else { "" };
    format!("{}{sep}{line}\n{}", &text[..at], &text[at..])
}

/// The scene as a mesh file to download, as `scnc export` writes it with its defaults
/// (detail high; z up for STL and 3MF, which are for printing, y up otherwise).
pub(crate) fn export(studio: &Studio, text: String, set: &Overrides, format: &str) -> Reply {
    use scnc::export::Placement;
    let Some(format) = Format::from_name(format).filter(|f| f.one_file()) else {
        let names: Vec<&str> = downloads().map(Format::name).collect();
        return Reply::text(400, &format!("`{format}`: the studio exports {}", names.join(", ")));
    };
    let (mime, ext) = (format.mime(), format.extensions()[0]);
    let compiled = studio.files.compile(text, set);
    let Some(scene) = &compiled.scene else {
        return Reply::text(422, "the scene has errors: fix them to export");
    };
    if scene.objects.is_empty() {
        return Reply::text(422, "the scene has no objects to export");
    }
    let frame = Placement { up: format.default_up(), scale: format.default_scale() };
    let limit = scnc::mesh::lower::DEFAULT_MEMORY_LIMIT;
    let loader = studio.files.loader();
    let skip_unbounded = format.for_printing();
    // Refined where an isosurface lost volume, as `scnc export
    // --tolerance` does: a download is meant to be used.
    let (collected, _) = studio.preview.pool.install(|| {
        let high = scnc::mesh::Detail::High;
        scnc::export::collect_refined(scene, high, frame, limit, skip_unbounded, &loader, &mut |_, _| {})
    });
    let export = match collected {
        Ok(e) if !e.parts.is_empty() => e,
        Ok(_) => return Reply::text(422, "no object of the scene has a surface to write"),
        Err(d) => return Reply::text(422, &format!("error[{}]: {}", d.code, d.message)),
    };
    let mut bytes = Vec::new();
    if let Err(e) = format.write(&export, &WriteOptions::default(), &mut bytes) {
        return Reply::text(500, &format!("cannot write the {ext}: {e}"));
    }
    let stem = studio.files.root.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    let stem = scnc::source::file_safe(&stem);
    Reply::download(mime, format!("{stem}.{ext}"), bytes)
}

/// The formats the studio offers as downloads: every one that is a single file.
pub(crate) fn downloads() -> impl Iterator<Item = Format> {
    Format::ALL.iter().copied().filter(|f| f.one_file())
}

/// `GET /api/formats`: the downloads, for the page's buttons.
pub(crate) fn formats() -> Reply {
    let list: Vec<serde_json::Value> = downloads()
        .map(|f| serde_json::json!({ "name": f.name(), "label": f.name().to_uppercase(), "about": f.about() }))
        .collect();
    Reply::json(&serde_json::Value::Array(list))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_new_camera_line_goes_after_the_includes() {
        let t = "// scene\ninclude \"l.scn\"\n\nobject sphere(1)\n";
        assert_eq!(
            insert_before_first_statement(t, "camera()"),
            "// scene\ninclude \"l.scn\"\n\ncamera()\nobject sphere(1)\n"
        );
        assert_eq!(insert_before_first_statement("", "camera()"), "camera()\n");
        assert_eq!(short(-0.00001), "0");
        assert_eq!(short(2.5), "2.5");
    }
}
