// The language reference panel, built from the library's own table of functions
// (languageReference()), so it lists exactly what the parser accepts.

const GROUPS = [['shapes', 'Shapes'], ['combinators', 'Combinators'], ['transforms', 'Transforms'], ['math', 'Math']];

/** Fills `root` with the functions by group; clicking one calls `insert(signature)`. */
export function showReference(root, entries, insert) {
  for (const [group, title] of GROUPS) {
    const heading = Object.assign(document.createElement('h3'), { textContent: title });
    const list = document.createElement('dl');
    for (const e of entries.filter((x) => x.group === group)) {
      const term = document.createElement('dt');
      const button = Object.assign(document.createElement('button'), { type: 'button', textContent: e.signature, title: 'insert at the cursor' });
      button.dataset.name = e.name;
      button.addEventListener('click', () => insert(e.signature.replace(', …', '')));
      term.append(button);
      list.append(term, Object.assign(document.createElement('dd'), { textContent: e.summary }));
    }
    root.append(heading, list);
  }
}
