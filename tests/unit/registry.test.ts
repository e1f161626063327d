// The model registry (web/runtime/registry.ts): the manifest's models joined with the descriptors of the
// model folders, and the rules that keep the page model-agnostic: no model id or kind is named outside its
// own folder (web/runtime/<model>/) and the registry, and three.js is imported only by the viewer.
import { readdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { parseManifest, type ModelInfo } from '../../web/model/manifest';
import { CLEANUP_METHODS } from '../../web/runtime/cleanup/cleanup';
import type { ModelDescriptor } from '../../web/runtime/descriptor';
import { descriptorsByKind, Registry } from '../../web/runtime/registry';

const WEB = resolve(__dirname, '../../web');
const MANIFEST = parseManifest(JSON.parse(readFileSync(resolve(__dirname, '../../public/models/index.json'), 'utf8')));

/** web/-relative paths (posix) and texts of every .ts file. */
function webSources(): Map<string, string> {
  const files = (readdirSync(WEB, { recursive: true }) as string[]).filter((f) => f.endsWith('.ts')).map((f) => f.split('\\').join('/'));
  return new Map(files.sort().map((f) => [f, readFileSync(join(WEB, f), 'utf8')]));
}

/** The code of a file without its comments (a model named in a comment is prose, not a branch). */
function code(source: string): string {
  return source.replace(/\/\*[\s\S]*?\*\//g, '').replace(/(^|[^:'"`])\/\/.*$/gm, '$1');
}

/** The model folders: web/runtime/<folder>/ with a descriptor.ts. */
function modelFolders(sources: Map<string, string>): string[] {
  return [...sources.keys()].filter((f) => /^runtime\/[^/]+\/descriptor\.ts$/.test(f)).map((f) => f.split('/')[1]);
}

/** web/runtime/<model>/ folders that mirror a training/<model>/ folder (with a descriptor or, like the refiner's, without). */
function mirroredFolders(): string[] {
  const training = new Set(readdirSync(resolve(WEB, '../training'), { withFileTypes: true }).filter((d) => d.isDirectory()).map((d) => d.name));
  return readdirSync(join(WEB, 'runtime'), { withFileTypes: true }).filter((d) => d.isDirectory() && training.has(d.name)).map((d) => d.name);
}

/**
 * "file: 'literal'" for each string literal outside the model folders and the registry that is exactly a
 * model id or kind of the manifest (`names`): a comparison, a quoted table key or a default naming a model.
 * (Bare keys are left alone: glTF's `asset.generator` is no model.)
 */
function modelNamesOutsideFolders(sources: Map<string, string>, names: Set<string>): string[] {
  const folders = mirroredFolders().map((f) => `runtime/${f}/`);
  const found: string[] = [];
  for (const [file, source] of sources) {
    if (folders.some((f) => file.startsWith(f)) || file === 'runtime/registry.ts') continue;
    for (const m of code(source).matchAll(/(['"`])([a-z][a-z0-9-]*)\1|\b([a-z][a-zA-Z0-9]*|'[a-z0-9-]+')\s*:/g)) {
      const literal = m[2] ?? m[3]?.replace(/'/g, '');
      if (literal && names.has(literal) && (m[2] !== undefined || m[3]?.startsWith("'"))) found.push(`${file}: '${literal}'`);
    }
  }
  return found;
}

/** Files outside web/viewer/ (and the glTF writer) that import three.js. */
function threeOutsideViewer(sources: Map<string, string>): string[] {
  return [...sources]
    .filter(([file]) => !file.startsWith('viewer/') && file !== 'motion/gltf.ts')
    .filter(([, source]) => /^import\b[^;]*?\bfrom\s*['"]three(\/[^'"]*)?['"]/m.test(source) || /import\s+\*\s+as\s+THREE\b/.test(source))
    .map(([file]) => file);
}

describe('the model registry', () => {
  it('finds one descriptor per model folder, by kind', () => {
    const kinds = descriptorsByKind();
    expect([...kinds.keys()].sort()).toEqual(['aclstm', 'latent-erd', 'lstm-gmm', 'vae-lstm']);
    expect(modelFolders(webSources()).sort()).toEqual(['aclstm', 'generator', 'latent_erd', 'vae_lstm']);
    expect(mirroredFolders().sort()).toEqual(['aclstm', 'autoencoder', 'generator', 'latent_erd', 'refiner', 'vae_lstm']);
  });

  it('offers each shipped model where its descriptor says, in manifest order', () => {
    const registry = new Registry(MANIFEST);
    expect(registry.ids('generate')).toEqual(['aclstm', 'aclstm-vanilla', 'generator', 'latent-erd', 'vae-lstm']);
    expect(registry.ids('dance')).toEqual(['aclstm', 'aclstm-vanilla']);
    expect(registry.ids('followPath')).toEqual(['generator', 'latent-erd', 'vae-lstm']);
    expect(registry.ids('liveControl')).toEqual(['generator', 'latent-erd']);
    expect(registry.defaultFor('walk')?.info.id).toBe('generator');
    // The refiner and the autoencoder are parts of other models: listed in the manifest, offered nowhere.
    expect(registry.find('refiner')).toBeUndefined();
    expect(registry.shortName('latent-erd')).toBe('latent ERD');
    expect(registry.label('aclstm-vanilla')).toBe('vanilla LSTM (baseline)');
  });

  it('offers a new kind as soon as the manifest lists a model of it and its folder describes it', () => {
    const dancer = { ...descriptorsByKind().get('aclstm')!, kind: 'test-dancer', shortName: 'test dancer' } satisfies ModelDescriptor;
    const kinds = descriptorsByKind({ './test_dancer/descriptor.ts': { descriptor: dancer }, ...Object.fromEntries([...descriptorsByKind()].map(([k, d]) => [`./${k}/descriptor.ts`, { descriptor: d }])) });
    const entry: ModelInfo = { id: 'my-dancer', kind: 'test-dancer', skeleton: 'aclstm-standard', fps: 30, styles: ['salsa'], bytes: 1 };
    const registry = new Registry([...MANIFEST, entry], kinds);
    expect(registry.ids('dance')).toEqual(['aclstm', 'aclstm-vanilla', 'my-dancer']);
    expect(new Registry(MANIFEST, kinds).ids('dance')).toEqual(['aclstm', 'aclstm-vanilla']); // not listed: not offered
    expect(() => descriptorsByKind({ './a/descriptor.ts': { descriptor: dancer }, './b/descriptor.ts': { descriptor: dancer } })).toThrow(/two descriptors of kind "test-dancer"/);
  });
});

describe('the page names no model outside its folder', () => {
  const sources = webSources();
  // "manifold" is also a clean-up method of the public API (denoise's method), named as such by the Clean up panel.
  const names = new Set(MANIFEST.flatMap((m) => [m.id, m.kind]).filter((name) => !(CLEANUP_METHODS as readonly string[]).includes(name)));

  it('compares no model id or kind outside web/runtime/<model>/ and the registry', () => {
    expect(modelNamesOutsideFolders(sources, names)).toEqual([]);
  });

  it('finds a planted comparison, table key and default', () => {
    const planted = new Map(sources);
    planted.set('ui/planted.ts', "if (model === 'latent-erd') go();\nconst short = { 'vae-lstm': 'VAE' };\nconst m = o.model ?? \"generator\"; // 'aclstm' in a comment is fine");
    expect(modelNamesOutsideFolders(planted, names)).toEqual(["ui/planted.ts: 'latent-erd'", "ui/planted.ts: 'vae-lstm'", "ui/planted.ts: 'generator'"]);
  });

  it('imports three.js only in web/viewer/', () => {
    expect(threeOutsideViewer(sources)).toEqual([]);
    const planted = new Map(sources);
    planted.set('ui/modes/planted.ts', "import * as THREE from 'three';");
    planted.set('ui/planted2.ts', "import { Vector3 } from 'three';");
    expect(threeOutsideViewer(planted)).toEqual(['ui/modes/planted.ts', 'ui/planted2.ts']);
  });
});
