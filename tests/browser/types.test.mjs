// Every JavaScript snippet of the two READMEs type-checks under `tsc --strict` against the built
// package's .d.ts files, resolved as npm installs them (a scratch project whose
// node_modules/isoforge is pkg/). What a snippet leaves to the reader (a `scene`, a `text`, the
// samples of a volume) is declared for it, and functions of "isoforge" it uses without importing
// are imported for it; nothing else is added. three is checked against @types/three. The
// generated .d.ts uses `Symbol.dispose`, so the lib includes `esnext.disposable` (the README
// says so).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, mkdirSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

const GIVEN = `import type { MeshResult } from 'isoforge';
import type { Material, Scene } from 'three';
declare const text: string;
declare const scene: Scene;
declare const material: Material;
declare const uint8Samples: Uint8Array;
declare const nx: number, ny: number, nz: number, x0: number, y0: number, z0: number, x1: number, y1: number, z1: number;
declare const result: MeshResult;
`;

/** The ```js blocks of `file` from the heading `from` on (to the next `## ` heading if `only`). */
function snippets(file, from, only = false) {
  let text = readFileSync(file, 'utf8');
  text = text.slice(text.indexOf(from));
  if (only) {
    const next = text.indexOf('\n## ', from.length);
    if (next > 0) text = text.slice(0, next);
  }
  return [...text.matchAll(/```js\n([\s\S]*?)```/g)].map((m) => m[1]);
}

test('every README snippet type-checks under tsc --strict', () => {
  assert.ok(existsSync('pkg/isoforge.d.ts'), 'pkg/ is not built: run scripts/build-wasm.sh first');
  const exported = new Set([...readFileSync('pkg/isoforge.d.ts', 'utf8').matchAll(/^export function (\w+)/gm)].map((m) => m[1]));
  const blocks = [
    ...snippets('pkg-config/README.md', '# isoforge').map((code, i) => [`npm-${i}`, code]),
    ...snippets('README.md', '## Quick start', true).map((code, i) => [`quick-${i}`, code]),
    ...snippets('README.md', '## JavaScript', true).map((code, i) => [`api-${i}`, code]),
  ];
  assert.ok(blocks.length >= 8, `${blocks.length} snippets found`);
  // Inside the repository, so that three and @types/three resolve from its node_modules.
  mkdirSync('target', { recursive: true });
  const dir = mkdtempSync(resolve('target/types-check-'));
  mkdirSync(join(dir, 'node_modules'));
  symlinkSync(resolve('pkg'), join(dir, 'node_modules', 'isoforge'), 'dir');
  writeFileSync(join(dir, 'package.json'), '{ "type": "module" }');
  // No @types/node here: the one Node function the snippets use, declared by hand.
  writeFileSync(join(dir, 'ambient.d.ts'),
    "declare module 'node:fs/promises' { export function writeFile(path: string, data: Uint8Array): Promise<void>; }\n");
  const files = ['ambient.d.ts'];
  for (const [name, code] of blocks) {
    const imported = new Set([...code.matchAll(/import\s+(?:\w+\s*,\s*)?\{([^}]*)\}\s*from\s*'isoforge'/g)].flatMap((m) => m[1].split(',').map((s) => s.trim())));
    const missing = [...exported].filter((f) => new RegExp(`\\b${f}\\(`).test(code) && !imported.has(f));
    const own = new Set([...code.matchAll(/\b(?:const|let)\s+\{?([^=;]*?)\}?\s*=/g)].flatMap((m) => m[1].split(',').map((s) => s.trim())));
    const given = GIVEN.split('\n').filter((line) => !['text', 'scene', 'material', 'result'].some((n) => own.has(n) && line.includes(`const ${n}:`))).join('\n');
    const three = /\bTHREE\./.test(code) && !/import \* as THREE/.test(code) ? "import * as THREE from 'three';\n" : '';
    const head = (missing.length ? `import { ${missing.join(', ')} } from 'isoforge';\n` : '') + three + given;
    writeFileSync(join(dir, `${name}.ts`), `${head}\n${code}\nexport {};\n`);
    files.push(`${name}.ts`);
  }
  const tsc = resolve('node_modules/typescript/bin/tsc');
  let out = '';
  try {
    execFileSync(process.execPath, [tsc, '--strict', '--noEmit', '--target', 'es2022', '--module', 'nodenext', '--moduleResolution', 'nodenext',
      '--lib', 'es2022,dom,esnext.disposable', ...files], { cwd: dir, encoding: 'utf8' });
  } catch (e) {
    out = `${e.stdout}${e.stderr}`;
  }
  if (!out) rmSync(dir, { recursive: true });
  assert.equal(out, '', `tsc --strict in ${dir}:\n${out}`);
});
