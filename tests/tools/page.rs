//! The studio's page end to end in a real browser (Debian's `chromium`, driven over the
//! DevTools protocol).

use std::path::Path;
use std::time::{Duration, Instant};

use crate::browser::{base64, Browser};
use crate::studio_server::{artefacts, image_difference, rendered, seed_scene, Server};

/// The page's address.
fn page_of(s: &Server) -> String {
    format!("http://127.0.0.1:{}/", s.port)
}

/// The preview canvas's pixels.
fn canvas_pixels(b: &mut Browser) -> image::RgbImage {
    let url = b.eval("document.querySelector('[data-testid=preview]').toDataURL('image/png')");
    let data = url.as_str().unwrap().strip_prefix("data:image/png;base64,").unwrap().to_string();
    image::load_from_memory(&base64(&data)).unwrap().to_rgb8()
}

const FINISHED: &str = "Number(document.querySelector('[data-testid=preview]').dataset.finished || 0)";
const IDLE: &str = "document.querySelector('[data-testid=preview]').dataset.busy === '0'";
/// The last finished render was of the page's current view.
const SHOWN_IS_CURRENT: &str =
    "document.querySelector('[data-testid=preview]').dataset.view === JSON.stringify(scnStudio.state.view)";

pub fn studio_in_a_browser() {
    let (dir, scene) = seed_scene();
    let original = std::fs::read_to_string(&scene).unwrap();
    let s = Server::start(&scene);
    let shots = artefacts();
    let mut b = Browser::launch();
    b.open(&page_of(&s));
    let limit = Duration::from_secs(30);

    // The page shows the scene as `scnc render` renders it.
    b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), limit);
    b.screenshot(&shots.join("1-opened.png"));
    let first = canvas_pixels(&mut b);
    if let Some(d) = image_difference("opened", &first, &rendered(&scene)) {
        panic!("the preview differs from `scnc render` at the same size: {d}");
    }

    // A misspelt builtin: its diagnostic within 2 s, and the image stays.
    b.eval("(() => { const e = scnStudio.editor; e.focus(); e.dispatch({ selection: { anchor: e.state.doc.length } }); })()");
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.type_text("object sphre(0.4) at [0, 1.3, 8] with red\n");
    b.wait_for(
        "[...document.querySelectorAll('[data-testid=diagnostics] li')].some(li => li.textContent.includes('E0201') \
         && li.textContent.includes('unknown function `sphre`'))",
        Duration::from_secs(2),
    );
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.screenshot(&shots.join("2-misspelt.png"));
    if let Some(d) = image_difference("misspelt", &canvas_pixels(&mut b), &first) {
        panic!("an edit with errors replaced the image: {d}");
    }

    // Fixed by typing over the misspelt name: no diagnostics, and a new image.
    b.eval(
        "(() => { const e = scnStudio.editor; const at = e.state.doc.toString().indexOf('sphre('); \
         e.dispatch({ selection: { anchor: at, head: at + 5 } }); })()",
    );
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.type_text("sphere");
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.wait_for("document.querySelectorAll('[data-testid=diagnostics] li').length === 0", limit);
    b.screenshot(&shots.join("3-fixed.png"));
    let fixed = canvas_pixels(&mut b);
    assert!(fixed != first, "the fixed scene rendered the same image");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), original, "typing wrote the file");

    // Dragging turns the view; the file is not touched. The page may see the drag's
    // moves late on a busy machine (and finish a render of a part of it first), so the
    // test waits for the view to have turned and for a render of that very view.
    b.drag("[data-testid=preview]", (60.0, 20.0));
    b.wait_for("scnStudio.state.view.yaw !== 0", limit);
    b.wait_for(&format!("{SHOWN_IS_CURRENT} && {IDLE}"), limit);
    b.screenshot(&shots.join("4-dragged.png"));
    assert!(canvas_pixels(&mut b) != fixed, "dragging did not change the view");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), original, "dragging wrote the file");

    // View → camera writes the dragged view into the text as a camera line; the page's
    // own view is reset, so the image stays (to the camera line's 4 decimals).
    let dragged = canvas_pixels(&mut b);
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.click("[data-testid=write-camera]");
    b.wait_for("scnStudio.ScnEditor.textOf(scnStudio.editor).includes('camera(position = [')", limit);
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    let written = canvas_pixels(&mut b);
    let differing = written
        .pixels()
        .zip(dragged.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 16))
        .count();
    assert!(differing * 100 < written.len() / 3, "{differing} pixels changed when the view became the camera line");
    b.screenshot(&shots.join("5-camera-written.png"));

    // Ctrl-S saves the editor's text, whole, leaving no temporary file.
    b.eval("scnStudio.editor.focus()");
    b.ctrl('s');
    let text = b.eval("scnStudio.ScnEditor.textOf(scnStudio.editor)").as_str().unwrap().to_string();
    let start = Instant::now();
    while std::fs::read_to_string(&scene).unwrap() != text {
        assert!(start.elapsed() < limit, "Ctrl-S did not save");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(text.contains("object sphere(0.4)"));
    let stray: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with(".scnc-"))
        .collect();
    assert!(stray.is_empty(), "temporary files left: {stray:?}");
    b.wait_for("document.querySelector('[data-testid=saved]').textContent.startsWith('saved')", limit);
    b.screenshot(&shots.join("6-saved.png"));

    // An edit made outside the page replaces the page's text.
    let outside = text.replace("sphere(0.4)", "sphere(0.3)");
    std::fs::write(&scene, &outside).unwrap();
    b.wait_for("scnStudio.ScnEditor.textOf(scnStudio.editor).includes('sphere(0.3)')", limit);

    // Export STL: a file downloads, and it is a valid STL of the scene's objects.
    let downloads = tempfile::tempdir().unwrap();
    b.downloads_to(downloads.path());
    b.click("[data-testid=export-stl]");
    // Chromium may show the file under its final name while still writing it, so wait
    // until it reads whole (a binary STL states its triangle count up front).
    let start = Instant::now();
    let mesh = loop {
        let found = std::fs::read_dir(downloads.path())
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|e| e == "stl"));
        let read = found.map(|p| std::fs::File::open(p).and_then(|mut f| stl_io::read_stl(&mut f)));
        match read {
            Some(Ok(mesh)) => break mesh,
            Some(Err(e)) => assert!(start.elapsed() < limit, "the STL never read whole: {e}"),
            None => assert!(start.elapsed() < limit, "no STL was downloaded"),
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(mesh.faces.len() > 1000, "{} triangles", mesh.faces.len());
    mesh.validate().expect("an STL whose faces name its vertices");
    b.screenshot(&shots.join("7-exported.png"));
}

