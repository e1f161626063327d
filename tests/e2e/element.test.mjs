// The <motion-playground> element (issue 17) on pages of its own, served by the dev server: attributes and
// properties reflect each other and events fire; two elements run on one page with their own workers and
// one download per model file, and one taken off the page stops until put back; loading="lazy" fetches nothing until scrolled to; bad attributes and link
// parameters fire `error` with a reason and keep the defaults; `src` is fetched from the page's origin only;
// a link round trip gives the same view and the same motion; Share copies the link and Embed shows the
// snippet; a file or joint name holding markup is shown as text.
import assert from 'node:assert/strict';
import { after, before, describe, test } from 'node:test';
import { corpusText, installUiLookups, launchBrowser, nextFrames, startServer, waitUntil, sitePage } from './harness.mjs';

const ISOLATION = { 'Cross-Origin-Opener-Policy': 'same-origin', 'Cross-Origin-Embedder-Policy': 'require-corp' };
const PATH = '0,0;3,1.5;6,0;9,-1.5';

describe('the <motion-playground> element', { timeout: 240_000 }, () => {
  let server, url, browser;
  const pages = new Map();

  before(async () => {
    ({ server, url } = await startServer());
    browser = await launchBrowser();
  });
  after(async () => {
    await browser?.close();
    await server?.close();
  });

  /**
   * Opens `name` (one of `pages`) in a fresh context; `requests` lists every URL fetched (the page's and its
   * workers'), `problems` the console errors and page errors.
   */
  async function open(name, { width = 1000, height = 800, isolated = true, query = '' } = {}) {
    const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: 1, acceptDownloads: true });
    const page = await context.newPage();
    const problems = [];
    const requests = [];
    page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
    page.on('pageerror', (e) => problems.push(e.message));
    page.on('request', (r) => r.resourceType() !== 'script' && requests.push(r.url())); // scripts: the dev server's `?import&url` modules name the wasm too
    await page.addInitScript(installUiLookups);
    await page.route(`${url}site/**`, (route) => {
      const file = new URL(route.request().url()).pathname.replace(/^\/site\//, '');
      if (pages.has(file)) return route.fulfill({ status: 200, contentType: 'text/html', headers: isolated ? ISOLATION : {}, body: pages.get(file) });
      if (file === 'clips/walk.bvh') return route.fulfill({ status: 200, contentType: 'text/plain', headers: { 'Cross-Origin-Resource-Policy': 'same-origin' }, body: corpusText('cmu/bvh/07_04.bvh.gz') });
      if (file === 'clips/markup.bvh') return route.fulfill({ status: 200, contentType: 'text/plain', body: MARKUP_BVH });
      return route.fulfill({ status: 404, body: 'not here' });
    });
    await page.goto(`${url}site/${name}${query}`, { waitUntil: 'load' });
    return { context, page, problems, requests };
  }

  const events = (page, id, type) => page.evaluate(({ id, type }) => window.events.filter((e) => (!id || e.id === id) && (!type || e.type === type)), { id, type });
  const waitForEvent = (page, id, type, message) =>
    waitUntil(page, ({ id, type }) => window.events.some((e) => e.id === id && e.type === type), { id, type }, { timeout: 90_000, message });
  /** Downloads of models and of the onnxruntime wasm. */
  const modelFiles = (requests) => requests.filter((u) => /\.(onnx|wasm)(\?|$)/.test(u));

  test('two dancing elements run on one page, each its own, with one download of each model file', async () => {
    pages.set('two.html', sitePage(`
      <motion-playground id="a" mode="dance" model="aclstm" dance-style="salsa" seed="1" autoplay controls="minimal"></motion-playground>
      <motion-playground id="b" mode="dance" model="aclstm" dance-style="salsa" seed="2" autoplay controls="none"></motion-playground>`));
    const { context, page, problems, requests } = await open('two.html');
    for (const id of ['a', 'b']) await waitForEvent(page, id, 'motion', `element #${id} shows a dance`);
    await waitUntil(page, () => [...document.querySelectorAll('motion-playground')].every((el) => el.playground.state().frame > 20), null, { message: 'both dances play' });
    const r = await page.evaluate(() => {
      const [a, b] = document.querySelectorAll('motion-playground');
      const first = (el) => Array.from(el.playground.current().positions.slice(0, 6));
      const out = { loads: window.events.filter((e) => e.type === 'load').map((e) => e.id), seedA: a.seed, seedB: b.seed, differ: first(a).join() !== first(b).join() };
      a.pause();
      out.pausedA = !a.playground.state().playing;
      out.playingB = b.playground.state().playing;
      out.controls = [a, b].map((el) => [...el.shadowRoot.querySelector('.app').classList].filter((c) => c.startsWith('controls-')));
      return out;
    });
    assert.deepEqual(r.loads.sort(), ['a', 'b']);
    assert.deepEqual([r.seedA, r.seedB], [1, 2]);
    assert.ok(r.differ, 'the two seeds dance differently');
    assert.ok(r.pausedA && r.playingB, 'pausing one leaves the other playing');
    assert.deepEqual(r.controls, [['controls-minimal'], ['controls-none']]);
    const files = modelFiles(requests);
    const perFile = new Map();
    for (const u of files) perFile.set(u.split('?')[0], (perFile.get(u.split('?')[0]) ?? 0) + 1);
    const counts = [...perFile].map(([u, n]) => [u.split('/').pop(), n]);
    assert.ok(counts.some(([f]) => /\.onnx$/.test(f)) && counts.some(([f]) => /\.wasm$/.test(f)), `the model and the runtime were fetched: ${JSON.stringify(counts)}`);
    assert.deepEqual(counts.filter(([, n]) => n > 1), [], `each model file is downloaded once for both elements: ${JSON.stringify(counts)}`);
    // Taken off the page, an element stops drawing and streaming; put back, it dances again.
    const pausedAt = await page.evaluate(() => {
      const a = document.getElementById('a');
      a.play();
      return a.playground.state().frame;
    });
    await waitUntil(page, (n) => document.getElementById('a').playground.state().frame > n + 5, pausedAt, { message: 'the first element plays again' });
    const removedAt = await page.evaluate(() => {
      const a = document.getElementById('a');
      window.removedA = a;
      a.remove();
      return a.playground.state().frame;
    });
    const bNow = await page.evaluate(() => document.getElementById('b').playground.state().frame);
    await waitUntil(page, (n) => document.getElementById('b').playground.state().frame > n + 30, bNow, { message: 'the other element plays on' });
    assert.equal(await page.evaluate(() => window.removedA.playground.state().frame), removedAt, 'the removed element is still');
    const motions = (await events(page, 'a', 'motion')).length;
    await page.evaluate(() => document.body.prepend(window.removedA));
    await waitUntil(page, (n) => window.events.filter((e) => e.id === 'a' && e.type === 'motion').length > n && document.getElementById('a').playground.state().frame > 10, motions, { message: 'put back, it streams a dance again' });
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('attributes and properties reflect each other, and play, pause and motion fire', async () => {
    pages.set('one.html', sitePage(`<motion-playground id="w" mode="walk" seed="3" temperature="0.4" refine="false" autoplay camera-controls></motion-playground>`));
    const { context, page, problems } = await open('one.html');
    await waitForEvent(page, 'w', 'motion', 'the walk starts');
    await waitForEvent(page, 'w', 'play', 'play fires as the walk plays');
    const r = await page.evaluate(async () => {
      const el = document.querySelector('motion-playground');
      const ui = (id) => el.shadowRoot.getElementById(id);
      // The element reflects its UI a moment after a change (a timer): wait for the state, not for a fixed time.
      const until = async (ok, ms = 10_000) => {
        for (const t0 = performance.now(); !ok() && performance.now() - t0 < ms; ) await new Promise((resolve) => setTimeout(resolve, 20));
      };
      const out = { props: { mode: el.mode, seed: el.seed, temperature: el.temperature, refine: el.refine, cameraControls: el.cameraControls, autoplay: el.autoplay } };
      out.ui = { seed: ui('walk-seed').value, temperature: Number(ui('walk-temperature').value) };
      el.seed = 11; // property → attribute → UI
      out.seedAttribute = el.getAttribute('seed');
      await el.ready;
      await until(() => ui('walk-seed').value === '11');
      out.uiSeed = ui('walk-seed').value;
      el.setAttribute('temperature', '0.8'); // attribute → property → UI
      await until(() => Number(ui('walk-temperature').value) === 0.8);
      out.temperature = [el.temperature, Number(ui('walk-temperature').value)];
      const seedInput = ui('walk-seed'); // UI → attribute
      seedInput.value = '21';
      seedInput.dispatchEvent(new Event('change', { bubbles: true }));
      await until(() => el.getAttribute('seed') === '21');
      out.fromUi = [el.getAttribute('seed'), el.seed];
      el.cameraControls = false;
      out.cameraControls = [el.hasAttribute('camera-controls'), el.playground !== undefined];
      el.pause();
      await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
      out.paused = !el.playground.state().playing;
      el.play();
      await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
      const m = await el.generate(); // 10 s from the element's view
      out.generated = { frames: m.frames, joints: m.joints.length };
      out.bvhStart = el.exportBVH().slice(0, 9);
      const glb = el.exportGLB();
      out.glbMagic = String.fromCharCode(...glb.slice(0, 4));
      out.currentTime = typeof el.currentTime === 'number' && el.currentTime >= 0;
      return out;
    });
    assert.deepEqual(r.props, { mode: 'walk', seed: 3, temperature: 0.4, refine: false, cameraControls: true, autoplay: true });
    assert.deepEqual(r.ui, { seed: '3', temperature: 0.4 });
    assert.equal(r.seedAttribute, '11');
    assert.equal(r.uiSeed, '11');
    assert.deepEqual(r.temperature, [0.8, 0.8]);
    assert.deepEqual(r.fromUi, ['21', 21]);
    assert.deepEqual(r.cameraControls, [false, true]);
    assert.equal(r.paused, true);
    assert.deepEqual(r.generated, { frames: 300, joints: r.generated.joints });
    assert.ok(r.generated.joints > 10);
    assert.equal(r.bvhStart, 'HIERARCHY');
    assert.equal(r.glbMagic, 'glTF');
    assert.ok(r.currentTime);
    const kinds = new Set((await events(page, 'w')).map((e) => e.type));
    for (const type of ['load', 'motion', 'play', 'pause', 'progress']) assert.ok(kinds.has(type), `${type} fired (got ${[...kinds].join(', ')})`);
    assert.deepEqual(await events(page, 'w', 'error'), []);
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('with loading="lazy" nothing is fetched for the models until the element is scrolled to', async () => {
    pages.set('lazy.html', sitePage(`<div style="height: 3000px">a long page</div>
      <motion-playground id="lazy" mode="dance" model="aclstm" dance-style="salsa" seed="1" autoplay loading="lazy"></motion-playground>`));
    const { context, page, problems, requests } = await open('lazy.html');
    await page.evaluate(() => document.querySelector('motion-playground').shadowRoot !== null); // the element is defined
    await waitUntil(page, () => customElements.get('motion-playground') !== undefined, null, { message: 'the element is defined' });
    await nextFrames(page, 10);
    assert.deepEqual(modelFiles(requests), [], 'no model or runtime file before scrolling');
    assert.equal(requests.some((u) => u.includes('/models/')), false, 'not even the model list');
    assert.deepEqual(await events(page, 'lazy', 'load'), []);
    await page.evaluate(() => document.querySelector('motion-playground').scrollIntoView());
    await waitForEvent(page, 'lazy', 'motion', 'the dance starts once scrolled to');
    assert.ok(modelFiles(requests).some((u) => /\.onnx/.test(u)), 'the model is fetched once scrolled to');
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('bad attributes fire error with a reason and keep the default; src from another origin is refused', async () => {
    pages.set('bad.html', sitePage(`
      <motion-playground id="bad" mode="fly" seed="-3" temperature="hot" controls="huge" path="1,2,3"></motion-playground>
      <motion-playground id="far" src="https://example.com/walk.bvh" controls="minimal"></motion-playground>
      <motion-playground id="src" src="clips/walk.bvh"></motion-playground>`));
    const { context, page, problems } = await open('bad.html');
    for (const id of ['bad', 'far', 'src']) await waitForEvent(page, id, 'load', `#${id} loads`);
    await waitForEvent(page, 'src', 'motion', 'the same-origin src is shown');
    const reasons = (await events(page, 'bad', 'error')).map((e) => e.detail.reason);
    for (const pattern of [/mode="fly": must be one of clip, walk, dance, path, steer/, /seed="-3"/, /temperature="hot"/, /controls="huge"/, /path="1,2,3"/]) {
      assert.ok(reasons.some((r) => pattern.test(r)), `an error event says ${pattern} (got ${JSON.stringify(reasons)})`);
    }
    const r = await page.evaluate(() => {
      const [bad, far, src] = document.querySelectorAll('motion-playground');
      return {
        badView: bad.view,
        badControls: [...bad.shadowRoot.querySelector('.app').classList].filter((c) => c.startsWith('controls-')),
        far: far.playground.current(),
        farError: far.playground.lastError(),
        src: src.playground.current()?.frames,
        srcName: src.shadowRoot.getElementById('clip-name').textContent,
      };
    });
    assert.equal(r.badView.mode, 'walk', 'a bad mode keeps the default first view (Random walk)');
    assert.deepEqual(r.badControls, ['controls-full']);
    assert.equal(r.far, null);
    assert.match(r.farError, /^src: .*example\.com.*(origin|allowed)/i);
    assert.ok((await events(page, 'far', 'error')).some((e) => /origin|allowed/i.test(e.detail.reason)));
    assert.equal(r.src, 450);
    assert.equal(r.srcName, 'walk');
    // The refused element still works: it plays a clip given through its API.
    const works = await page.evaluate(async () => {
      const far = document.getElementById('far');
      const m = await far.playground.importMotion((await (await fetch('clips/walk.bvh')).text()), 'bvh');
      far.playground.show(m, 'walk');
      return far.playground.current().frames;
    });
    assert.equal(works, 450);
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('a link reproduces the view and the same motion; Share copies it and Embed shows the snippet', async () => {
    const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, deviceScaleFactor: 1 });
    await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: new URL(url).origin });
    const first = await context.newPage();
    await first.addInitScript(installUiLookups);
    await first.goto(`${url}?mode=path&model=vae-lstm&seed=4&path=${encodeURIComponent(PATH)}`, { waitUntil: 'load' });
    await first.waitForFunction(() => window.playground !== undefined);
    await waitUntil(first, () => window.playground.current()?.frames > 0 && $ui('path-progress')?.hidden !== false, null, { timeout: 90_000, message: 'the linked path is walked' });
    const shown = await first.evaluate(async () => {
      const el = document.querySelector('motion-playground');
      // The address bar follows the view on a timer: wait for it (10 s at most), not for a fixed time.
      for (const t0 = performance.now(); new URL(el.shareLink).search !== location.search && performance.now() - t0 < 10_000; ) {
        await new Promise((resolve) => setTimeout(resolve, 20));
      }
      const m = window.playground.current();
      return { view: el.view, link: el.shareLink, address: location.href, frames: m.frames, sample: Array.from(m.positions.filter((_, i) => i % 997 === 0)) };
    });
    assert.deepEqual(shown.view, { mode: 'path', model: 'vae-lstm', seed: 4, path: [[0, 0], [3, 1.5], [6, 0], [9, -1.5]] });
    assert.equal(new URL(shown.address).search, new URL(shown.link).search, 'the address bar holds the link');

    // Share copies the link; Embed shows a snippet for this view, as text.
    await first.locator('#share-btn').click();
    await waitUntil(first, () => $ui('share-dialog').open && $uiFrame().dataset.copied, null, { message: 'Share copies the link' });
    assert.equal(await first.evaluate(() => navigator.clipboard.readText()), shown.link);
    await first.locator('#share-close').click();
    await first.locator('#embed-btn').click();
    const snippet = await first.evaluate(() => $ui('share-text').value);
    assert.match(snippet, /<script type="module" src="[^"]*motion-playground\.js"><\/script>/);
    assert.match(snippet, /<motion-playground mode="path" model="vae-lstm" seed="4" path="0,0;3,1\.5;6,0;9,-1\.5"/);

    // Opening the link elsewhere gives the same view and the same motion.
    const second = await context.newPage();
    await second.addInitScript(installUiLookups);
    await second.goto(shown.link, { waitUntil: 'load' });
    await second.waitForFunction(() => window.playground !== undefined);
    await waitUntil(second, () => window.playground.current()?.frames > 0 && $ui('path-progress')?.hidden !== false, null, { timeout: 90_000, message: 'the link is walked again' });
    const again = await second.evaluate(() => {
      const m = window.playground.current();
      return { view: document.querySelector('motion-playground').view, frames: m.frames, sample: Array.from(m.positions.filter((_, i) => i % 997 === 0)) };
    });
    assert.deepEqual(again.view, shown.view);
    assert.equal(again.frames, shown.frames);
    assert.deepEqual(again.sample, shown.sample, 'the same seed gives the same motion');
    await context.close();
  });

  test('bad link parameters are refused with a message and the defaults kept', async () => {
    const context = await browser.newContext({ viewport: { width: 1280, height: 800 } });
    const page = await context.newPage();
    await page.addInitScript(installUiLookups);
    await page.goto(`${url}?mode=fly&seed=abc&temperature=9`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.playground !== undefined);
    await page.evaluate(() => window.playground.ready);
    const r = await waitUntil(page, () => {
      const toasts = [...document.querySelector('motion-playground').shadowRoot.querySelectorAll('.toast')].map((t) => t.textContent);
      return toasts.length >= 3 && { toasts, mode: document.querySelector('motion-playground').view.mode };
    }, null, { message: 'each bad parameter gets a message' });
    assert.ok(r.toasts.some((t) => /Link: mode="fly"/.test(t)), JSON.stringify(r.toasts));
    assert.ok(r.toasts.some((t) => /Link: seed="abc"/.test(t)));
    assert.ok(r.toasts.some((t) => /Link: temperature="9"/.test(t)));
    assert.equal(r.mode, 'walk', 'the default first view');
    await context.close();
  });

  test('a file name or joint name holding markup is shown as text, never as HTML', async () => {
    pages.set('markup.html', sitePage(`<motion-playground id="m" src="clips/markup.bvh"></motion-playground>`));
    const { context, page, problems } = await open('markup.html');
    await waitForEvent(page, 'm', 'motion', 'the clip with markup in its names is shown');
    const r = await page.evaluate(async () => {
      const el = document.querySelector('motion-playground');
      el.playground.show(el.playground.current(), '<img src=x onerror="window.pwned=1">.bvh');
      await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
      const root = el.shadowRoot;
      root.getElementById('cleanup-toggle').click();
      await new Promise((resolve) => setTimeout(resolve, 100));
      return {
        name: root.getElementById('clip-name').textContent,
        joints: el.playground.current().joints,
        options: [...root.querySelectorAll('option')].map((o) => o.textContent).filter((t) => t.includes('<')),
        injected: root.querySelectorAll('img:not(.poster), x-inj, script').length + document.querySelectorAll('x-inj').length,
        pwned: window.pwned ?? null,
      };
    });
    assert.equal(r.name, '<img src=x onerror="window.pwned=1">.bvh');
    assert.ok(r.joints.includes('<x-inj>Hips</x-inj>'), JSON.stringify(r.joints));
    assert.equal(r.injected, 0, 'no element was made from a name');
    assert.equal(r.pwned, null);
    assert.deepEqual(problems, []);
    await context.close();
  });
});

/** A two-joint BVH whose root is named with markup. */
const MARKUP_BVH = `HIERARCHY
ROOT <x-inj>Hips</x-inj>
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0
1 90 0 0 0 0 0 0 0
2 90 0 0 0 0 0 0 0
`;
