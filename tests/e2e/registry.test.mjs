// The model registry end to end: a model of a new kind added the way the registry says (a folder with a
// descriptor.ts under web/runtime/, and an entry in public/models/index.json) appears in the page's picker and
// works through playground.generate, with no other edit. The test builds that in a copy of the page (the
// repository's own files are left alone): the new kind reuses the acLSTM's client and network, so its dances
// must be the acLSTM's, bit for bit. Run with `npm run test:e2e`.
import assert from 'node:assert/strict';
import { cpSync, mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { createServer } from 'vite';
import { freePort, launchBrowser, openPlayground, ROOT } from './harness.mjs';

/** The new kind's folder: one descriptor, the acLSTM's with another kind and name. */
const DESCRIPTOR = `import { descriptor as aclstm } from '../aclstm/descriptor';
import type { ModelDescriptor } from '../descriptor';

export const descriptor: ModelDescriptor = { ...aclstm, kind: 'test-dancer', shortName: 'test dancer', labels: { 'my-dancer': 'My dancer' } };
`;

/** A copy of the page whose models list one more model, of the new kind, and whose runtime has its folder. */
function pageWithNewModel() {
  const dir = mkdtempSync(path.join(os.tmpdir(), 'registry-'));
  cpSync(path.join(ROOT, 'web'), path.join(dir, 'web'), { recursive: true });
  for (const file of ['vite.config.ts', 'package.json', 'tsconfig.json']) cpSync(path.join(ROOT, file), path.join(dir, file));
  cpSync(path.join(ROOT, 'examples'), path.join(dir, 'examples'), { recursive: true });
  symlinkSync(path.join(ROOT, 'node_modules'), path.join(dir, 'node_modules'), 'dir');
  // The shipped model files, linked; the new model's files are the acLSTM's under its own id.
  const models = path.join(dir, 'public', 'models');
  mkdirSync(models, { recursive: true });
  for (const name of readdirSync(path.join(ROOT, 'public', 'models'))) {
    if (name !== 'index.json') symlinkSync(path.join(ROOT, 'public', 'models', name), path.join(models, name));
  }
  symlinkSync(path.join(ROOT, 'public', 'models', 'aclstm.onnx'), path.join(models, 'my-dancer.onnx'));
  symlinkSync(path.join(ROOT, 'public', 'models', 'aclstm.json'), path.join(models, 'my-dancer.json'));
  const index = JSON.parse(readFileSync(path.join(ROOT, 'public', 'models', 'index.json'), 'utf8'));
  const aclstm = index.models.find((m) => m.id === 'aclstm');
  index.models.push({ ...aclstm, id: 'my-dancer', kind: 'test-dancer', file: 'my-dancer.onnx' });
  writeFileSync(path.join(models, 'index.json'), JSON.stringify(index, null, 1));
  for (const name of readdirSync(path.join(ROOT, 'public')).filter((n) => n !== 'models')) {
    symlinkSync(path.join(ROOT, 'public', name), path.join(dir, 'public', name));
  }
  mkdirSync(path.join(dir, 'web', 'runtime', 'test_dancer'));
  writeFileSync(path.join(dir, 'web', 'runtime', 'test_dancer', 'descriptor.ts'), DESCRIPTOR);
  return dir;
}

describe('a model of a new kind, added by its folder and its index.json entry', () => {
  let dir, server, browser, url;

  before(async () => {
    dir = pageWithNewModel();
    const port = await freePort();
    server = await createServer({
      configFile: path.join(dir, 'vite.config.ts'),
      cacheDir: path.join(dir, '.vite'),
      logLevel: 'warn',
      clearScreen: false,
      server: { host: '127.0.0.1', port, strictPort: true, hmr: false, watch: null, fs: { allow: [dir, ROOT] } },
    });
    await server.listen();
    url = `http://127.0.0.1:${port}/`;
    browser = await launchBrowser();
  });

  after(async () => {
    await browser?.close();
    await server?.close();
    if (dir) rmSync(dir, { recursive: true, force: true });
  });

  test('appears in the Dance picker and in models(), and dances through generate as the model it reuses', async () => {
    const { context, page, problems } = await openPlayground(browser, url);
    try {
      const listed = await page.evaluate(() => window.playground.models().map((m) => `${m.id}:${m.kind}`));
      assert.ok(listed.includes('my-dancer:test-dancer'), `models() lists the new model: ${listed}`);
      const options = await page.evaluate(() =>
        [...document.querySelector('motion-playground').shadowRoot.querySelector('#dance-model').options].map((o) => `${o.value}=${o.textContent}`),
      );
      assert.deepEqual(options, ['aclstm-mdn=acLSTM, phrase sampling', 'aclstm=acLSTM (deterministic)', 'my-dancer=My dancer']);
      const same = await page.evaluate(async () => {
        const a = await window.playground.generate({ model: 'my-dancer', style: 'salsa', frames: 60, seed: 3 });
        const b = await window.playground.generate({ model: 'aclstm', style: 'salsa', frames: 60, seed: 3 });
        return { frames: a.frames, joints: a.joints.length, equal: a.positions.length === b.positions.length && a.positions.every((v, i) => v === b.positions[i]) };
      });
      assert.deepEqual(same, { frames: 60, joints: same.joints, equal: true });
      assert.ok(same.joints > 10);
      // Its options are the acLSTM's: a style is required.
      const refused = await page.evaluate(() => window.playground.generate({ model: 'my-dancer', frames: 2, seed: 0 }).then(() => 'resolved', (e) => e.message));
      assert.equal(refused, 'generate: style is required for model "my-dancer" (styles: salsa, indian, martial)');
      assert.deepEqual(problems, []);
    } finally {
      await context.close();
    }
  });
});
