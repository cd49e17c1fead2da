// The editor of `scnc studio`: CodeMirror 6 with scn highlighting, and hooks through which
// the page (studio.js) pushes diagnostics and answers hover and completion from the
// server. Rebuild with `npm ci && npm run build` (see ../README.md, "Studio").
import { EditorState, StateEffect, StateField } from "@codemirror/state";
import {
  EditorView, keymap, lineNumbers, highlightActiveLine, highlightActiveLineGutter,
  drawSelection, hoverTooltip, showTooltip,
} from "@codemirror/view";
import { defaultKeymap, history, historyKeymap, indentWithTab } from "@codemirror/commands";
import {
  StreamLanguage, syntaxHighlighting, defaultHighlightStyle, bracketMatching, indentOnInput,
} from "@codemirror/language";
import { setDiagnostics, lintGutter } from "@codemirror/lint";
import { autocompletion, closeBrackets, closeBracketsKeymap } from "@codemirror/autocomplete";
import { searchKeymap, highlightSelectionMatches } from "@codemirror/search";

const KEYWORDS = new Set([
  "let", "object", "light", "camera", "render", "for", "in", "if", "then", "else",
  "include", "at", "with", "rotate", "scale", "and", "or", "not", "true", "false", "mesh",
]);

// The scn tokens, as the lexer (src/syntax/token.rs) has them, for colour only.
const scn = StreamLanguage.define({
  name: "scn",
  token(stream) {
    if (stream.eatSpace()) return null;
    if (stream.match("//")) { stream.skipToEnd(); return "comment"; }
    if (stream.match(/^"(?:[^"\\]|\\.)*"?/)) return "string";
    if (stream.match(/^#[0-9a-fA-F]{3,8}\b/)) return "number";
    if (stream.match(/^\d+(?:\.\d+)?(?:[eE][+-]?\d+)?/)) return "number";
    if (stream.match(/^[A-Za-z_][A-Za-z0-9_]*/)) {
      const w = stream.current();
      if (KEYWORDS.has(w)) return "keyword";
      if (stream.peek() === "(") return "function";
      return "variableName";
    }
    if (stream.match(/^(=>|==|!=|<=|>=|\.\.|[-+*\/%<>=])/)) return "operator";
    stream.next();
    return null;
  },
  languageData: { commentTokens: { line: "//" } },
});

/**
 * The hover docs' Markdown as DOM nodes (never as HTML text): fenced code blocks,
 * paragraphs, "- " lists, and `code` and **bold** within them, which is all the
 * builtins' docs use.
 */
export function markdown(text) {
  const root = document.createElement("div");
  // Even pieces are prose, odd ones code (split on the fences).
  const pieces = text.split(/```[a-z]*\n?/);
  pieces.forEach((piece, i) => {
    if (i % 2 === 1) {
      const pre = document.createElement("pre");
      pre.className = "scn-hover-code";
      pre.textContent = piece.replace(/\n$/, "");
      root.append(pre);
      return;
    }
    for (const para of piece.split(/\n\s*\n/)) {
      if (!para.trim()) continue;
      // Runs of lines starting "- " are lists; the lines between them, paragraphs.
      let list = null, prose = [];
      const flush = () => {
        if (prose.length) { const p = document.createElement("p"); inline(p, prose.join(" ")); root.append(p); prose = []; }
      };
      for (const line of para.trim().split("\n")) {
        if (line.trimStart().startsWith("- ")) {
          flush();
          if (!list) { list = document.createElement("ul"); root.append(list); }
          const li = document.createElement("li");
          inline(li, line.trimStart().slice(2));
          list.append(li);
        } else {
          list = null;
          prose.push(line.trim());
        }
      }
      flush();
    }
  });
  return root;
}

/** Appends `text` to `el` with its `code` and **bold** spans as elements. */
function inline(el, text) {
  for (const part of text.split(/(`[^`]+`|\*\*[^*]+\*\*)/)) {
    if (!part) continue;
    if (part.startsWith("`") && part.endsWith("`") && part.length > 1) {
      const c = document.createElement("code");
      c.textContent = part.slice(1, -1);
      el.append(c);
    } else if (part.startsWith("**") && part.endsWith("**") && part.length > 3) {
      const b = document.createElement("strong");
      b.textContent = part.slice(2, -2);
      el.append(b);
    } else {
      el.append(document.createTextNode(part));
    }
  }
}

/** The signature shown while the cursor is in a builtin's call (null when none). */
const setSignature = StateEffect.define();
const signatureField = StateField.define({
  create: () => null,
  update(value, tr) {
    for (const e of tr.effects) if (e.is(setSignature)) value = e.value;
    if (value && tr.docChanged) value = { ...value, pos: tr.changes.mapPos(value.pos) };
    return value;
  },
  provide: (field) => showTooltip.from(field, (sig) => sig && {
    pos: sig.pos, above: true, strictSide: false,
    create() {
      const dom = document.createElement("div");
      dom.className = "scn-signature";
      dom.dataset.testid = "signature";
      const head = document.createElement("div");
      // The label with the active parameter in bold.
      const active = sig.active !== null && sig.active !== undefined ? sig.params[sig.active] : null;
      const at = active ? sig.label.indexOf(active.label) : -1;
      if (at >= 0) {
        const b = document.createElement("strong");
        b.textContent = active.label;
        head.append(sig.label.slice(0, at), b, sig.label.slice(at + active.label.length));
      } else {
        head.textContent = sig.label;
      }
      dom.append(head);
      const doc = document.createElement("div");
      doc.className = "scn-signature-doc";
      doc.textContent = active ? active.doc : sig.doc;
      dom.append(doc);
      return { dom };
    },
  }),
});

/**
 * Makes the editor in `parent` holding `text`. `hooks`: `change(text)` after every edit,
 * `save()` on Mod-s, `format()` on Shift-Alt-f, `hover(pos)`, `complete(pos)` and
 * `signature(pos)` returning promises of the server's answers.
 */
export function create(parent, text, hooks) {
  const hover = hoverTooltip(async (view, pos) => {
    const h = await hooks.hover(pos);
    if (!h) return null;
    return {
      pos: h.from, end: h.to, above: true,
      create() {
        const dom = document.createElement("div");
        dom.className = "scn-hover";
        dom.dataset.testid = "hover";
        dom.append(markdown(h.text));
        return { dom };
      },
    };
  });
  const complete = async (context) => {
    const word = context.matchBefore(/[A-Za-z_][A-Za-z0-9_]*/);
    if (!word && !context.explicit) return null;
    const items = await hooks.complete(context.pos);
    return {
      from: word ? word.from : context.pos,
      options: items.map((c) => ({ label: c.label, detail: c.detail, info: c.doc || undefined, type: c.kind })),
    };
  };
  const keys = [
    { key: "Mod-s", preventDefault: true, run: () => { hooks.save(); return true; } },
    { key: "Shift-Alt-f", preventDefault: true, run: () => { hooks.format(); return true; } },
  ];
  const state = EditorState.create({
    doc: text,
    extensions: [
      lineNumbers(), highlightActiveLineGutter(), highlightActiveLine(), history(), drawSelection(),
      indentOnInput(), bracketMatching(), closeBrackets(), highlightSelectionMatches(),
      syntaxHighlighting(defaultHighlightStyle, { fallback: true }), scn, lintGutter(), hover,
      autocompletion({ override: [complete] }),
      keymap.of([...keys, ...closeBracketsKeymap, ...defaultKeymap, ...searchKeymap, ...historyKeymap, indentWithTab]),
      EditorView.updateListener.of((u) => {
        if (u.docChanged) hooks.change(u.state.doc.toString());
        if (u.docChanged || u.selectionSet) askSignature(u.view);
      }),
      EditorView.lineWrapping, signatureField,
    ],
  });
  // The signature of the call the cursor is in, asked for once typing pauses.
  let timer = null;
  let asked = 0;
  function askSignature(view) {
    clearTimeout(timer);
    timer = setTimeout(async () => {
      const pos = view.state.selection.main.head;
      const seq = ++asked;
      let sig = null;
      try { sig = await hooks.signature(pos); } catch (e) { sig = null; }
      if (seq !== asked || view.state.selection.main.head !== pos) return;
      view.dispatch({ effects: setSignature.of(sig ? { ...sig, pos } : null) });
    }, 120);
  }
  return new EditorView({ state, parent });
}

/** Shows `diagnostics` ({from, to, severity, message}, offsets in the editor's text). */
export function showDiagnostics(view, diagnostics) {
  const len = view.state.doc.length;
  const clamped = diagnostics.map((d) => ({
    ...d, from: Math.min(d.from, len), to: Math.min(Math.max(d.to, d.from), len),
  }));
  view.dispatch(setDiagnostics(view.state, clamped));
}

/** Replaces the whole text (a reload, a format), keeping the cursor where it can. */
export function replaceText(view, text) {
  const head = Math.min(view.state.selection.main.head, text.length);
  view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: text }, selection: { anchor: head } });
}

/** The current text. */
export function textOf(view) {
  return view.state.doc.toString();
}
