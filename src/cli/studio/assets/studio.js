// scnc studio: the page. The editor is CodeMirror (editor.js, global ScnEditor); the
// server answers checks, renders (a binary stream, see readMessages) and saves.
"use strict";

const $ = (id) => document.getElementById(id);
const canvas = $("preview");
const ctx = canvas.getContext("2d");
/** The coarse pass, kept to fill the canvas until the full frame's bands replace it. */
const coarse = document.createElement("canvas");

/** The scene's own camera: no orbit, pan or zoom of the page's. */
const homeView = () => ({ yaw: 0, pitch: 0, zoom: 1, panx: 0, pany: 0 });

const state = {
  view: homeView(),
  backend: "sdf",
  rung: null,
  frame: 0,
  frames: 1,
  fps: 24,
  playing: false,
  render: null, // the AbortController of the render in flight
  lastText: "",
  params: {}, // the parameter controls' values (name → text); the file keeps its own
  paramList: [], // the scene's params, as the last compile listed them
  paramsFor: null, // the text that list is of
  paramShape: "", // what the controls were built from
  paramSeq: 0,
};

let editor = null;

function query(extra) {
  const v = state.view;
  const p = new URLSearchParams({
    yaw: v.yaw, pitch: v.pitch, zoom: v.zoom, panx: v.panx, pany: v.pany,
    backend: state.backend, frame: state.frame, ...extra,
  });
  if (state.rung !== null) p.set("rung", state.rung);
  if (Object.keys(state.params).length) p.set("set", JSON.stringify(state.params));
  return p.toString();
}

async function post(path, body) {
  const r = await fetch(path, { method: "POST", body, headers: { "Content-Type": "text/plain;charset=utf-8" } });
  if (!r.ok) throw new Error(await r.text());
  return r;
}

// --- diagnostics ---------------------------------------------------------------------

/** Selects `from`..`to` of the editor's text, scrolled into view, and focuses it. */
function select(from, to) {
  editor.dispatch({ selection: { anchor: from, head: to }, scrollIntoView: true });
  editor.focus();
}

function showDiagnostics(list) {
  ScnEditor.showDiagnostics(editor, list);
  const ul = $("diagnostics");
  ul.replaceChildren(...list.map((d) => {
    const li = document.createElement("li");
    li.className = d.severity;
    const code = document.createElement("span");
    code.className = "code";
    code.textContent = `${d.severity}[${d.code}]`;
    li.append(code, d.message);
    li.onclick = () => select(d.from, d.to);
    return li;
  }));
}

// --- rendering -----------------------------------------------------------------------

/** Calls `on(kind, payload)` for each message of the render stream: a kind byte, a
 * little-endian u32 length and the payload. */
async function readMessages(response, on) {
  const reader = response.body.getReader();
  let buf = new Uint8Array(0);
  for (;;) {
    const { done, value } = await reader.read();
    if (done) return;
    const joined = new Uint8Array(buf.length + value.length);
    joined.set(buf); joined.set(value, buf.length);
    buf = joined;
    let at = 0;
    while (buf.length - at >= 5) {
      const len = new DataView(buf.buffer, buf.byteOffset + at + 1, 4).getUint32(0, true);
      if (buf.length - at - 5 < len) break;
      on(String.fromCharCode(buf[at]), buf.subarray(at + 5, at + 5 + len));
      at += 5 + len;
    }
    buf = buf.slice(at);
  }
}

const text = new TextDecoder();
const json = (bytes) => JSON.parse(text.decode(bytes));

/** Shows the canvas as large as the stage allows, at its image's aspect. */
function fitCanvas() {
  const w = canvas.width, h = canvas.height;
  const k = Math.min($("stage").clientWidth / w, (window.innerHeight * 0.6) / h);
  canvas.style.width = `${Math.floor(w * k)}px`;
  canvas.style.height = `${Math.floor(h * k)}px`;
}
window.addEventListener("resize", fitCanvas);

function drawBand(target, bytes) {
  const dv = new DataView(bytes.buffer, bytes.byteOffset, 12);
  const y0 = dv.getUint32(0, true), rows = dv.getUint32(4, true), width = dv.getUint32(8, true);
  const rgb = bytes.subarray(12);
  const img = target.createImageData(width, rows);
  for (let i = 0, j = 0; i < rgb.length; i += 3, j += 4) {
    img.data[j] = rgb[i]; img.data[j + 1] = rgb[i + 1]; img.data[j + 2] = rgb[i + 2]; img.data[j + 3] = 255;
  }
  target.putImageData(img, 0, y0);
}

