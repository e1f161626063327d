// Helpers for counting what <motion-playground> elements hold (issue 43): live Workers and WebGL contexts
// (counted by an init script that wraps the constructors), and the memory of the page: its JS heap after a
// forced collection (CDP Performance.getMetrics JSHeapUsedSize) and the resident memory of this browser's
// renderer and GPU processes (ps, the browser being a child of this node process). Used by
// tests/e2e/lifecycle.test.mjs and tests/bench/memory.mjs.
import { execFileSync } from 'node:child_process';
import { sitePage as browserSitePage } from './browser.mjs';

/** A page of the site (served at /site/… by `serveSite`) that loads the element's module; it keeps no events. */
export function sitePage(body, style = 'motion-playground { width: 320px; height: 240px; display: block; }') {
  return browserSitePage(body, { title: 'lifecycle', style, recordEvents: false });
}

export const ISOLATION = { 'Cross-Origin-Opener-Policy': 'same-origin', 'Cross-Origin-Embedder-Policy': 'require-corp' };

/** Serves `pages` (name → html) at `${url}site/<name>` in `context`, cross-origin isolated like the dev server. */
export async function serveSite(context, url, pages) {
  await context.route(`${url}site/**`, (route) => {
    const file = new URL(route.request().url()).pathname.replace(/^\/site\//, '');
    if (pages[file]) return route.fulfill({ status: 200, contentType: 'text/html', headers: ISOLATION, body: pages[file] });
    return route.fulfill({ status: 404, body: 'not here' });
  });
}

/**
 * Runs in the page before its scripts: window.__live.workers() is the number of Workers created and not
 * terminated; window.__live.contexts() the number of WebGL contexts made and not lost; window.__live.made the
 * number of contexts ever made.
 */
export function installCounters() {
  const NativeWorker = window.Worker;
  const live = new Set();
  class CountedWorker extends NativeWorker {
    constructor(...args) {
      super(...args);
      live.add(this);
    }
    terminate() {
      live.delete(this);
      super.terminate();
    }
  }
  window.Worker = CountedWorker;
  // Weakly held: the counter must not keep a removed element's canvas (and so the element) alive.
  const contexts = new Set();
  const seen = new WeakSet();
  const getContext = HTMLCanvasElement.prototype.getContext;
  const counters = {
    made: 0,
    workers: () => live.size,
    contexts: () => {
      let n = 0;
      for (const ref of contexts) {
        const gl = ref.deref();
        if (!gl) contexts.delete(ref);
        else if (!gl.isContextLost()) n++;
      }
      return n;
    },
  };
  HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
    const gl = getContext.call(this, type, ...rest);
    if (gl && /webgl/.test(String(type)) && !seen.has(gl)) {
      seen.add(gl);
      contexts.add(new WeakRef(gl));
      counters.made++;
    }
    return gl;
  };
  window.__live = counters;
}

/** Resident memory (MB) of this node process's Chromium renderer and GPU processes. */
export function rendererMemoryMB() {
  let out;
  try {
    out = execFileSync('ps', ['-eo', 'pid=,ppid=,rss=,args='], { encoding: 'utf8', maxBuffer: 16 << 20 });
  } catch {
    return null;
  }
  const procs = out.trim().split('\n').map((line) => {
    const m = line.trim().match(/^(\d+)\s+(\d+)\s+(\d+)\s+(.*)$/);
    return m && { pid: +m[1], ppid: +m[2], rss: +m[3], args: m[4] };
  }).filter(Boolean);
  const mine = new Set([process.pid]);
  let grew = true;
  while (grew) {
    grew = false;
    for (const p of procs) if (!mine.has(p.pid) && mine.has(p.ppid)) { mine.add(p.pid); grew = true; }
  }
  const kb = procs.filter((p) => mine.has(p.pid) && /--type=(renderer|gpu-process)/.test(p.args)).reduce((s, p) => s + p.rss, 0);
  return Math.round(kb / 1024);
}

/** The page's JS heap in use (MB) after a forced garbage collection, through CDP session `cdp`. */
export async function heapMB(cdp) {
  await cdp.send('HeapProfiler.collectGarbage');
  await cdp.send('HeapProfiler.collectGarbage');
  const { metrics } = await cdp.send('Performance.getMetrics');
  const used = metrics.find((m) => m.name === 'JSHeapUsedSize')?.value ?? 0;
  return +(used / 2 ** 20).toFixed(1);
}

/** Workers, WebGL contexts, heap and renderer memory now. */
export async function sample(page, cdp) {
  const heap = await heapMB(cdp);
  const counts = await page.evaluate(() => ({ workers: window.__live.workers(), contexts: window.__live.contexts(), elements: document.querySelectorAll('motion-playground').length }));
  return { ...counts, heapMB: heap, rendererMB: rendererMemoryMB() };
}

/**
 * Adds `n` elements (default view: Random walk, but one in Path mode walking a path and one dancing), waits
 * until each shows motion (or `timeout` ms), then removes them all and waits `settle` ms.
 */
export async function addAndRemove(page, n, { timeout = 60_000, settle = 500 } = {}) {
  const shown = await page.evaluate(async ({ n, timeout }) => {
    // Whether `el` shows motion within `timeout` ms; the timer is cleared, so that nothing here keeps a removed element.
    const shows = (el, timeout) => new Promise((resolve) => {
      const timer = setTimeout(() => resolve(false), timeout);
      el.addEventListener('motion', () => {
        clearTimeout(timer);
        resolve(true);
      }, { once: true });
    });
    const made = [];
    for (let i = 0; i < n; i++) {
      const el = document.createElement('motion-playground');
      el.setAttribute('controls', 'minimal');
      if (i === 1) { el.setAttribute('mode', 'path'); el.setAttribute('path', '0,0;3,1.5;6,0;9,-1.5'); }
      if (i === 2) { el.setAttribute('mode', 'dance'); el.setAttribute('model', 'aclstm'); el.setAttribute('autoplay', ''); }
      made.push(shows(el, timeout));
      document.body.append(el);
    }
    const shown = (await Promise.all(made)).filter(Boolean).length;
    for (const el of [...document.querySelectorAll('motion-playground')]) el.remove();
    return shown;
  }, { n, timeout });
  await page.waitForTimeout(settle);
  return shown;
}