/// The numbers in the README's "Studio" section: for each seed scene at its own size
/// (1000×1000), the time from an edit to the first (quarter-size) image and to the full
/// frame, as the page measures them, median of 7 edits. Run with
/// `cargo test --release --test tools -- --ignored --nocapture studio_latency`.
pub fn studio_latency_on_the_seed_scenes() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/seed");
    let mut b = Browser::launch();
    let mut table = String::from("| scene | edit → first image (ms) | edit → full frame (ms) |\n|---|---|---|\n");
    for n in 1..=7 {
        let file = std::fs::read_dir(&seeds)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.file_name().unwrap().to_string_lossy().starts_with(&format!("0{n}-")))
            .unwrap();
        let s = Server::start(&file);
        b.open(&page_of(&s));
        b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), Duration::from_secs(60));
        let (mut first, mut full) = (Vec::new(), Vec::new());
        for i in 0..7 {
            let done = b.eval(FINISHED).as_u64().unwrap();
            b.eval("(() => { const e = scnStudio.editor; e.focus(); e.dispatch({ selection: { anchor: e.state.doc.length } }); })()");
            b.type_text(&format!("\n// edit {i}"));
            b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), Duration::from_secs(60));
            let mut ms =
                |k: &str| b.eval(&format!("Number(document.querySelector('[data-testid=preview]').dataset.{k})"));
            first.push(ms("firstImageMs").as_f64().unwrap());
            full.push(ms("fullMs").as_f64().unwrap());
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        table.push_str(&format!("| {name} | {:.0} | {:.0} |\n", median(&mut first), median(&mut full)));
    }
    #[allow(clippy::print_stdout, reason = "the measurement's result")]
    {
        println!("{table}");
    }
}

/// The README's picture of the studio (`docs/studio.png` is this, looked at and copied):
/// the tour scene with the accuracy ladder on. Run with
/// `cargo test --release --test tools -- --ignored studio_screenshot`.
pub fn studio_screenshot_for_the_readme() {
    let tour = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/tour.scn");
    let s = Server::start(&tour);
    let mut b = Browser::launch();
    b.open(&page_of(&s));
    b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), Duration::from_secs(60));
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.click("[data-testid=accuracy-on]");
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), Duration::from_secs(60));
    b.wait_for(
        "document.querySelector('[data-testid=accuracy-result]').textContent.length > 0",
        Duration::from_secs(60),
    );
    b.screenshot(&artefacts().join("readme.png"));
}

