// The program editor: a textarea, checked as you type by compiling on the main thread (compiling
// takes well under a millisecond; meshing is what goes to the workers), with a parse error shown
// at its line and column, under the text it is about, and whole (it wraps at the editor's edge).

/** Parses the library's error text, `line:column: message` then the line and a caret. */
export function parseError(message) {
  const m = /^(\d+):(\d+): (.*)/.exec(message);
  return m ? { line: Number(m[1]), column: Number(m[2]), text: m[3] } : null;
}

export class Editor {
  /** `onEdit()` is called after each edit a person makes (not after `replace`). */
  constructor(textarea, errorBox, compile, onEdit = () => {}) {
    this.textarea = textarea;
    this.errorBox = errorBox;
    this.compile = compile;
    this.error = null;
    this.replacing = false;
    let timer = 0;
    textarea.addEventListener('input', () => {
      if (this.replacing) return;
      clearTimeout(timer);
      timer = setTimeout(() => this.check(), 200);
      onEdit();
    });
    textarea.addEventListener('scroll', () => this.place());
  }

  get text() {
    return this.textarea.value;
  }

  set text(value) {
    this.textarea.value = value;
    this.check();
  }

  /**
   * Replaces the whole text as one edit on the browser's undo stack, so that Ctrl+Z in the editor
   * brings back what was there (a plain `value =` would clear the stack). Focus goes back where
   * it was.
   */
  replace(value) {
    const t = this.textarea;
    const focused = document.activeElement;
    this.replacing = true;
    t.focus();
    t.select();
    const inserted = document.execCommand('insertText', false, value);
    this.replacing = false;
    if (!inserted || t.value !== value) t.value = value;
    t.setSelectionRange(0, 0);
    t.scrollTop = 0;
    if (focused && focused !== t && typeof focused.focus === 'function') focused.focus();
    this.check();
  }

  /** Compiles the text; shows and returns the error message, or null when it compiles. */
  check() {
    try {
      this.compile(this.text).free();
      this.error = null;
    } catch (e) {
      this.error = String(e.message ?? e);
    }
    this.place();
    return this.error;
  }

  /** Puts the error box under the error's line, the caret under its column. */
  place() {
    const box = this.errorBox;
    this.textarea.setAttribute('aria-invalid', this.error ? 'true' : 'false');
    if (!this.error) {
      box.hidden = true;
      return;
    }
    const at = parseError(this.error);
    const style = getComputedStyle(this.textarea);
    const lineHeight = parseFloat(style.lineHeight);
    const charWidth = measureChar(style.font);
    const line = at?.line ?? 1;
    box.hidden = false;
    box.dataset.line = String(line);
    box.dataset.column = String(at?.column ?? 0);
    box.textContent = at ? `${line}:${at.column}: ${at.text}` : this.error;
    box.style.top = `${parseFloat(style.paddingTop) + line * lineHeight - this.textarea.scrollTop + 2}px`;
    // The box spans the editor and wraps (a long message stays readable); its arrow points at
    // the column.
    const x = parseFloat(style.paddingLeft) + Math.max((at?.column ?? 1) - 1, 0) * charWidth - this.textarea.scrollLeft;
    box.style.setProperty('--caret', `${Math.min(Math.max(x, 0), this.textarea.clientWidth - 8)}px`);
  }
}

const widths = new Map();
function measureChar(font) {
  if (!widths.has(font)) {
    const ctx = document.createElement('canvas').getContext('2d');
    ctx.font = font;
    widths.set(font, ctx.measureText('0000000000').width / 10);
  }
  return widths.get(font);
}
