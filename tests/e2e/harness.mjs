// Shared setup for the end-to-end tests: the browser harness (tests/support/browser.mjs, also used by the
// benchmarks and the evaluation scripts), re-exported here, and the tests' own helpers below.
import assert from 'node:assert/strict';
import { after, afterEach, before } from 'node:test';
import { launchBrowser, openPlayground, startServer } from '../support/browser.mjs';

export {
  CHROMIUM,
  CHROMIUM_ARGS,
  corpusBytes,
  corpusText,
  freePort,
  installUiLookups,
  launchBrowser,
  MOCAP,
  openPlayground,
  ROOT,
  sitePage,
  startServer,
} from '../support/browser.mjs';

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