/// The studio helps as one works: a new file opens a starter scene, the Examples menu
/// loads a shipped example, a render shows that it is busy and never shows an older
/// render's figures as its own, hover docs are rendered (no Markdown fences), signature
/// help follows the cursor into a call, and a click on the preview selects the object's
/// source.
pub fn studio_helps_as_you_work() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("new.scn");
    std::fs::write(&scene, "").unwrap();
    let s = Server::start(&scene);
    let shots = artefacts();
    let mut b = Browser::launch();
    b.open(&page_of(&s));
    let limit = Duration::from_secs(60);
    let text = "scnStudio.ScnEditor.textOf(scnStudio.editor)";

    // An empty file opens with the tour, not yet saved.
    b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), limit);
    assert!(b.eval(text).as_str().unwrap().contains("examples/tour.scn"), "no starter scene");
    let saved = b.eval("document.querySelector('[data-testid=saved]').textContent");
    assert!(saved.as_str().unwrap().contains("not saved"), "{saved}");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), "", "the starter was written to the file");

    // Click-to-source: the preview's centre is the cut sphere of the tour.
    let (x, y) = b.centre("[data-testid=preview]");
    b.click_at((x, y));
    b.wait_for(
        "(() => { const e = scnStudio.editor, r = e.state.selection.main; \
         return e.state.sliceDoc(r.from, r.to).startsWith('object subtract(sphere(1)'); })()",
        limit,
    );

    // Busy while rendering, and the accuracy result never shows another rung's numbers.
    b.eval(
        "(() => { window.busySeen = false; const busy = document.querySelector('[data-testid=busy]'); \
         new MutationObserver(() => { if (!busy.hidden) window.busySeen = true; }).observe(busy, { attributes: true }); })()",
    );
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.click("[data-testid=accuracy-on]");
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.wait_for("document.querySelector('[data-testid=accuracy-result]').dataset.rung === '2'", limit);
    assert_eq!(b.eval("window.busySeen"), serde_json::Value::Bool(true), "no busy state was shown");
    assert_eq!(b.eval("document.querySelector('[data-testid=busy]').hidden"), serde_json::Value::Bool(true));
    let done = b.eval(FINISHED).as_u64().unwrap();
    let right_after = b.eval(
        "(() => { const r = document.querySelector('[data-testid=accuracy]'); r.value = 4; \
         r.dispatchEvent(new Event('input')); return document.querySelector('[data-testid=accuracy-result]').textContent; })()",
    );
    let right_after = right_after.as_str().unwrap().to_string();
    assert!(right_after.starts_with("rung 5 of 6"), "after moving to rung 5 the result says `{right_after}`");
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    b.wait_for("document.querySelector('[data-testid=accuracy-result]').dataset.rung === '4'", limit);
    let result = b.eval("document.querySelector('[data-testid=accuracy-result]').textContent");
    assert!(
        result.as_str().unwrap().starts_with("rung 5 of 6: ") && !result.as_str().unwrap().contains("measuring"),
        "{result}"
    );
    b.click("[data-testid=accuracy-on]");
    b.screenshot(&shots.join("8-accuracy.png"));

    // The Examples menu: a shipped example in the editor, rendered, the file untouched.
    let count = b.eval("document.querySelectorAll('[data-testid=examples] option').length").as_u64().unwrap();
    assert!(count >= 10, "{count} entries in the Examples menu");
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.eval(
        "(() => { const m = document.querySelector('[data-testid=examples]'); \
         m.value = [...m.options].find(o => o.textContent === 'Fields').value; m.dispatchEvent(new Event('change')); })()",
    );
    b.wait_for(&format!("{text}.includes('let gyroid(p, period)')"), limit);
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), "", "choosing an example wrote the file");
    b.screenshot(&shots.join("9-example.png"));

    // Hover docs are rendered Markdown: no fences, code set as code.
    let at = b.eval(&format!("{text}.indexOf('noise3(') + 2")).as_u64().unwrap();
    let xy = b.eval(&format!(
        "(() => {{ const c = scnStudio.editor.coordsAtPos({at}); c && scnStudio.editor.dispatch({{ scrollIntoView: true }}); \
         return [(c.left + c.right) / 2, (c.top + c.bottom) / 2]; }})()"
    ));
    b.move_to((xy[0].as_f64().unwrap(), xy[1].as_f64().unwrap()));
    b.wait_for("document.querySelector('[data-testid=hover]') !== null", limit);
    let hover = b.eval("document.querySelector('[data-testid=hover]').textContent").as_str().unwrap().to_string();
    assert!(hover.contains("noise3") && !hover.contains("```"), "hover: {hover}");
    assert_eq!(b.eval("document.querySelector('[data-testid=hover] p') !== null"), serde_json::Value::Bool(true));
    b.screenshot(&shots.join("10-hover.png"));

    // Signature help inside a call, with the parameter at the cursor.
    b.eval(
        "(() => { const e = scnStudio.editor; e.focus(); e.dispatch({ selection: { anchor: e.state.doc.length } }); })()",
    );
    b.type_text("\nobject sphere(");
    b.wait_for("document.querySelector('[data-testid=signature]')?.textContent.startsWith('sphere(')", limit);
    let sig = b.eval("document.querySelector('[data-testid=signature]').textContent").as_str().unwrap().to_string();
    assert!(sig.starts_with("sphere(") && sig.contains("r: num"), "signature help: {sig}");
    b.screenshot(&shots.join("11-signature.png"));
}

