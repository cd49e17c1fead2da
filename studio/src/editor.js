// The editor of `scnc studio`: CodeMirror 6 with scn highlighting, and hooks through which
// the page (studio.js) pushes diagnostics and answers hover and completion from the
// server. Rebuild with `npm ci && npm run build` (see ../README.md, "Studio").
import { EditorState } from "@codemirror/state";
import {
  EditorView, keymap, lineNumbers, highlightActiveLine, highlightActiveLineGutter,
  drawSelection, hoverTooltip,
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
 * Makes the editor in `parent` holding `text`. `hooks`: `change(text)` after every edit,
 * `save()` on Mod-s, `format()` on Shift-Alt-f, `hover(pos)` and `complete(pos)` returning
 * promises of the server's answers.
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
        dom.textContent = h.text;
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
      EditorView.updateListener.of((u) => { if (u.docChanged) hooks.change(u.state.doc.toString()); }),
    ],
  });
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