async function render(sourceText, opts = {}) {
  if (state.render) state.render.abort();
  const controller = new AbortController();
  state.render = controller;
  const started = performance.now();
  const view = JSON.stringify(state.view);
  let level = null;
  let firstImageMs = null;
  canvas.dataset.busy = "1";
  $("note").textContent = "";
  // Never show an older render's figures as this one's: they wait, greyed, until this
  // render's own arrive.
  $("busy").hidden = false;
  $("status").classList.add("stale");
  $("accuracy-result").classList.add("stale");
  if (state.rung !== null) $("accuracy-result").textContent = `rung ${state.rung + 1} of 6: measuring…`;
  try {
    const r = await fetch(`/api/render?${query({ coarse: opts.coarse ?? 4 })}`, {
      method: "POST", body: sourceText, signal: controller.signal,
    });
    if (!r.ok) throw new Error(await r.text());
    await readMessages(r, (kind, payload) => {
      if (controller.signal.aborted) return;
      switch (kind) {
        case "M": {
          const m = json(payload);
          level = m.level;
          setAnimation(m.frames, m.fps, m.frame);
          if (m.level === "coarse") {
            coarse.width = m.width; coarse.height = m.height;
          } else {
            // Resizing clears the canvas: the coarse image fills it until bands arrive.
            if (canvas.width !== m.width || canvas.height !== m.height) {
              canvas.width = m.width; canvas.height = m.height; fitCanvas();
            }
            if (coarse.width > 1) { ctx.imageSmoothingEnabled = false; ctx.drawImage(coarse, 0, 0, m.width, m.height); }
          }
          break;
        }
        case "B":
          if (level === "coarse") {
            drawBand(coarse.getContext("2d"), payload);
            if (canvas.width < coarse.width * 2) {
              canvas.width = coarse.width * 4; canvas.height = coarse.height * 4; fitCanvas();
            }
            ctx.imageSmoothingEnabled = false;
            ctx.drawImage(coarse, 0, 0, canvas.width, canvas.height);
          } else {
            drawBand(ctx, payload);
          }
          if (firstImageMs === null) {
            firstImageMs = performance.now() - started;
            canvas.dataset.firstImageMs = firstImageMs.toFixed(1);
          }
          break;
        case "S": {
          const s = json(payload);
          const total = performance.now() - started;
          canvas.dataset.fullMs = total.toFixed(1);
          canvas.dataset.renders = String(Number(canvas.dataset.renders || 0) + 1);
          $("status").classList.remove("stale");
          $("status").textContent =
            `${s.setting}: first image ${firstImageMs.toFixed(0)} ms after the edit, full frame ${total.toFixed(0)} ms ` +
            `(lower ${s.lower_ms.toFixed(0)} ms, trace ${s.full_ms.toFixed(0)} ms, ${s.rays} rays)`;
          $("effects").textContent = s.effects;
          $("stats").textContent = s.text;
          break;
        }
        case "A": {
          const a = json(payload);
          $("accuracy-result").classList.remove("stale");
          $("accuracy-result").dataset.rung = String(a.rung);
          $("accuracy-result").textContent =
            `rung ${a.rung + 1} of ${a.rungs}: ${a.ms.toFixed(0)} ms, ${a.differing_percent.toFixed(2)} % of pixels off by more than ` +
            `${a.threshold}/255 and RMSE ${a.rmse.toFixed(4)} against the finest rung (${a.reference_ms.toFixed(0)} ms)`;
          break;
        }
        case "C": {
          const c = json(payload);
          showDiagnostics(c.diagnostics);
          state.paramsFor = sourceText;
          showParams(c.params);
          break;
        }
        case "N": $("note").textContent = json(payload).note; break;
        case "E":
          showDiagnostics(json(payload));
          $("status").classList.remove("stale");
          $("status").textContent = "not rendered: the scene has errors (the last image stays)";
          break;
        case "P": {
          // Light transport converging while the user is idle.
          const p = json(payload);
          canvas.dataset.samples = String(p.samples);
          $("busy").hidden = true;
          $("note").textContent =
            `converging: ${p.samples} samples a pixel, estimated noise ` +
            `${p.noise_percent === null ? "—" : p.noise_percent.toFixed(2) + " %"} ` +
            `(${p.seconds.toFixed(1)} s); an edit starts again`;
          break;
        }
        case "L": break; // lowering begun: the images follow
        case "X": break;
      }
    });
    if (!controller.signal.aborted) {
      // Hooks for tests and automation: renders finished, and whether one is running.
      canvas.dataset.finished = String(Number(canvas.dataset.finished || 0) + 1);
      canvas.dataset.view = view;
      canvas.dataset.busy = "0";
      $("busy").hidden = true;
      if (state.playing) scheduleNextFrame();
    }
  } catch (e) {
    if (e.name !== "AbortError") {
      $("status").classList.remove("stale");
      $("status").textContent = `render failed: ${e.message}`;
      $("busy").hidden = true;
    }
  }
}

