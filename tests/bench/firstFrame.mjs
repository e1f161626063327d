// First-frame family: a first visit of the production build (and of the dev server), from navigation start to
// the first generated frame on screen.
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import path from 'node:path';
import { build as viteBuild, preview as vitePreview } from 'vite';
import { freePort, installUiLookups, ROOT } from '../support/browser.mjs';
import { VIEWPORT } from './common.mjs';

/**
 * Runs in the page before its scripts (first-frame). Hooks window.playground as main.ts sets it, so `ready` is
 * seen as it resolves; then, unless the page has already chosen Random walk for itself (a first visit opens on
 * it: FIRST_VIEW in web/ui/viewState.ts, applied when `ready` resolves), presses the Random walk button. Watches
 * every display frame until the viewer holds the walk's first frames (playground.state().frames > 0) and takes
 * the time at the display frame after that one, by which the frame drawing them is on screen. Times are
 * performance.now(): ms since navigation start. The result lands in window.__firstFrame.
 */
function watchFirstFrame() {
  if (window.top !== window) return;
  performance.setResourceTimingBufferSize(100_000); // the dev server serves every module as a file of its own
  const out = { modeChosenByPage: null };
  let pg;
  Object.defineProperty(window, 'playground', {
    configurable: true,
    get: () => pg,
    set(value) {
      pg = value;
      value.ready.then(() => {
        out.readyMs = performance.now();
        const walk = window.$ui('mode-walk');
        out.modeChosenByPage = walk?.getAttribute('aria-pressed') === 'true';
        if (!out.modeChosenByPage) walk?.click();
      });
    },
  });
  // bytes: the file's size; transferred: its body as sent (smaller where the server compressed it).
  const file = (e) => ({
    file: new URL(e.name).pathname.split('/').pop(),
    bytes: e.decodedBodySize,
    transferred: e.encodedBodySize,
    startMs: Math.round(e.startTime),
    endMs: Math.round(e.responseEnd),
  });
  const tick = () => {
    if (out.readyMs === undefined || !(pg.state().frames > 0)) {
      requestAnimationFrame(tick);
      return;
    }
    out.shownMs = performance.now();
    requestAnimationFrame(() => {
      out.firstFrameMs = performance.now();
      out.walkPressed = window.$ui('mode-walk')?.getAttribute('aria-pressed') === 'true';
      out.title = window.$ui('clip-name')?.textContent ?? null;
      const done = performance.getEntriesByType('resource').filter((e) => e.responseEnd > 0 && e.responseEnd <= out.firstFrameMs);
      out.requests = done.length;
      out.models = done.filter((e) => new URL(e.name).pathname.includes('/models/')).map(file);
      out.wasm = done.filter((e) => new URL(e.name).pathname.endsWith('.wasm')).map(file);
      const nav = performance.getEntriesByType('navigation')[0];
      out.domContentLoadedMs = nav?.domContentLoadedEventEnd;
      out.loadMs = nav?.loadEventEnd;
      window.__firstFrame = out;
    });
  };
  requestAnimationFrame(tick);
}

/**
 * One fresh visit (a new browser context: empty cache) of `ctx.url + query`, watched by watchFirstFrame:
 * navigation start → `ready` → the first generated frame on screen, and the files fetched by then.
 */
