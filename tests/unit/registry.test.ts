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

/** web/-relative paths (posix) and texts of every .ts and .html file. */
function webSources(): Map<string, string> {
  const files = (readdirSync(WEB, { recursive: true }) as string[]).filter((f) => /\.(ts|html)$/.test(f)).map((f) => f.split('\\').join('/'));
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

/** A model id in camel case, as a property would name it ("latent-erd" → "latentErd"). */
const camel = (id: string) => id.replace(/-([a-z0-9])/g, (_, c: string) => c.toUpperCase());

/**
 * "file: 'name'" for each place outside the model folders and the registry that names a model id or kind of
 * the manifest (`names`): a string literal or quoted table key that is exactly one (a comparison, a key, a
 * default), a regular expression that matches one, a property named after one (`app.latentErd`), or an HTML
 * attribute value that is one (a fixed `<option value="…">`). Prose is left alone ("loading the generator…"),
 * and so are bare keys, since glTF's `asset: { generator: … }` is no model.
 */
function modelNamesOutsideFolders(sources: Map<string, string>, names: Set<string>): string[] {
  const folders = mirroredFolders().map((f) => `runtime/${f}/`);
  const properties = new Map([...names].map((n) => [camel(n), n]));
  const found: string[] = [];
  const named = (text: string) => [...names].filter((n) => new RegExp(`(?<![\\w-])${n}(?![\\w-])`).test(text));
  for (const [file, source] of sources) {
    if (folders.some((f) => file.startsWith(f)) || file === 'runtime/registry.ts') continue;
    if (file.endsWith('.html')) {
      for (const m of source.matchAll(/=\s*"([^"]*)"/g)) if (names.has(m[1])) found.push(`${file}: '${m[1]}'`);
      continue;
    }
    const text = code(source);
    for (const m of text.matchAll(/(['"`])([a-z][a-z0-9-]*)\1|'([a-z0-9-]+)'\s*:/g)) {
      const literal = m[2] ?? m[3];
      if (names.has(literal)) found.push(`${file}: '${literal}'`);
    }
    for (const m of text.matchAll(/(?<=[=(,:!&|?]\s*)\/((?:\\.|[^/\n\\])+)\/[dgimsuy]*/g)) {
      for (const n of named(m[1])) found.push(`${file}: /${n}/`);
    }
    for (const m of text.matchAll(/\.([a-z][a-zA-Z0-9]*)\b/g)) {
      const id = properties.get(m[1]);
      if (id !== undefined && (file.startsWith('ui/') || file.startsWith('api/'))) found.push(`${file}: .${m[1]}`);
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
    expect(registry.ids('generate')).toEqual(['aclstm-mdn', 'aclstm', 'generator', 'style-generator', 'latent-erd', 'vae-lstm']);
    expect(registry.ids('dance')).toEqual(['aclstm-mdn', 'aclstm']);
    expect(registry.defaultFor('dance')?.info.id).toBe('aclstm-mdn'); // issue 42: Dance starts with the sampled model
    expect(registry.ids('followPath')).toEqual(['generator', 'style-generator', 'latent-erd', 'vae-lstm']);
    expect(registry.ids('liveControl')).toEqual(['generator', 'style-generator', 'latent-erd']);
    expect(registry.defaultFor('walk')?.info.id).toBe('generator'); // the CMU-only model stays the default
    expect(registry.defaultFor('followPath')?.info.id).toBe('generator');
    expect(registry.defaultFor('liveControl')?.info.id).toBe('generator');
    // The refiner and the autoencoder are parts of other models: listed in the manifest, offered nowhere.
    expect(registry.find('refiner')).toBeUndefined();
    expect(registry.shortName('latent-erd')).toBe('latent ERD');
    expect(registry.label('aclstm')).toBe('acLSTM (deterministic)');
  });

  it('says what each shipped model was trained on and under what licence; a non-commercial model is labelled so', () => {
    const registry = new Registry(MANIFEST);
    for (const m of MANIFEST) {
      expect(m.data, m.id).toMatch(/CMU/);
      if (m.commercial === false) {
        // Trained on the Bandai Namco set (CC BY-NC 4.0): says so, and is labelled so in every picker.
        expect(m.data, m.id).toMatch(/Bandai Namco/);
        expect(m.licence, m.id).toMatch(/CC BY-NC 4\.0.*non-commercial/);
        expect(registry.label(m.id)).toMatch(/\(non-commercial\)$/);
      } else {
        expect(m.licence, m.id).toMatch(/free for research and commercial use/);
        expect(m.commercial, m.id).toBe(true);
      }
    }
    expect(MANIFEST.filter((m) => m.commercial === false).map((m) => m.id)).toEqual(['style-generator']);
    expect(registry.provenance('generator')).toMatch(/^Trained on CMU motion capture .*\. Licence: CMU .*commercial use\.$/);
    const styled: ModelInfo = { ...MANIFEST.find((m) => m.id === 'generator')!, id: 'styled', data: 'CMU and Bandai Namco', licence: 'CC BY-NC 4.0', commercial: false };
    const withStyled = new Registry([...MANIFEST, styled]);
    expect(withStyled.label('styled')).toBe('styled (non-commercial)');
    expect(withStyled.ids('walk')).toEqual(['generator', 'style-generator', 'styled']); // the CMU-only model stays the default
    expect(() => parseManifest({ models: [{ ...styled, commercial: 'no' }] })).toThrow(/commercial must be true or false/);
    expect(() => parseManifest({ models: [{ ...styled, licence: 4 }] })).toThrow(/licence must be a string/);
  });

  it('offers a new kind as soon as the manifest lists a model of it and its folder describes it', () => {
    const dancer = { ...descriptorsByKind().get('aclstm')!, kind: 'test-dancer', shortName: 'test dancer' } satisfies ModelDescriptor;
    const kinds = descriptorsByKind({ './test_dancer/descriptor.ts': { descriptor: dancer }, ...Object.fromEntries([...descriptorsByKind()].map(([k, d]) => [`./${k}/descriptor.ts`, { descriptor: d }])) });
    const entry: ModelInfo = { id: 'my-dancer', kind: 'test-dancer', skeleton: 'aclstm-standard', fps: 30, styles: ['salsa'], bytes: 1 };
    const registry = new Registry([...MANIFEST, entry], kinds);
    expect(registry.ids('dance')).toEqual(['aclstm-mdn', 'aclstm', 'my-dancer']);
    expect(new Registry(MANIFEST, kinds).ids('dance')).toEqual(['aclstm-mdn', 'aclstm']); // not listed: not offered
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
    planted.set('ui/planted.ts', [
      "if (model === 'latent-erd') go();",
      "const short = { 'vae-lstm': 'VAE' };",
      'const m = o.model ?? "generator"; // \'aclstm\' in a comment is fine',
      "const why = message.replace(/^(generator|refiner) denoise: /, '');",
      'const { client } = await app.latentErd.load();',
      "note('loading the generator…'); const asset = { generator: 'Motion Playground' };",
    ].join('\n'));
    planted.set('ui/planted.html', '<select id="m"><option value="vae-lstm">VAE-LSTM</option><option value="">off</option></select>');
    expect(modelNamesOutsideFolders(planted, names)).toEqual([
      "ui/planted.ts: 'latent-erd'",
      "ui/planted.ts: 'vae-lstm'",
      "ui/planted.ts: 'generator'",
      'ui/planted.ts: /generator/',
      'ui/planted.ts: /refiner/',
      'ui/planted.ts: .latentErd',
      "ui/planted.html: 'vae-lstm'",
    ]);
  });

  it('imports three.js only in web/viewer/', () => {
    expect(threeOutsideViewer(sources)).toEqual([]);
    const planted = new Map(sources);
    planted.set('ui/modes/planted.ts', "import * as THREE from 'three';");
    planted.set('ui/planted2.ts', "import { Vector3 } from 'three';");
    expect(threeOutsideViewer(planted)).toEqual(['ui/modes/planted.ts', 'ui/planted2.ts']);
  });
});