// --- the edit loop -------------------------------------------------------------------

function edited(newText) {
  state.lastText = newText;
  // One request: the render's stream brings the diagnostics and the parameters of the
  // one compile it makes (`C`), or the errors that stop it (`E`).
  render(newText);
}

// --- parameters (the customizer) -----------------------------------------------------

async function loadParams(text) {
  const seq = ++state.paramSeq;
  try {
    const set = new URLSearchParams({ set: JSON.stringify(state.params) });
    const r = await (await post(`/api/params?${set}`, text)).json();
    // A scene with errors keeps the last controls: they come back when it compiles.
    if (seq === state.paramSeq && r.params) { state.paramsFor = text; showParams(r.params); }
  } catch (e) { /* the server is gone: the status line says so on the next render */ }
}

/** The `#rrggbb` of a colour parameter's `[r, g, b]`. */
const hex = (c) => "#" + c.map((x) => Math.round(x).toString(16).padStart(2, "0")).join("");

/** A value as the control's text: what `-D` would say. */
const asText = (p, v) => (p.type === "color" ? hex(v) : String(v));

function showParams(list) {
  state.paramList = list;
  for (const k of Object.keys(state.params)) if (!list.some((p) => p.name === k)) delete state.params[k];
  $("params-panel").hidden = list.length === 0;
  const shape = JSON.stringify(list.map((p) => [p.name, p.type, p.default, p.range, p.step, p.choices, p.description, p.group]));
  // Controls under the user's hand are not rebuilt while only the values change.
  if (shape === state.paramShape) return;
  state.paramShape = shape;
  const box = $("params");
  box.replaceChildren();
  let group = null;
  for (const p of list) {
    if (p.group && p.group !== group) {
      const h = document.createElement("h4");
      h.textContent = p.group;
      box.append(h);
    }
    group = p.group;
    box.append(paramControl(p));
  }
}

/** One parameter's row: its name, a control fitting its type, range and choices, and its value. */
function paramControl(p) {
  const row = document.createElement("label");
  row.className = "param";
  row.title = p.description || "";
  const name = document.createElement("span");
  name.className = "name";
  name.textContent = p.description ? `${p.name} — ${p.description}` : p.name;
  const out = document.createElement("output");
  const current = state.params[p.name] ?? asText(p, p.default);
  let input;
  if (p.choices) {
    input = document.createElement("select");
    for (const c of p.choices) {
      const o = document.createElement("option");
      o.value = asText(p, c);
      o.textContent = p.type === "str" ? c : asText(p, c);
      input.append(o);
    }
  } else {
    input = document.createElement("input");
    if (p.type === "bool") input.type = "checkbox";
    else if (p.type === "color") input.type = "color";
    else if (p.type === "num" && p.range) {
      input.type = "range";
      [input.min, input.max] = p.range;
      input.step = p.step ?? "any";
    } else if (p.type === "num") { input.type = "number"; input.step = p.step ?? "any"; }
    else input.type = "text";
  }
  input.dataset.param = p.name;
  input.dataset.testid = `param-${p.name}`;
  if (input.type === "checkbox") input.checked = current === "true"; else input.value = current;
  out.textContent = input.type === "range" ? current : "";
  const changed = () => {
    const text = input.type === "checkbox" ? String(input.checked) : input.value;
    state.params[p.name] = text;
    if (input.type === "range") out.textContent = text;
    // Only the preview changes: the file keeps its value until written back.
    render(ScnEditor.textOf(editor));
  };
  input.addEventListener(input.type === "checkbox" || input.tagName === "SELECT" ? "change" : "input", changed);
  row.append(name, input, out);
  return row;
}