/// The customizer: the scene's `param`s show as a slider, a checkbox, a drop-down and a
/// colour well; moving one re-renders what `scnc render -D …` renders without touching
/// the file, and *Controls → file* writes the values into the `param` lines.
pub fn studio_sliders_set_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("params.scn");
    let text = "param r = 1 in 0.5 .. 2 step 0.1 \"Radius\" group \"Size\"\n\
                param lit = true \"Point light on\"\n\
                param shape = \"ball\" in [\"ball\", \"cube\"]\n\
                param tint = #c83232\n\
                render(width = 96, height = 72)\n\
                light ambient(0.3)\n\
                if lit {\n  light point(0.7) at [3, 4, -2]\n}\n\
                object (if shape == \"ball\" then sphere(r) else box([r, r, r])) at [0, 0, 5] with material(color = tint)\n";
    std::fs::write(&scene, text).unwrap();
    let s = Server::start(&scene);
    let mut b = Browser::launch();
    b.open(&page_of(&s));
    let limit = Duration::from_secs(60);
    b.wait_for(&format!("{FINISHED} >= 1 && {IDLE}"), limit);
    b.wait_for("document.querySelectorAll('#params [data-param]').length === 4", limit);
    let kinds = b.eval("[...document.querySelectorAll('#params [data-param]')].map(i => i.type).join(' ')");
    assert_eq!(kinds.as_str().unwrap(), "range checkbox select-one color");

    let render_with = |defines: &[&str]| {
        let png = dir.path().join("reference.png");
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_scnc"));
        cmd.arg("render").arg(&scene).arg("-o").arg(&png);
        for d in defines {
            cmd.args(["-D", d]);
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        image::open(&png).unwrap().to_rgb8()
    };
    let set = |b: &mut Browser, js: &str| {
        let done = b.eval(FINISHED).as_u64().unwrap();
        b.eval(js);
        b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    };
    set(&mut b, "(() => { const i = document.querySelector('[data-testid=param-r]'); i.value = '1.5'; i.dispatchEvent(new Event('input')); })()");
    let first_ms = b.eval("Number(document.querySelector('[data-testid=preview]').dataset.firstImageMs)");
    if let Some(d) = image_difference("slider", &canvas_pixels(&mut b), &render_with(&["r=1.5"])) {
        panic!("the slider's preview differs from `scnc render -D r=1.5`: {d}");
    }
    set(&mut b, "(() => { const i = document.querySelector('[data-testid=param-shape]'); i.value = 'cube'; i.dispatchEvent(new Event('change')); })()");
    set(&mut b, "document.querySelector('[data-testid=param-lit]').click()");
    set(&mut b, "(() => { const i = document.querySelector('[data-testid=param-tint]'); i.value = '#3264c8'; i.dispatchEvent(new Event('input')); })()");
    let all = ["r=1.5", "shape=cube", "lit=false", "tint=#3264c8"];
    if let Some(d) = image_difference("controls", &canvas_pixels(&mut b), &render_with(&all)) {
        panic!("the controls' preview differs from `scnc render -D …`: {d}");
    }
    let editor = "scnStudio.ScnEditor.textOf(scnStudio.editor)";
    assert_eq!(b.eval(editor).as_str().unwrap(), text, "a control changed the editor's text");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text, "a control changed the file");

    // Written back: the values become the defaults, and the image stays.
    let done = b.eval(FINISHED).as_u64().unwrap();
    b.click("[data-testid=params-write]");
    b.wait_for(&format!("{editor}.includes('param r = 1.5 in')"), limit);
    b.wait_for(&format!("{FINISHED} > {done} && {IDLE}"), limit);
    let written = b.eval(editor).as_str().unwrap().to_string();
    for line in ["param lit = false", "param shape = \"cube\" in", "param tint = #3264c8"] {
        assert!(written.contains(line), "`{line}` not written back:\n{written}");
    }
    assert_eq!(b.eval("Object.keys(scnStudio.state.params).length").as_u64(), Some(0));
    if let Some(d) = image_difference("written", &canvas_pixels(&mut b), &render_with(&all)) {
        panic!("the written-back scene renders differently: {d}");
    }
    #[allow(clippy::print_stdout, reason = "the measurement, for the issue's note")]
    {
        println!("slider → first image: {first_ms} ms");
    }
}
