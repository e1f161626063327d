// Shared setup for the end-to-end tests and the benchmark: a Vite dev server started in-process,
// headless Chromium (playwright-core, the system browser) and corpus files read from ../shared/mocap.
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { after, afterEach, before } from 'node:test';
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

/** Waits for `n` animation frames in the page (lets the viewer render what was just set). */
export function nextFrames(page, n = 2) {
  return page.evaluate(
    (count) =>
      new Promise((resolve) => {
        let left = count;
        const step = () => (--left <= 0 ? resolve() : requestAnimationFrame(step));
        requestAnimationFrame(step);
      }),
    n,
  );
}

/**
 * Waits until `fn` (run in the page with `arg`) returns a truthy value, like `page.waitForFunction`, and
 * returns that value. If it does not within `timeout` ms it fails as an assertion with `message` (what
 * did not happen), so a test that waits on the page's state fails for that reason, not with a bare
 * timeout. The timeout only bounds a hang; nothing is asserted about how long the wait took.
 */
export async function waitUntil(page, fn, arg, { timeout = 30_000, message = 'the page never reached the state waited for' } = {}) {
  try {
    const handle = await page.waitForFunction(fn, arg, { timeout });
    const value = await handle.jsonValue();
    await handle.dispose();
    return value;
  } catch (e) {
    if (e?.name !== 'TimeoutError') throw e;
    throw new assert.AssertionError({ message: `${message} (waited ${Math.round(timeout / 1000)} s)` });
  }
}

/**
 * For a `describe` block: starts the dev server, Chromium and one playground page before its tests and
 * closes them after. Returns an object whose `server`, `url`, `browser`, `page`, `context` and
 * `problems` are filled in once the tests run. After each test, the console and page errors collected
 * during it must be none (and are cleared), so every test checks its own.
 */
export function usePlayground(options) {
  const suite = {};
  before(async () => {
    Object.assign(suite, await startServer());
    suite.browser = await launchBrowser();
    Object.assign(suite, await openPlayground(suite.browser, suite.url, options));
  });
  afterEach(() => {
    assert.deepEqual(suite.problems?.splice(0) ?? [], [], 'no console or page errors during the test');
  });
  after(async () => {
    await suite.browser?.close();
    await suite.server?.close();
  });
  return suite;
}

/**
 * Drags the mouse along `points` (fractions of the page's canvas, [x, y]) with the left button, `steps`
 * mouse moves per segment, then lets the page draw twice.
 */
export async function drawStroke(page, points, steps = 3) {
  const box = await page.locator('canvas.viewer-canvas').boundingBox();
  const at = ([fx, fy]) => [box.x + fx * box.width, box.y + fy * box.height];
  await page.mouse.move(...at(points[0]));
  await page.mouse.down();
  for (const p of points.slice(1)) await page.mouse.move(...at(p), { steps });
  await page.mouse.up();
  await nextFrames(page, 2);
}

/**
 * How a window.playground call fails: { message: null } if it resolves, else its message and name, lastError
 * and the frames shown (so a test can check the page kept what it showed).
 */
export function apiFailure(page, method, options) {
  return page.evaluate(
    async ({ method, options }) => {
      try {
        await window.playground[method](options);
        return { message: null };
      } catch (e) {
        return { message: e.message, name: e.name, lastError: window.playground.lastError(), shown: window.playground.current()?.frames ?? null };
      }
    },
    { method, options },
  );
}