/** Writes the controls' values into the file's `param` lines, as *View → camera* does the view. */
async function writeParams() {
  const text = ScnEditor.textOf(editor);
  if (state.paramsFor !== text) await loadParams(text);
  if (state.paramsFor !== text) return;
  const edits = state.paramList
    .filter((p) => state.params[p.name] !== undefined)
    .map((p) => {
      const v = state.params[p.name];
      return { from: p.from, to: p.to, insert: p.type === "str" ? JSON.stringify(v) : v };
    })
    .sort((a, b) => b.from - a.from);
  let out = text;
  for (const e of edits) out = out.slice(0, e.from) + e.insert + out.slice(e.to);
  state.params = {};
  state.paramShape = "";
  if (out !== text) ScnEditor.replaceText(editor, out); else edited(text);
}

function resetParams() {
  state.params = {};
  state.paramShape = "";
  edited(ScnEditor.textOf(editor));
}

async function save() {
  try {
    await post("/api/save", ScnEditor.textOf(editor));
    $("saved").textContent = `saved ${new Date().toLocaleTimeString()}`;
  } catch (e) { $("saved").textContent = `not saved: ${e.message}`; }
}

async function format() {
  const r = await (await post("/api/format", ScnEditor.textOf(editor))).json();
  if (r.text !== undefined) ScnEditor.replaceText(editor, r.text); else showDiagnostics(r.diagnostics);
}

async function writeCamera() {
  const r = await (await post(`/api/camera?${query({})}`, ScnEditor.textOf(editor))).json();
  if (r.text === undefined) { showDiagnostics(r.diagnostics); return; }
  state.view = homeView();
  ScnEditor.replaceText(editor, r.text);
}

async function exportAs(format) {
  try {
    const set = new URLSearchParams({ format, set: JSON.stringify(state.params) });
    const r = await post(`/api/export?${set}`, ScnEditor.textOf(editor));
    const name = (r.headers.get("Content-Disposition") || "").match(/filename="([^"]+)"/)?.[1] || `scene.${format}`;
    const a = document.createElement("a");
    a.href = URL.createObjectURL(await r.blob());
    a.download = name;
    document.body.append(a); a.click(); a.remove();
    $("note").textContent = `exported ${name}`;
  } catch (e) { $("note").textContent = `export failed: ${e.message}`; }
}

// --- camera --------------------------------------------------------------------------

function viewChanged() { render(ScnEditor.textOf(editor)); }

/** Selects the source of the object under the preview's point `(x, y)` (fractions). */
async function pick(x, y) {
  const r = await (await post(`/api/pick?${query({ x, y })}`, ScnEditor.textOf(editor))).json();
  $("note").textContent = r ? "" : "no object there";
  if (r) select(r.from, r.to);
}

let drag = null;
canvas.addEventListener("pointerdown", (e) => {
  drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey, startX: e.clientX, startY: e.clientY, moved: false };
  canvas.setPointerCapture(e.pointerId);
  canvas.classList.add("dragging");
});
canvas.addEventListener("pointermove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (Math.abs(e.clientX - drag.startX) + Math.abs(e.clientY - drag.startY) < 3 && !drag.moved) return;
  drag.moved = true;
  const size = canvas.getBoundingClientRect();
  if (drag.pan) {
    state.view.panx -= dx / size.width * state.view.zoom;
    state.view.pany += dy / size.height * state.view.zoom;
  } else {
    state.view.yaw += dx * 0.4;
    state.view.pitch = Math.max(-180, Math.min(180, state.view.pitch + dy * 0.4));
  }
  viewChanged();
});
const endDrag = () => { drag = null; canvas.classList.remove("dragging"); };
// A click that did not drag selects the object's line in the editor.
canvas.addEventListener("pointerup", (e) => {
  const clicked = drag && !drag.moved;
  endDrag();
  if (!clicked) return;
  const r = canvas.getBoundingClientRect();
  pick((e.clientX - r.left) / r.width, (e.clientY - r.top) / r.height);
});
canvas.addEventListener("pointercancel", endDrag);
canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  state.view.zoom = Math.max(0.01, Math.min(100, state.view.zoom * Math.exp(e.deltaY * 0.001)));
  viewChanged();
}, { passive: false });

