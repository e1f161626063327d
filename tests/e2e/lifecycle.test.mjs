// The element's lifecycle (issue 43): a removed <motion-playground> stops everything it started (workers, its
// WebGL context, its frame loop, a path walk being computed), ten rounds of adding and removing seven elements
// leave the page where it started; an element moved within the page keeps its state, one put back starts again;
// forty elements on one page each draw when scrolled into view while the live WebGL contexts stay few; an
// element whose context is lost or cannot be made fires `error` and shows its poster.
// Workers and contexts are counted by an init script (tests/support/lifecycle.mjs installCounters).
import assert from 'node:assert/strict';
import { after, before, describe, test } from 'node:test';
import { corpusText, launchBrowser, startServer, waitUntil } from './harness.mjs';
import { addAndRemove, heapMB, installCounters, serveSite, sitePage } from '../support/lifecycle.mjs';

const PATH = '0,0;3,1.5;6,0;9,-1.5';
const POSTER = 'data:image/svg+xml,' + encodeURIComponent('<svg xmlns="http://www.w3.org/2000/svg" width="4" height="4"><rect width="4" height="4" fill="red"/></svg>');

describe('the element lifecycle', { timeout: 900_000 }, () => {
  let server, url, browser;

  before(async () => {
    ({ server, url } = await startServer());
    browser = await launchBrowser();
  });
  after(async () => {
    await browser?.close();
    await server?.close();
  });

  async function open(name, html, { width = 1000, height = 800 } = {}) {
    const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: 1 });
    await serveSite(context, url, { [name]: html });
    const page = await context.newPage();
    const problems = [];
    page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
    page.on('pageerror', (e) => problems.push(e.message));
    await page.addInitScript(installCounters);
    await page.goto(`${url}site/${name}`, { waitUntil: 'load' });
    await page.waitForFunction(() => customElements.get('motion-playground') !== undefined);
    return { context, page, problems };
  }

  const live = (page) => page.evaluate(() => ({ workers: window.__live.workers(), contexts: window.__live.contexts() }));

  test('ten rounds of adding and removing seven elements leave the workers, contexts and heap where they started', async () => {
    const { context, page, problems } = await open('churn.html', sitePage(''));
    const cdp = await context.newCDPSession(page);
    await cdp.send('Performance.enable');
    assert.deepEqual(await live(page), { workers: 0, contexts: 0 });
    // The first round loads the modules and the shared downloads (kept for the page): the heap is compared after it.
    assert.equal(await addAndRemove(page, 7), 7, 'the seven elements of the first round show motion');
    await waitUntil(page, () => window.__live.workers() === 0, null, { message: 'the first round\'s workers are stopped' });
    await page.waitForTimeout(1000);
    const heapStart = await heapMB(cdp);
    for (let round = 2; round <= 10; round++) {
      assert.equal(await addAndRemove(page, 7), 7, `the seven elements of round ${round} show motion`);
      await waitUntil(page, () => window.__live.workers() === 0 && window.__live.contexts() === 0, null, { message: `round ${round}: every worker stopped and every context freed` });
    }
    await page.waitForTimeout(1000);
    const heapEnd = await heapMB(cdp);
    console.log(`# heap after round 1: ${heapStart} MB, after round 10: ${heapEnd} MB; workers ${JSON.stringify(await live(page))}`);
    assert.ok(heapEnd <= heapStart * 1.1, `the JS heap stays within 10 % (${heapStart} → ${heapEnd} MB)`);
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('a Path-mode element removed while its walk is computed stops it; moved, an element keeps its state; put back, it starts again', async () => {
    const { context, page, problems } = await open('one.html', sitePage('<div id="left"></div><div id="right"></div>'));
    await page.evaluate(({ PATH }) => {
      window.events = [];
      const el = document.createElement('motion-playground');
      el.id = 'p';
      el.setAttribute('mode', 'path');
      el.setAttribute('path', PATH);
      for (const type of ['motion', 'error', 'progress']) el.addEventListener(type, (e) => window.events.push({ type, detail: e.detail }));
      document.getElementById('left').append(el);
    }, { PATH });
    // Taken off the page while the walk is being computed: no walk arrives, its worker is stopped.
    await waitUntil(page, () => window.events.some((e) => e.type === 'progress' && e.detail.what === 'path') && window.__live.workers() > 0, null, { timeout: 90_000, message: 'the path walk is being computed' });
    await page.evaluate(() => document.getElementById('p').remove());
    await waitUntil(page, () => window.__live.workers() === 0 && window.__live.contexts() === 0, null, { message: 'the removed element stopped its workers and freed its context' });
    const progressAt = await page.evaluate(() => window.events.length);
    await page.waitForTimeout(3000);
    assert.deepEqual(await page.evaluate((n) => window.events.slice(n), progressAt), [], 'nothing more from the removed element: no walk, no error');

    // A walking element moved to another place on the page keeps its stream (no new motion) and workers.
    await page.evaluate(() => {
      const el = document.createElement('motion-playground');
      el.id = 'w';
      el.setAttribute('mode', 'walk');
      el.addEventListener('motion', () => window.events.push({ type: 'walk-motion' }));
      document.getElementById('left').append(el);
    });
    await waitUntil(page, () => Number(document.getElementById('w').shadowRoot.getElementById('walk-status').dataset.frame) > 10, null, { timeout: 90_000, message: 'the walking element walks' });
    const before = await page.evaluate(() => ({ motions: window.events.filter((e) => e.type === 'walk-motion').length, workers: window.__live.workers(), contexts: window.__live.made }));
    await page.evaluate(() => document.getElementById('right').append(document.getElementById('w')));
    const frame = await page.evaluate(() => Number(document.getElementById('w').shadowRoot.getElementById('walk-status').dataset.frame));
    await waitUntil(page, (f) => Number(document.getElementById('w').shadowRoot.getElementById('walk-status').dataset.frame) > f + 10, frame, { message: 'moved, it walks on' });
    const moved = await page.evaluate(() => ({ motions: window.events.filter((e) => e.type === 'walk-motion').length, workers: window.__live.workers(), contexts: window.__live.made }));
    assert.deepEqual(moved, before, 'moved within the page: the same stream, workers and context');

    // Removed and put back: it stops, then starts again from its attributes.
    await page.evaluate(() => {
      window.removed = document.getElementById('w');
      window.removed.remove();
    });
    await waitUntil(page, () => window.__live.workers() === 0 && window.__live.contexts() === 0, null, { message: 'removed: no workers, no context' });
    await page.evaluate(() => document.getElementById('left').append(window.removed));
    await waitUntil(page, (n) => window.events.filter((e) => e.type === 'walk-motion').length > n && Number(document.getElementById('w').shadowRoot.getElementById('walk-status').dataset.frame) > 10, moved.motions, { timeout: 90_000, message: 'put back, it walks again' });
    assert.ok((await live(page)).workers >= 1);
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('forty elements on one page each draw when scrolled into view, with few live WebGL contexts', async () => {
    const body = Array.from({ length: 40 }, (_, i) => `<motion-playground id="e${i}" mode="clip" controls="none" poster="${POSTER}"></motion-playground>`).join('\n');
    const { context, page, problems } = await open('forty.html', sitePage(body, 'motion-playground { width: 360px; height: 220px; display: block; margin: 0 0 24px; }'), { width: 800, height: 600 });
    await page.evaluate(() => {
      window.errors = [];
      for (const el of document.querySelectorAll('motion-playground')) el.addEventListener('error', (e) => window.errors.push({ id: el.id, reason: e.detail.reason }));
    });
    const bvh = corpusText('cmu/bvh/07_04.bvh.gz');
    // One import, shown by every element (a still clip would not need drawing every frame: each plays it).
    await page.evaluate(async (text) => {
      const all = [...document.querySelectorAll('motion-playground')];
      await Promise.all(all.map((el) => el.ready));
      const motion = await all[0].playground.importMotion(text, 'bvh');
      for (const el of all) el.playground.show(motion, 'walk');
    }, bvh);
    /** Scrolls element `id` into view and reads its canvas right after the viewer drew it: how many pixels differ from the background. */
    const drawn = (id) => page.evaluate(async (id) => {
      const el = document.getElementById(id);
      el.scrollIntoView({ block: 'center' });
      const canvas = el.shadowRoot.querySelector('canvas');
      const read = () => new Promise((resolve) => requestAnimationFrame(() => {
        // After the viewer's own frame callback (registered earlier): the drawing buffer holds this frame.
        const w = 90, h = 55;
        const c = document.createElement('canvas');
        c.width = w;
        c.height = h;
        const g = c.getContext('2d');
        g.drawImage(canvas, 0, 0, w, h);
        const data = g.getImageData(0, 0, w, h).data;
        const bg = [data[0], data[1], data[2]];
        let differ = 0;
        for (let i = 0; i < data.length; i += 4) if (Math.abs(data[i] - bg[0]) + Math.abs(data[i + 1] - bg[1]) + Math.abs(data[i + 2] - bg[2]) > 30) differ++;
        resolve(differ);
      }));
      for (let tries = 0; tries < 120; tries++) {
        const n = await read();
        if (n > 20) return n;
      }
      return 0;
    }, id);
    let most = 0;
    const order = [...Array.from({ length: 40 }, (_, i) => `e${i}`), 'e0', 'e1', 'e2'];
    for (const id of order) {
      const n = await drawn(id);
      assert.ok(n > 20, `${id} draws when scrolled into view (${n} pixels off the background)`);
      most = Math.max(most, (await live(page)).contexts);
    }
    const counts = await live(page);
    console.log(`# live WebGL contexts at most ${most} (now ${counts.contexts}); made ${await page.evaluate(() => window.__live.made)}`);
    assert.ok(most <= 10, `live WebGL contexts stay few (at most ${most})`);
    assert.deepEqual(await page.evaluate(() => window.errors), [], 'no element lost its context');
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('an element whose context is lost, or cannot be made, fires error and shows its poster', async () => {
    const body = `<motion-playground id="a" mode="clip" controls="none" poster="${POSTER}"></motion-playground>`;
    const { context, page, problems } = await open('lost.html', sitePage(body));
    await page.evaluate(() => {
      window.errors = [];
      document.getElementById('a').addEventListener('error', (e) => window.errors.push(e.detail.reason));
    });
    await page.evaluate(() => document.getElementById('a').ready);
    const bvh = corpusText('cmu/bvh/07_04.bvh.gz');
    await page.evaluate(async (text) => {
      const el = document.getElementById('a');
      el.playground.show(await el.playground.importMotion(text, 'bvh'), 'walk');
    }, bvh);
    const posterHidden = () => page.evaluate(() => document.getElementById('a').shadowRoot.querySelector('.poster').hidden);
    await waitUntil(page, () => window.__live.contexts() === 1, null, { message: 'the element has its context' });
    assert.equal(await posterHidden(), true, 'a motion shown: no poster');
    // The browser takes the context (as it does beyond 16 on a page).
    await page.evaluate(() => {
      window.loser = document.getElementById('a').shadowRoot.querySelector('canvas').getContext('webgl2').getExtension('WEBGL_lose_context');
      window.loser.loseContext();
    });
    await waitUntil(page, () => window.errors.some((r) => /WebGL/.test(r)), null, { message: 'a lost context fires error' });
    assert.equal(await posterHidden(), false, 'the poster is shown instead');
    await page.evaluate(() => window.loser.restoreContext());
    await waitUntil(page, () => document.getElementById('a').shadowRoot.querySelector('.poster').hidden, null, { message: 'restored, the poster goes' });
    // Taken again and not given back: the element asks for it when it is next scrolled into view.
    await page.evaluate(() => {
      window.loser.loseContext();
      const spacer = document.createElement('div');
      spacer.style.height = '3000px';
      document.body.append(spacer);
    });
    await waitUntil(page, () => window.errors.filter((r) => /WebGL/.test(r)).length === 2 && !document.getElementById('a').shadowRoot.querySelector('.poster').hidden, null, { message: 'lost again: error and poster' });
    await page.evaluate(() => window.scrollTo(0, 2500));
    await page.waitForTimeout(500);
    await page.evaluate(() => window.scrollTo(0, 0));
    await waitUntil(page, () => document.getElementById('a').shadowRoot.querySelector('.poster').hidden && window.__live.contexts() === 1, null, { message: 'scrolled back, the element has its context again and the poster goes' });

    // A new element that can get no context at all.
    await page.evaluate((poster) => {
      const getContext = HTMLCanvasElement.prototype.getContext;
      HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
        if (this.getRootNode().host?.id === 'b' && /webgl/.test(type)) return null;
        return getContext.call(this, type, ...rest);
      };
      const el = document.createElement('motion-playground');
      el.id = 'b';
      el.setAttribute('mode', 'clip');
      el.setAttribute('poster', poster);
      el.addEventListener('error', (e) => window.errors.push(`b: ${e.detail.reason}`));
      document.body.prepend(el);
    }, POSTER);
    await waitUntil(page, () => window.errors.some((r) => /^b: WebGL/.test(r)), null, { message: 'no context: error fires' });
    assert.equal(await page.evaluate(() => document.getElementById('b').shadowRoot.querySelector('.poster').hidden), false, 'and the poster shows');
    assert.deepEqual(problems.filter((p) => !/WebGL|context/i.test(p)), []);
    await context.close();
  });
});
