// The import graph of web/**/*.ts: no file imports itself back (no cycles), and each folder imports only
// the folders below it (the table below). Edges are static `import … from` / `export … from` / `import '…'`,
// dynamic `import('…')` and worker references `new URL('./x.ts', import.meta.url)`, type-only imports
// included. (The installed TypeScript 7 has no JavaScript API, so the import lines are read with regexes;
// the code's imports start at the beginning of a line.)
import { readdirSync, readFileSync } from 'node:fs';
import { join, posix, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';

const WEB = resolve(__dirname, '../../web');

/**
 * Which web/ folders a folder may import (besides itself), lowest first. Files directly in web/ (main.ts)
 * may import anything. A new folder fails the test until it is added here.
 */
const MAY_IMPORT: Record<string, string[]> = {
  motion: [],
  model: ['motion'],
  optimizer: ['model', 'motion'],
  runtime: ['model', 'motion', 'optimizer'],
  viewer: ['motion'],
  ui: ['motion', 'model', 'optimizer', 'runtime', 'viewer'],
  api: ['motion', 'model', 'optimizer', 'runtime', 'viewer', 'ui'],
};

const STATIC = /^(?:import|export)\b[^;'"]*?\bfrom\s*['"]([^'"]+)['"]/gm;
const SIDE_EFFECT = /^import\s*['"]([^'"]+)['"]/gm;
const DYNAMIC = /\bimport\(\s*['"]([^'"]+)['"]\s*\)/g;
const WORKER_URL = /\bnew URL\(\s*['"]([^'"]+)['"]\s*,\s*import\.meta\.url\s*\)/g;

/** The specifiers a file imports (comments dropped first for the ones that may sit anywhere in a line). */
function importSpecifiers(source: string): string[] {
  const code = source.replace(/\/\*[\s\S]*?\*\//g, '').replace(/(^|\s)\/\/.*$/gm, '$1');
  const found = [STATIC, SIDE_EFFECT].flatMap((re) => [...source.matchAll(re)]);
  found.push(...[DYNAMIC, WORKER_URL].flatMap((re) => [...code.matchAll(re)]));
  return found.map((m) => m[1]);
}

/** web/-relative paths (posix) of every .ts file, and each file's imports of other web files. */
function importGraph(): Map<string, string[]> {
  const files = (readdirSync(WEB, { recursive: true }) as string[])
    .filter((f) => f.endsWith('.ts'))
    .map((f) => f.split('\\').join('/'))
    .sort();
  const known = new Set(files);
  const graph = new Map<string, string[]>();
  for (const file of files) {
    const targets = new Set<string>();
    for (const spec of importSpecifiers(readFileSync(join(WEB, file), 'utf8'))) {
      if (!spec.startsWith('.')) continue; // a package
      const base = posix.normalize(posix.join(posix.dirname(file), spec.replace(/\?.*$/, '')));
      const target = [base, `${base}.ts`, `${base}/index.ts`].find((c) => known.has(c));
      if (target) targets.add(target);
    }
    graph.set(file, [...targets].sort());
  }
  return graph;
}

/**
 * Each strongly connected set of files (more than one, or a file importing itself) as one of its cycles,
 * "a.ts -> b.ts -> a.ts", followed by the whole set when the cycle does not pass through all of it.
 */
function findCycles(graph: Map<string, string[]>): string[] {
  // Tarjan's algorithm, then a shortest path back to the start inside each component.
  const index = new Map<string, number>(), low = new Map<string, number>(), onStack = new Set<string>();
  const stack: string[] = [];
  const components: string[][] = [];
  const visit = (v: string) => {
    index.set(v, index.size);
    low.set(v, index.get(v)!);
    stack.push(v);
    onStack.add(v);
    for (const w of graph.get(v) ?? []) {
      if (!index.has(w)) {
        visit(w);
        low.set(v, Math.min(low.get(v)!, low.get(w)!));
      } else if (onStack.has(w)) {
        low.set(v, Math.min(low.get(v)!, index.get(w)!));
      }
    }
    if (low.get(v) !== index.get(v)) return;
    const component: string[] = [];
    let w: string;
    do {
      w = stack.pop()!;
      onStack.delete(w);
      component.push(w);
    } while (w !== v);
    if (component.length > 1 || graph.get(v)?.includes(v)) components.push(component.sort());
  };
  for (const v of graph.keys()) if (!index.has(v)) visit(v);

  return components.map((component) => {
    const inside = new Set(component);
    const start = component[0];
    const previous = new Map<string, string>();
    const queue = [start];
    while (queue.length) {
      const v = queue.shift()!;
      const next = (graph.get(v) ?? []).filter((w) => inside.has(w));
      if (next.includes(start)) {
        const cycle = [start];
        for (let u = v; u !== start; u = previous.get(u)!) cycle.splice(1, 0, u);
        const all = cycle.length < component.length ? ` (${component.length} files in one knot: ${component.join(', ')})` : '';
        return `${[...cycle, start].join(' -> ')}${all}`;
      }
      for (const w of next) {
        if (previous.has(w) || w === start) continue;
        previous.set(w, v);
        queue.push(w);
      }
    }
    return component.join(' <-> '); // not reached: every file of a component leads back to the start
  });
}

const folderOf = (file: string) => (file.includes('/') ? file.slice(0, file.indexOf('/')) : '');

/** Imports that break the folder table, as "ui/x.ts (ui) imports api/y.ts (api)". */
function layeringViolations(graph: Map<string, string[]>): string[] {
  const out: string[] = [];
  for (const [file, targets] of graph) {
    const from = folderOf(file);
    if (from === '') continue;
    const allowed = MAY_IMPORT[from];
    if (!allowed) {
      out.push(`${file}: folder web/${from} is not in the layering table of tests/unit/imports.test.ts`);
      continue;
    }
    for (const target of targets) {
      const to = folderOf(target);
      if (to !== from && !allowed.includes(to)) out.push(`${file} (${from}) imports ${target} (${to || 'web/'})`);
    }
  }
  return out;
}

describe('web/ import graph', () => {
  const graph = importGraph();

  it('reads the imports (static, type-only, side-effect and worker references)', () => {
    expect(graph.get('main.ts')).toEqual(expect.arrayContaining(['api/element.ts', 'runtime/worker/assetBase.ts']));
    expect(graph.get('motion-playground.ts')).toEqual(expect.arrayContaining(['api/element.ts', 'runtime/worker/assetBase.ts']));
    expect(graph.get('ui/app.ts')).toContain('ui/modes/host.ts'); // `import type`
    expect(graph.get('viewer/viewer.ts')).toContain('viewer/palette.ts'); // `import './palette'`
    expect(graph.get('runtime/aclstm/danceClient.ts')).toContain('runtime/aclstm/dance.worker.ts'); // new URL(…, import.meta.url)
    expect(graph.get('motion/bvh.ts')?.length).toBeGreaterThan(0); // a multi-line import
  });

  it('has no import cycles', () => {
    const cycles = findCycles(graph);
    expect(cycles, `import cycles in web/:\n  ${cycles.join('\n  ')}`).toEqual([]);
  });

  it('keeps each folder to the folders below it', () => {
    expect(layeringViolations(graph)).toEqual([]);
  });

  it('finds a planted cycle and a planted layering break', () => {
    const planted = new Map(graph);
    planted.set('ui/dom.ts', [...(graph.get('ui/dom.ts') ?? []), 'ui/app.ts']);
    expect(findCycles(planted)).toContainEqual(expect.stringMatching(/^ui\/app\.ts -> ui\/dom\.ts -> ui\/app\.ts \(\d+ files in one knot: /));
    planted.set('motion/types.ts', ['viewer/viewer.ts']);
    expect(layeringViolations(planted)).toContain('motion/types.ts (motion) imports viewer/viewer.ts (viewer)');
  });
});

describe('importSpecifiers', () => {
  it('reads every import form and skips comments', () => {
    const source = [
      "import { a } from './a';",
      "import type {\n  B,\n  C,\n} from '../b';",
      "export { d } from './d';",
      "export * from './e';",
      "import './f';",
      "const g = await import('./g');",
      "new Worker(new URL('./h.worker.ts', import.meta.url), { type: 'module' });",
      "// import('./not-this')",
      "/** new URL('./nor-this.ts', import.meta.url) */",
      "export function from(x: number, from = 1) {}",
    ].join('\n');
    expect(importSpecifiers(source)).toEqual(['./a', '../b', './d', './e', './f', './g', './h.worker.ts']);
  });
});
