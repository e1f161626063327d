// The <motion-playground> element and the page against odd input from outside (issue 43): signal-like objects
// that are not quite AbortSignals (#4), very long file names, URLs, attributes and API strings (#5: every message
// shown or fired is at most 300 characters), a `%` in a `src` file name (#6), a `src` that never answers (#7: an
// `error` after 30 s), a `src` redirected to an origin not allowed (#9), and the `loading`, `controls` and
// `poster` attributes' errors (#12: each fires once; an unknown `loading` is refused). Local servers on
// 127.0.0.1 and localhost stand in for other sites (two origins).
import assert from 'node:assert/strict';
import http from 'node:http';
import { after, before, describe, test } from 'node:test';
import { chromium } from 'playwright-core';
import { CHROMIUM, CHROMIUM_ARGS, corpusText, freePort, installUiLookups, openPlayground, startServer, waitUntil, sitePage } from './harness.mjs';

const MAX_MESSAGE = 300;
const WALK = corpusText('cmu/bvh/07_04.bvh.gz');
const LONG = 100_000;

/** A plain HTTP server on `host` (all interfaces when left out) answering with `handler`; `close` ends it and its open requests. */
async function listen(handler, host) {
  const server = http.createServer(handler);
  const port = await freePort();
  await new Promise((resolve) => server.listen(port, host, resolve));
  return { port, close: () => new Promise((resolve) => { server.closeAllConnections(); server.close(resolve); }) };
}

