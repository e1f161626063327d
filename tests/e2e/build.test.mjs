// The production build: `vite build` into a temporary folder, served by `vite preview` (which must send
// the cross-origin isolation headers too), and the page works from it.
import assert from 'node:assert/strict';
import { createReadStream, existsSync, mkdtempSync, readFileSync, rmSync, statSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { build, preview } from 'vite';
import { corpusText, freePort, installUiLookups, launchBrowser, openPlayground, ROOT, waitUntil } from './harness.mjs';

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json', '.wasm': 'application/wasm', '.onnx': 'application/octet-stream', '.css': 'text/css', '.png': 'image/png' };

/**
 * A plain static file server (no special headers: not cross-origin isolated) with `folder` under `prefix`,
 * as a project website would host a copy of the built folder.
 */
function staticServer(folder, prefix) {
  const server = createServer((req, res) => {
    const pathname = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const file = pathname.startsWith(prefix) ? path.join(folder, pathname.slice(prefix.length)) : '';
    if (!file || !file.startsWith(folder) || !existsSync(file) || !statSync(file).isFile()) {
      res.writeHead(404).end('not found');
      return;
    }
    res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] ?? 'application/octet-stream' });
    createReadStream(file).pipe(res);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

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

  test('examples/embed.html runs from the built folder copied to a plain static host', async () => {
    assert.ok(existsSync(path.join(outDir, 'motion-playground.js')), 'the element is one module at the top of the folder');
    const host = await staticServer(outDir, '/site/playground/');
    try {
      const base = `http://127.0.0.1:${host.address().port}/site/playground/`;
      const context = await browser.newContext({ viewport: { width: 1000, height: 900 } });
      const page = await context.newPage();
      const problems = [];
      const missing = [];
      page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
      page.on('pageerror', (e) => problems.push(e.message));
      page.on('response', (r) => r.status() >= 400 && missing.push(`${r.status()} ${r.url()}`));
      await page.addInitScript(installUiLookups);
      await page.goto(`${base}examples/embed.html`, { waitUntil: 'load' });
      await waitUntil(page, () => document.getElementById('dance').playground?.current()?.frames > 0, null, { timeout: 90_000, message: 'the dance element dances' });
      await page.evaluate(() => document.getElementById('walk').scrollIntoView());
      await waitUntil(page, () => document.getElementById('walk').playground?.current()?.frames > 0, null, { timeout: 90_000, message: 'the lazy path element walks its path once scrolled to' });
      const r = await page.evaluate(() => ({
        isolated: crossOriginIsolated,
        views: ['dance', 'walk'].map((id) => document.getElementById(id).view),
        errors: ['dance', 'walk'].map((id) => document.getElementById(id).playground.lastError()),
      }));
      await context.close();
      assert.equal(r.isolated, false, 'a plain host: no isolation headers, one thread');
      assert.deepEqual(r.views[0], { mode: 'dance', model: 'aclstm', style: 'salsa', seed: 1 });
      assert.equal(r.views[1].mode, 'path');
      assert.equal(r.views[1].model, 'vae-lstm');
      assert.deepEqual(r.errors, [null, null]);
      assert.deepEqual(missing, [], 'every file is found under the copied folder (relative URLs)');
      assert.deepEqual(problems, []);
    } finally {
      await new Promise((resolve) => host.close(resolve));
    }
  });
});