// --- animation -----------------------------------------------------------------------

function setAnimation(frames, fps, frame) {
  state.frames = frames; state.fps = fps;
  $("animation").hidden = frames <= 1;
  $("frame").max = Math.max(0, frames - 1);
  $("frame").value = frame;
  $("frame-label").textContent = `frame ${frame} of ${frames} (${fps} fps)`;
}

let playTimer = null;
function scheduleNextFrame() {
  clearTimeout(playTimer);
  playTimer = setTimeout(() => {
    if (!state.playing) return;
    state.frame = (state.frame + 1) % state.frames;
    render(ScnEditor.textOf(editor), { coarse: 1 });
  }, 1000 / state.fps);
}

$("play").onclick = () => {
  state.playing = !state.playing;
  $("play").textContent = state.playing ? "⏸" : "▶";
  if (state.playing) scheduleNextFrame();
};
$("frame").oninput = () => { state.frame = Number($("frame").value); viewChanged(); };

// --- controls ------------------------------------------------------------------------

$("save").onclick = save;
$("format").onclick = format;
$("write-camera").onclick = writeCamera;
$("params-write").onclick = (e) => { e.preventDefault(); writeParams(); };
$("params-reset").onclick = (e) => { e.preventDefault(); resetParams(); };
$("reset-view").onclick = () => { state.view = homeView(); viewChanged(); };
$("backend").onchange = () => { state.backend = $("backend").value; viewChanged(); };
function rungChanged() {
  const on = $("accuracy-on").checked;
  $("accuracy").disabled = !on;
  state.rung = on ? Number($("accuracy").value) : null;
  $("rung").textContent = on ? `rung ${state.rung + 1} of 6` : "";
  if (!on) $("accuracy-result").textContent = "";
  viewChanged();
}
$("accuracy-on").onchange = rungChanged;
$("accuracy").oninput = rungChanged;

// --- downloads -----------------------------------------------------------------------

/** One button per format the server can write as one file (its list is the formats'). */
async function loadFormats() {
  const list = await (await fetch("/api/formats")).json();
  for (const f of list) {
    const b = document.createElement("button");
    b.id = `export-${f.name}`;
    b.dataset.testid = `export-${f.name}`;
    b.textContent = f.label;
    b.title = f.about;
    b.onclick = () => exportAs(f.name);
    $("exports").append(b);
  }
}

// --- examples ------------------------------------------------------------------------

async function loadExamples() {
  const list = await (await fetch("/api/examples")).json();
  const menu = $("examples");
  for (const [i, e] of list.entries()) {
    const o = document.createElement("option");
    o.value = String(i);
    o.textContent = e.name;
    menu.append(o);
  }
  menu.onchange = () => {
    const e = list[Number(menu.value)];
    menu.value = "";
    if (!e) return;
    state.view = homeView();
    ScnEditor.replaceText(editor, e.text);
    $("saved").textContent = `${e.name}: not saved (Ctrl-S writes it to the file)`;
  };
}

// --- start ---------------------------------------------------------------------------

(async () => {
  const file = await (await fetch("/api/file")).json();
  $("file").textContent = file.path;
  document.title = `${file.name} — scnc studio`;
  // A new or empty file starts from the tour, unsaved: the file is written on save.
  const opening = file.starter ?? file.text;
  editor = ScnEditor.create($("editor"), opening, {
    change: edited,
    save,
    format,
    hover: async (pos) => (await post(`/api/hover?pos=${pos}`, ScnEditor.textOf(editor))).json(),
    complete: async (pos) => (await post(`/api/complete?pos=${pos}`, ScnEditor.textOf(editor))).json(),
    signature: async (pos) => (await post(`/api/signature?pos=${pos}`, ScnEditor.textOf(editor))).json(),
  });
  window.scnStudio = { editor, state, ScnEditor };
  if (file.starter) $("saved").textContent = "new file: a starter scene, not saved yet";
  edited(opening);
  loadExamples();
  loadFormats();
  // The file on disk is the truth: an edit made elsewhere replaces the page's text.
  const events = new EventSource("/api/events");
  events.addEventListener("file", (e) => {
    const t = JSON.parse(e.data).text;
    if (t !== ScnEditor.textOf(editor)) ScnEditor.replaceText(editor, t);
  });
  events.addEventListener("include", () => edited(ScnEditor.textOf(editor)));
})();