async function firstFrameRun(ctx, query) {
  const context = await ctx.browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  try {
    const page = await context.newPage();
    const problems = [];
    page.on('console', (msg) => msg.type() === 'error' && problems.push(msg.text()));
    page.on('pageerror', (err) => problems.push(err.message));
    await page.addInitScript(installUiLookups);
    await page.addInitScript(watchFirstFrame);
    await page.goto(ctx.url + query, { waitUntil: 'commit' });
    await page.waitForFunction(() => window.__firstFrame, null, { timeout: 60_000, polling: 100 });
    const r = await page.evaluate(() => window.__firstFrame);
    if (!r.walkPressed) throw new Error(`the page is not in Random walk mode at its first frame (title ${JSON.stringify(r.title)})`);
    const sum = (files, key = 'bytes') => files.reduce((a, f) => a + f[key], 0);
    return {
      first_frame_ms: Math.round(r.firstFrameMs),
      ready_ms: Math.round(r.readyMs),
      shown_ms: Math.round(r.shownMs),
      dom_content_loaded_ms: Math.round(r.domContentLoadedMs),
      load_ms: Math.round(r.loadMs),
      walk_chosen_by: r.modeChosenByPage ? 'page' : 'click',
      // When each model file and the wasm were asked for and arrived: [start, end] ms after navigation start.
      fetched_ms: Object.fromEntries([...r.models, ...r.wasm].map((f) => [f.file, [f.startMs, f.endMs]])),
      model_bytes: sum(r.models),
      model_bytes_transferred: sum(r.models, 'transferred'),
      model_files: r.models,
      wasm_bytes: sum(r.wasm),
      requests: r.requests,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

/**
 * The page as `npm run build` makes it (without the type check), built into a git-ignored tmp/ folder and served
 * by `vite preview` (the same cross-origin isolation headers); `close()` stops the server and removes the folder.
 */
async function startBuiltPage() {
  mkdirSync(path.join(ROOT, 'tmp'), { recursive: true });
  const outDir = mkdtempSync(path.join(ROOT, 'tmp', 'bench-build-'));
  try {
    const configFile = path.join(ROOT, 'vite.config.ts');
    await viteBuild({ configFile, logLevel: 'error', build: { outDir, emptyOutDir: true, sourcemap: false } });
    const port = await freePort();
    const server = await vitePreview({ configFile, logLevel: 'warn', build: { outDir }, preview: { host: '127.0.0.1', port, strictPort: true, open: false } });
    return {
      url: `http://127.0.0.1:${port}/`,
      close: async () => {
        await server.close();
        rmSync(outDir, { recursive: true, force: true });
      },
    };
  } catch (e) {
    rmSync(outDir, { recursive: true, force: true });
    throw e;
  }
}

/**
 * First frame of a first visit: the plain URL in a fresh browser context opens on the refined Random walk (the
 * page chooses it when `ready` resolves; otherwise the watcher presses the button then), timed from navigation
 * start to the first generated frame on screen. Measured on the production build served from localhost (what a
 * visitor gets): one untimed visit, then `runs` visits of the plain URL and `runs` of `?refine=false` (the
 * generator alone), alternating. Also `runs` visits on the bench's dev server (which serves every module as a
 * file of its own, so its page alone loads far slower); its first visit also warms its module transforms.
 */
async function firstFrameBenchmark(ctx, { runs = 3 } = {}) {
  const median = (xs) => [...xs].sort((a, b) => a - b)[(xs.length - 1) >> 1];
  const summary = (rows) => ({
    first_frame_ms: median(rows.map((r) => r.first_frame_ms)),
    first_frame_ms_runs: rows.map((r) => r.first_frame_ms),
    ready_ms: median(rows.map((r) => r.ready_ms)),
    load_ms: median(rows.map((r) => r.load_ms)),
    model_bytes: rows[0].model_bytes,
    model_bytes_transferred: rows[0].model_bytes_transferred,
    model_files: Object.fromEntries(rows[0].model_files.map((f) => [f.file, f.bytes])),
    wasm_bytes: rows[0].wasm_bytes,
    walk_chosen_by: rows[0].walk_chosen_by,
  });
  const built = await startBuiltPage();
  const refined = [], raw = [], dev = [];
  let devCold;
  try {
    const at = { ...ctx, url: built.url };
    await firstFrameRun(at, ''); // untimed: the server's and the OS's file caches
    for (let i = 0; i < runs; i++) {
      refined.push(await firstFrameRun(at, ''));
      raw.push(await firstFrameRun(at, '?refine=false'));
    }
  } finally {
    await built.close();
  }
  devCold = await firstFrameRun(ctx, '');
  for (let i = 0; i < runs; i++) dev.push(await firstFrameRun(ctx, ''));
  return {
    served: 'the production build (vite build, vite preview) on localhost; the plain page URL (a first visit) in a fresh browser context per visit',
    ...summary(refined),
    target_first_frame_ms: 1500,
    runs: refined.map(({ model_files, ...r }) => r),
    generator_only: summary(raw),
    dev_server: { ...summary(dev), cold_first_frame_ms: devCold.first_frame_ms },
    page_errors: [devCold, ...refined, ...raw, ...dev].reduce((a, r) => a + r.page_errors, 0),
  };
}

/** The summary of a firstFrameBenchmark result. */
function firstFrameSummary(r) {
  const mb = (n) => `${(n / 1e6).toFixed(2)} MB`;
  const g = r.generator_only, d = r.dev_server;
  return (
    `first frame ${r.first_frame_ms} ms after navigation start (target ≤ ${r.target_first_frame_ms}; median of ${JSON.stringify(r.first_frame_ms_runs)}), production build;` +
    ` ready at ${r.ready_ms} ms; ${mb(r.model_bytes)} of models fetched by then (${Object.entries(r.model_files).map(([f, n]) => `${f} ${mb(n)}`).join(', ')}; ${mb(r.model_bytes_transferred)} as sent) + ${mb(r.wasm_bytes)} wasm;` +
    ` Random walk chosen by the ${r.walk_chosen_by}\n    with ?refine=false ${g.first_frame_ms} ms (${JSON.stringify(g.first_frame_ms_runs)}, ${mb(g.model_bytes)} of models);` +
    ` on the dev server ${d.first_frame_ms} ms (${JSON.stringify(d.first_frame_ms_runs)}, ready at ${d.ready_ms} ms; its first visit ${d.cold_first_frame_ms} ms)`
  );
}

export const BENCHMARKS = [
  {
    name: 'first-frame',
    description: 'a first visit (fresh browser context) of the production build on localhost, opening on Random walk: navigation start to the first generated frame on screen, and the model bytes fetched by then (also ?refine=false, and the dev server) — target ≤ 1,500 ms',
    run: (ctx) => firstFrameBenchmark(ctx),
    summary: firstFrameSummary,
  },
];
