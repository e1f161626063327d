// The browser harness shared by the end-to-end tests (tests/e2e/harness.mjs re-exports it), the benchmarks
// (tests/bench) and the evaluation scripts (scripts/evaluate-*.mjs): a Vite dev server started in-process,
// headless Chromium (playwright-core, the system browser), the playground opened in a page, and corpus files
// read from ../shared/mocap. Nothing here belongs to node:test, so scripts can import it outside a test run.
import { existsSync, readFileSync } from 'node:fs';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { gunzipSync } from 'node:zlib';
import { chromium } from 'playwright-core';
import { createServer } from 'vite';

export const ROOT = fileURLToPath(new URL('../..', import.meta.url));
export const MOCAP = process.env.MOCAP_DIR ?? path.resolve(ROOT, '../shared/mocap');
export const CHROMIUM = process.env.CHROMIUM_PATH ?? '/usr/bin/chromium';
export const CHROMIUM_ARGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--no-first-run',
];

/** Raw bytes of a corpus file (path relative to the mocap folder, e.g. "cmu/asf/16.asf"). */
export function corpusBytes(rel) {
  const file = path.join(MOCAP, rel);
  if (!existsSync(file)) throw new Error(`corpus file missing: ${file} (set MOCAP_DIR to the shared/mocap folder)`);
  return readFileSync(file);
}

/** Text of a corpus file, gunzipped when it ends in .gz. */
export function corpusText(rel) {
  const bytes = corpusBytes(rel);
  return (rel.endsWith('.gz') ? gunzipSync(bytes) : bytes).toString('utf8');
}

/** A TCP port that was free a moment ago. */
export function freePort() {
  return new Promise((resolve, reject) => {
    const srv = net.createServer();
    srv.unref();
    srv.on('error', reject);
    srv.listen(0, '127.0.0.1', () => {
      const { port } = srv.address();
      srv.close(() => resolve(port));
    });
  });
}

/**
 * Starts the Vite dev server from vite.config.ts on a free port; returns { server, url }.
 * `headers` override response headers (e.g. to serve the page without cross-origin isolation).
 */
export async function startServer({ headers } = {}) {
  const port = await freePort();
  const server = await createServer({
    configFile: path.join(ROOT, 'vite.config.ts'),
    logLevel: 'warn',
    clearScreen: false,
    // No HMR and no file watching: the page under test must not reload itself.
    server: { host: '127.0.0.1', port, strictPort: true, hmr: false, watch: null, ...(headers ? { headers } : {}) },
  });
  await server.listen();
  return { server, url: `http://127.0.0.1:${port}/` };
}

export async function launchBrowser() {
  if (!existsSync(CHROMIUM)) throw new Error(`Chromium not found at ${CHROMIUM} (set CHROMIUM_PATH)`);
  return chromium.launch({ executablePath: CHROMIUM, args: CHROMIUM_ARGS });
}

/**
 * Opens the playground in a new page and waits for `playground.ready`. Console errors and page errors
 * are collected into the returned `problems` array.
 */
export async function openPlayground(browser, url, { width = 1280, height = 800 } = {}) {
  const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: 1, acceptDownloads: true });
  const page = await context.newPage();
  const problems = [];
  page.on('console', (msg) => {
    if (msg.type() === 'error') problems.push(`console.error: ${msg.text()}`);
  });
  page.on('pageerror', (err) => problems.push(`pageerror: ${err.message}`));
  page.on('requestfailed', (req) => problems.push(`request failed: ${req.url()} ${req.failure()?.errorText ?? ''}`));
  await page.addInitScript(installUiLookups);
  // A first visit opens on Random walk; the tests start from the empty Clip view unless the URL says otherwise.
  const address = new URL(url);
  if (!address.searchParams.has('mode')) address.searchParams.set('mode', 'clip');
  await page.goto(address.href, { waitUntil: 'load' });
  await page.waitForFunction(() => window.playground !== undefined, null, { timeout: 20_000 });
  await page.evaluate(() => window.playground.ready);
  return { context, page, problems };
}

/**
 * Runs in the page before its scripts: lookups into the page's <motion-playground> shadow root for the
 * tests' page.evaluate calls ($ui(id), $uiAll(selector), $uiOne(selector), $uiFrame() for the mode classes,
 * $uiActive() for the focused element inside it).
 */
export function installUiLookups() {
  const root = () => document.querySelector('motion-playground')?.shadowRoot ?? null;
  Object.assign(window, {
    $ui: (id) => root()?.getElementById(id) ?? null,
    $uiAll: (selector) => root()?.querySelectorAll(selector) ?? [],
    $uiOne: (selector) => root()?.querySelector(selector) ?? null,
    $uiFrame: () => root()?.querySelector('.app') ?? null,
    $uiActive: () => root()?.activeElement ?? null,
  });
}

/**
 * A page of a site holding `body`, which may use the element (its module is loaded first; /@vite/env defines
 * what the dev server's own pages get). `style` sizes the elements; with `recordEvents` every event of every
 * element in `body` is kept, in order, in window.events (listeners go on before the module defines the element).
 */
export function sitePage(body, { title = 'site', style = 'motion-playground { width: 480px; height: 320px; display: block; }', recordEvents = true } = {}) {
  const recorder = `<script>
  window.events = [];
  for (const el of document.querySelectorAll('motion-playground')) {
    for (const type of ['load', 'error', 'progress', 'play', 'pause', 'motion']) {
      el.addEventListener(type, (e) => window.events.push({ id: el.id, type, detail: e.detail ?? null }));
    }
  }
</script>`;
  return `<!doctype html><html><head><meta charset="utf-8"><title>${title}</title>
<script type="module" src="/@vite/env"></script>
<script type="module" src="/motion-playground.ts"></script>
<style>body { margin: 0; } ${style}</style></head>
<body>${body}
${recordEvents ? recorder : ''}</body></html>`;
}
