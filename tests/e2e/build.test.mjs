// The production build: `vite build` into a temporary folder, served by `vite preview` (which must send
// the cross-origin isolation headers too), and the page works from it.
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { build, preview } from 'vite';
import { corpusText, freePort, launchBrowser, openPlayground, ROOT } from './harness.mjs';

describe('production build', { timeout: 120_000 }, () => {
  let outDir, server, browser;

  before(async () => {
    outDir = mkdtempSync(path.join(tmpdir(), 'playground-dist-'));
    const configFile = path.join(ROOT, 'vite.config.ts');
    await build({ configFile, logLevel: 'warn', build: { outDir, emptyOutDir: true, sourcemap: false } });
    const port = await freePort();
    server = await preview({ configFile, logLevel: 'warn', build: { outDir }, preview: { host: '127.0.0.1', port, strictPort: true } });
    browser = await launchBrowser();
  });

  after(async () => {
    await browser?.close();
    await server?.close();
    if (outDir) rmSync(outDir, { recursive: true, force: true });
  });

  test('the build contains the page and the model manifest', () => {
    assert.match(readFileSync(path.join(outDir, 'index.html'), 'utf8'), /<script type="module"/);
    const built = JSON.parse(readFileSync(path.join(outDir, 'models', 'index.json'), 'utf8'));
    assert.deepEqual(built, JSON.parse(readFileSync(path.join(ROOT, 'public', 'models', 'index.json'), 'utf8')));
    assert.ok(Array.isArray(built.models));
  });

  test('served by vite preview: isolated, ready, imports and shows a clip', async () => {
    const url = server.resolvedUrls.local[0];
    const res = await fetch(url);
    assert.equal(res.headers.get('cross-origin-opener-policy'), 'same-origin');
    assert.equal(res.headers.get('cross-origin-embedder-policy'), 'require-corp');
    const { context, page, problems } = await openPlayground(browser, url);
    const r = await page.evaluate(async (bvh) => {
      const p = window.playground;
      const m = await p.importMotion(bvh, 'bvh');
      p.show(m);
      return { isolated: crossOriginIsolated, version: p.version, frames: p.current().frames };
    }, corpusText('cmu/bvh/07_04.bvh.gz'));
    await page.waitForFunction(() => window.playground.state().frame > 0);
    await context.close();
    assert.equal(r.isolated, true);
    assert.equal(r.version, JSON.parse(readFileSync(path.join(ROOT, 'package.json'), 'utf8')).version);
    assert.equal(r.frames, 450);
    assert.deepEqual(problems, []);
  });
});
