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
import { CHROMIUM, CHROMIUM_ARGS, corpusText, freePort, installUiLookups, openPlayground, startServer, waitUntil } from './harness.mjs';

const MAX_MESSAGE = 300;
const WALK = corpusText('cmu/bvh/07_04.bvh.gz');
const LONG = 100_000;

/** A page of the site holding `body` (as in element.test.mjs): every event of every element is kept in window.events. */
function sitePage(body) {
  return `<!doctype html><html><head><meta charset="utf-8"><title>robust element test</title>
<script type="module" src="/@vite/env"></script>
<script type="module" src="/motion-playground.ts"></script>
<style>body { margin: 0; } motion-playground { width: 480px; height: 320px; display: block; }</style></head>
<body>${body}
<script>
  window.events = [];
  for (const el of document.querySelectorAll('motion-playground')) {
    for (const type of ['load', 'error', 'motion']) {
      el.addEventListener(type, (e) => window.events.push({ id: el.id, type, detail: e.detail ?? null }));
    }
  }
</script></body></html>`;
}

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
});