describe('the element and the page against odd input', { timeout: 300_000 }, () => {
  let server, url, browser, far, other;
  const pages = new Map();

  before(async () => {
    ({ server, url } = await startServer());
    // Pages fulfilled by page.route have no address, so they count as public: Chromium's Local Network Access would
    // refuse their fetches to the loopback servers below (the other sites), which a real site's page makes freely.
    browser = await chromium.launch({ executablePath: CHROMIUM, args: [...CHROMIUM_ARGS, '--disable-features=LocalNetworkAccessChecks'] });
    // Another site, allowed by the elements that name it: a clip, a request that never answers, redirects.
    other = await listen((req, res) => {
      res.setHeader('Access-Control-Allow-Origin', '*');
      if (req.url === '/walk.bvh') return res.end(WALK);
      res.statusCode = 404;
      res.end('not here');
    }); // reached as localhost: another origin than 127.0.0.1
    far = await listen((req, res) => {
      res.setHeader('Access-Control-Allow-Origin', '*');
      if (req.url === '/walk.bvh') return res.end(WALK);
      if (req.url === '/hang.bvh') return; // never answers
      if (req.url === '/to-other.bvh') {
        res.writeHead(302, { Location: `http://localhost:${other.port}/walk.bvh` });
        return res.end();
      }
      if (req.url === '/to-self.bvh') {
        res.writeHead(302, { Location: '/walk.bvh' });
        return res.end();
      }
      res.statusCode = 404;
      res.end('not here');
    }, '127.0.0.1');
  });
  after(async () => {
    await browser?.close();
    await server?.close();
    await far?.close();
    await other?.close();
  });

  /** Opens `name` (one of `pages`) in a fresh context; /site/clips/*.bvh serve a walk, /nope/* is missing. */
  async function open(name, hash = '') {
    const context = await browser.newContext({ viewport: { width: 1000, height: 800 }, deviceScaleFactor: 1 });
    const page = await context.newPage();
    const problems = [];
    page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
    page.on('pageerror', (e) => problems.push(e.message));
    await page.addInitScript(installUiLookups);
    await page.route(`${url}site/**`, (route) => {
      const file = new URL(route.request().url()).pathname.replace(/^\/site\//, '');
      if (pages.has(file)) return route.fulfill({ status: 200, contentType: 'text/html', body: pages.get(file) });
      if (file.startsWith('clips/') && file.endsWith('.bvh')) return route.fulfill({ status: 200, contentType: 'text/plain', body: WALK });
      return route.fulfill({ status: 404, body: 'not here' });
    });
    await page.route(`${url}nope/**`, (route) => route.fulfill({ status: 404, body: 'not here' }));
    await page.goto(`${url}site/${name}${hash}`, { waitUntil: 'load' });
    return { context, page, problems };
  }

  const events = (page, id, type) => page.evaluate(({ id, type }) => window.events.filter((e) => (!id || e.id === id) && (!type || e.type === type)), { id, type });
  const waitForEvent = (page, id, type, message, timeout = 90_000) =>
    waitUntil(page, ({ id, type }) => window.events.some((e) => e.id === id && e.type === type), { id, type }, { timeout, message });

  // #4: a signal-like object the API cannot use is refused, and one whose methods fail never leaves a call hanging.
  test('generate settles whatever signal-like object it is given', async () => {
    const { context, page, problems } = await openPlayground(browser, url);
    const r = await page.evaluate(async () => {
      const settled = (p) => Promise.race([
        p.then(() => 'resolved', (e) => `rejected: ${e.message}`),
        new Promise((resolve) => setTimeout(() => resolve('never settled'), 20_000)),
      ]);
      const generate = (signal) => settled(window.playground.generate({ model: 'generator', frames: 5, seed: 1, signal }));
      return {
        noRemove: await generate({ aborted: false, addEventListener() {} }),
        throwingAdd: await generate({ aborted: false, addEventListener() { throw new Error('no listeners here'); }, removeEventListener() {} }),
        throwingRemove: await generate({ aborted: false, addEventListener() {}, removeEventListener() { throw new Error('cannot remove'); } }),
        real: await generate(new AbortController().signal),
        aborted: await generate(AbortSignal.abort()),
      };
    });
    assert.match(r.noRemove, /^rejected: generate: signal must be an AbortSignal/);
    assert.match(r.throwingAdd, /^rejected: generate: signal must be an AbortSignal.*no listeners here/);
    assert.equal(r.throwingRemove, 'resolved');
    assert.equal(r.real, 'resolved');
    assert.equal(r.aborted, 'rejected: generate: cancelled');
    assert.deepEqual(problems.filter((p) => !/request failed/.test(p)), []);
    await context.close();
  });

  // #5: file names, URLs, attributes, link parameters and API strings of 10^5 characters give messages of at most 300.
  test('every message shown or fired stays within 300 characters, whatever the input', async () => {
    const long = (c) => c.repeat(LONG);
    // The page: files dropped with long names, the API's methods with long strings.
    const { context, page } = await openPlayground(browser, url);
    const page1 = await page.evaluate(async (LONG) => {
      const el = document.querySelector('motion-playground');
      const seen = { toasts: [], errors: [], lastErrors: [] };
      el.addEventListener('error', (e) => seen.errors.push(e.detail.reason));
      new MutationObserver(() => {
        for (const t of el.shadowRoot.querySelectorAll('.toast-text')) seen.toasts.push(t.textContent);
      }).observe(el.shadowRoot, { subtree: true, childList: true });
      const note = () => seen.lastErrors.push(window.playground.lastError() ?? '');
      const drop = async (files) => {
        const dt = new DataTransfer();
        for (const f of files) dt.items.add(new File([f.text], f.name));
        const target = $uiOne('.viewer-canvas');
        for (const type of ['dragenter', 'dragover', 'drop']) target.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true }));
        await new Promise((resolve) => setTimeout(resolve, 1500));
        note();
      };
      const name = 'n'.repeat(LONG);
      await drop([{ name: `${name}.bvh`, text: 'not a motion' }]);
      await drop([{ name: `${name}.xyz`, text: 'what' }]);
      await drop([{ name: `${name}.amc`, text: '1\nroot 0 0 0 0 0 0\n' }]);
      const tiny = 'HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n';
      await drop([{ name: `${name}.bvh`, text: tiny }, { name: `${name}.txt`, text: 'x' }]);
      const text = 'x'.repeat(LONG);
      const calls = [
        () => window.playground.generate({ model: text, frames: 5 }),
        () => window.playground.generate({ model: 'generator', frames: 5, [text]: 1 }),
        () => window.playground.importMotion(text, 'bvh'),
        () => window.playground.importMotion(`HIERARCHY\nROOT ${text}\n`, 'bvh'),
        () => window.playground.importMotion('HIERARCHY', text),
        () => window.playground.show({ joints: [text] }, text),
        () => window.playground.setView({ framing: text }),
        () => window.playground.followPath({ points: text }),
        () => window.playground.simulateControl({ seconds: 1, schedule: [{ t: 0, speed: 1, heading: 0 }], gait: text }),
        () => window.playground.denoise(window.playground.current(), { method: text }),
        () => window.playground.addNoise(window.playground.current(), { [text]: 1 }),
        () => window.playground.exportBVH(window.playground.current(), { [text]: 1 }),
      ];
      const thrown = [];
      for (const call of calls) {
        try {
          await call();
          thrown.push('(no error)');
        } catch (e) {
          thrown.push(e.message);
        }
        note();
      }
      for (const t of el.shadowRoot.querySelectorAll('.toast-text')) seen.toasts.push(t.textContent);
      return { ...seen, thrown };
    }, LONG);
    await context.close();

    // The element: every attribute it reads, 10^5 characters long, then `src` set to a long missing URL; the link's parameters.
    const attrs = ['mode', 'model', 'dance-style', 'seed', 'temperature', 'refine', 'path', 'controls', 'loading', 'allowed-origins'].map((a) => `${a}="${long(a[0])}"`).join(' ');
    pages.set('long.html', sitePage(`
      <motion-playground id="attrs" ${attrs} poster="javascript:${long('p')}" src="/nope/${long('a')}.bvh"></motion-playground>
      <motion-playground id="link" link></motion-playground>`));
    const site = await open('long.html', `#mode=${long('m')}&seed=${long('9')}&path=${long('1,')}`);
    await waitForEvent(site.page, 'attrs', 'load', 'the element with long attributes loads');
    await waitForEvent(site.page, 'link', 'load', 'the element with a long link loads');
    await site.page.evaluate((LONG) => { document.getElementById('attrs').src = `/nope/${'b'.repeat(LONG)}.bvh`; }, LONG);
    await waitUntil(site.page, () => window.events.filter((e) => e.id === 'attrs' && e.type === 'error' && /^src: /.test(e.detail.reason)).length >= 2, null, { message: 'both src fail' });
    const fired = (await events(site.page, null, 'error')).map((e) => e.detail.reason);
    const shown = await site.page.evaluate(() => [...document.querySelectorAll('motion-playground')].flatMap((el) => [
      ...[...el.shadowRoot.querySelectorAll('.toast-text')].map((t) => t.textContent),
      el.playground.lastError() ?? '',
    ]));
    await site.context.close();

    const everything = { ...page1, fired, shown };
    for (const [what, messages] of Object.entries(everything)) {
      const over = messages.filter((m) => m.length > MAX_MESSAGE).map((m) => `${m.length}: ${m.slice(0, 80)}…`);
      assert.deepEqual(over, [], `${what}: every message is at most ${MAX_MESSAGE} characters`);
    }
    // Each path did give a message (the test reaches the sinks it means to).
    assert.ok(page1.toasts.some((t) => /^Could not import n+/.test(t) || /nnnn/.test(t)), `a banner names the dropped file: ${JSON.stringify(page1.toasts.map((t) => t.slice(0, 60)))}`);
    assert.ok(page1.thrown.filter((m) => m !== '(no error)').length >= 10, JSON.stringify(page1.thrown.map((m) => m.slice(0, 60))));
    for (const pattern of [/^src: .*HTTP 404/, /^attribute mode=/, /^attribute seed=/, /^attribute path=/, /controls=/, /poster/]) {
      assert.ok(fired.some((r) => pattern.test(r)), `an error event matches ${pattern}: ${JSON.stringify(fired.map((r) => r.slice(0, 60)))}`);
    }
    assert.ok(fired.filter((r) => /^src: /.test(r)).every((r) => r.includes('…')), 'a cut URL shows where it was cut');
    assert.ok(shown.some((t) => /^Link: /.test(t)), 'the long link parameters give messages');
  });

  // #6: a `%` that is no escape in a `src` file name: the clip loads, named by its file.
  test('a src file name with a stray % loads and is named by its file', async () => {
    pages.set('percent.html', sitePage(`
      <motion-playground id="stray" src="clips/a%zz.bvh"></motion-playground>
      <motion-playground id="escaped" src="clips/caf%C3%A9.bvh?v=2#x"></motion-playground>`));
    const { context, page, problems } = await open('percent.html');
    for (const id of ['stray', 'escaped']) await waitForEvent(page, id, 'load', `#${id} loads`);
    const r = await page.evaluate(() => Object.fromEntries([...document.querySelectorAll('motion-playground')].map((el) => [el.id, {
      frames: el.playground.current()?.frames ?? null,
      name: el.shadowRoot.getElementById('clip-name').textContent,
      error: el.playground.lastError(),
    }])));
    assert.deepEqual(r.stray, { frames: 450, name: 'a%zz', error: null });
    assert.deepEqual(r.escaped, { frames: 450, name: 'café', error: null });
    assert.deepEqual(await events(page, null, 'error'), []);
    assert.deepEqual(problems, []);
    await context.close();
  });

  // #7: a `src` that never answers: after 30 s an `error`, and the element goes on.
  test('a src that never answers fails after 30 s with an error event', async () => {
    const origin = `http://127.0.0.1:${far.port}`;
    pages.set('hang.html', sitePage(`<motion-playground id="hang" src="${origin}/hang.bvh" allowed-origins="${origin}"></motion-playground>`));
    const { context, page, problems } = await open('hang.html');
    const started = Date.now();
    await waitUntil(page, () => window.events.some((e) => e.type === 'error'), null, { timeout: 60_000, message: 'the hanging src fires error' });
    const waited = Date.now() - started;
    const [error] = await events(page, 'hang', 'error');
    assert.match(error.detail.reason, /^src: .*hang\.bvh.* no answer within 30 s/);
    assert.ok(waited > 25_000, `it waited the 30 s (${waited} ms)`);
    await waitForEvent(page, 'hang', 'load', 'the element loads after the failed src');
    assert.equal(await page.evaluate(() => document.getElementById('hang').playground.current()), null);
    assert.deepEqual(problems, []);
    await context.close();
  });

  // #9: `allowed-origins` holds for where a redirect ends, not only for the URL asked for.
  test('a src redirected to an origin that is not allowed is refused, naming that origin', async () => {
    const origin = `http://127.0.0.1:${far.port}`;
    pages.set('redirect.html', sitePage(`
      <motion-playground id="away" src="${origin}/to-other.bvh" allowed-origins="${origin}"></motion-playground>
      <motion-playground id="home" src="${origin}/to-self.bvh" allowed-origins="${origin}"></motion-playground>`));
    const { context, page, problems } = await open('redirect.html');
    for (const id of ['away', 'home']) await waitForEvent(page, id, 'load', `#${id} loads`);
    const r = await page.evaluate(() => Object.fromEntries([...document.querySelectorAll('motion-playground')].map((el) => [el.id, el.playground.current()?.frames ?? null])));
    assert.deepEqual(r, { away: null, home: 450 }, 'the clip redirected away is not shown; the one redirected within the allowed origin is');
    const reasons = (await events(page, 'away', 'error')).map((e) => e.detail.reason);
    assert.equal(reasons.length, 1, JSON.stringify(reasons));
    assert.match(reasons[0], new RegExp(`^src: .*redirected to http://localhost:${other.port}\\b.*not this page's origin or in allowed-origins`));
    assert.deepEqual(await events(page, 'home', 'error'), []);
    assert.deepEqual(problems, []);
    await context.close();
  });

  // #12: an unknown `loading` is refused with the allowed values; each bad `controls`, `poster` and `loading` fires one error.
  test('bad loading, controls and poster attributes each fire one error, and the defaults are kept', async () => {
    pages.set('attributes.html', sitePage(`<motion-playground id="odd" controls="huge" poster="javascript:alert(1)" loading="never"></motion-playground>
      <motion-playground id="bad-url" poster="http://[oops"></motion-playground>`));
    const { context, page, problems } = await open('attributes.html');
    for (const id of ['odd', 'bad-url']) await waitForEvent(page, id, 'load', `#${id} starts at once (loading keeps its default, eager)`);
    const reasons = async (id) => (await events(page, id, 'error')).map((e) => e.detail.reason);
    assert.deepEqual((await reasons('odd')).sort(), [
      'attribute controls="huge": must be one of full, minimal, none',
      'attribute loading="never": must be one of eager, lazy',
      'attribute poster: javascript: URLs are not allowed',
    ]);
    assert.deepEqual(await reasons('bad-url'), ['attribute poster="http://[oops": not a URL']);
    const controls = await page.evaluate(() => [...document.getElementById('odd').shadowRoot.querySelector('.app').classList].filter((c) => c.startsWith('controls-')));
    assert.deepEqual(controls, ['controls-full']);
    // Changed later: once per change.
    await page.evaluate(() => {
      const el = document.getElementById('odd');
      el.controls = 'big';
      el.loading = 'soon';
      el.poster = 'ftp://x/y.png';
      el.controls = 'minimal';
      el.controls = 'big';
    });
    const later = (await reasons('odd')).slice(3);
    assert.deepEqual(later, [
      'attribute controls="big": must be one of full, minimal, none',
      'attribute loading="soon": must be one of eager, lazy',
      'attribute poster: ftp: URLs are not allowed',
      'attribute controls="big": must be one of full, minimal, none',
    ]);
    assert.deepEqual(problems, []);
    await context.close();
  });
});
