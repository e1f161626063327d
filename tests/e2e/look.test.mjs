// The look switch (issue 40): the project's mannequin is the default look; Skeleton / Character / Both from the
// buttons, the L key, `setView({ look })`, the `look` link parameter and the element's `look` attribute; the
// mannequin is really drawn (far more figure pixels than the stick figure); a skeleton that is not a humanoid
// keeps the stick figure without an error.
import assert from 'node:assert/strict';
import { after, before, describe, test } from 'node:test';
import { installUiLookups, launchBrowser, nextFrames, openPlayground, sitePage, startServer, waitUntil } from './harness.mjs';

describe('the look: skeleton, character or both', { timeout: 240_000 }, () => {
  let server, url, browser;
  before(async () => {
    ({ server, url } = await startServer());
    browser = await launchBrowser();
  });
  after(async () => {
    await browser?.close();
    await server?.close();
  });

  const stats = (page) => page.evaluate(() => window.playground.stats());
  const pressed = (page) => page.evaluate(() => [...$uiAll('[data-look]')].filter((b) => b.getAttribute('aria-pressed') === 'true').map((b) => b.dataset.look));
  /** Waits for Random walk's first frames. */
  const walking = (page) => waitUntil(page, () => (window.playground.current()?.frames ?? 0) > 20, undefined, { timeout: 120_000, message: 'Random walk never showed frames' });

  /** Light pixels of the canvas (the figure's; the ground, grid and fog are dark with trail and footprints off). */
  async function figurePixels(page) {
    await nextFrames(page, 3);
    const png = await page.locator('motion-playground').screenshot({ type: 'png' });
    return page.evaluate(async (b64) => {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      const bmp = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
      const g = new OffscreenCanvas(bmp.width, bmp.height).getContext('2d');
      g.drawImage(bmp, 0, 0);
      // Only the middle of the stage: the panels and buttons are outside it.
      const x0 = Math.round(bmp.width * 0.3), y0 = Math.round(bmp.height * 0.12), w = Math.round(bmp.width * 0.4), h = Math.round(bmp.height * 0.55);
      const d = g.getImageData(x0, y0, w, h).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) if (0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2] > 110) n++;
      return n;
    }, png.toString('base64'));
  }

  test('Random walk opens on the character; the buttons, L, and setView switch it, and the link follows', async () => {
    const { context, page, problems } = await openPlayground(browser, `${url}?mode=walk&resolution=full`);
    try {
      await walking(page);
      let s = await stats(page);
      assert.equal(s.look, 'character', 'the character is the default look');
      assert.ok(s.characterVertices > 1500, `a smooth character is drawn (${s.characterVertices} vertices)`);
      assert.deepEqual(await pressed(page), ['character']);
      assert.equal(new URL(page.url()).searchParams.get('look'), null, 'the default look stays out of the link');

      // Same frame, same camera: the character covers far more of the screen than the stick figure.
      await page.evaluate(() => {
        window.playground.pause();
        window.playground.setView({ trail: false, footprints: false, follow: true });
      });
      const character = await figurePixels(page);
      await page.evaluate(() => $uiOne('[data-look="skeleton"]').click());
      s = await stats(page);
      assert.equal(s.look, 'skeleton');
      assert.equal(s.characterVertices, 0, 'no character drawn in the skeleton look');
      assert.deepEqual(await pressed(page), ['skeleton']);
      const skeleton = await figurePixels(page);
      assert.ok(character > skeleton * 1.6, `the character covers more than the stick figure (${character} vs ${skeleton} light pixels)`);
      await waitUntil(page, () => new URL(location.href).searchParams.get('look') === 'skeleton', undefined, { message: 'the link never said look=skeleton' });
      assert.equal(await page.evaluate(() => document.querySelector('motion-playground').getAttribute('look')), 'skeleton');

      // The L key cycles: skeleton → character → both.
      await page.locator('canvas.viewer-canvas').click({ position: { x: 20, y: 200 } });
      await page.keyboard.press('l');
      assert.equal((await stats(page)).look, 'character');
      await page.keyboard.press('l');
      assert.equal((await stats(page)).look, 'both');
      assert.deepEqual(await pressed(page), ['both']);
      const both = await figurePixels(page);
      assert.notEqual(both, character, 'both looks different from the character alone');
      await waitUntil(page, () => new URL(location.href).searchParams.get('look') === 'both', undefined, { message: 'the link never said look=both' });

      // Keyboard reachable: a focused button switches with Enter.
      await page.evaluate(() => $uiOne('[data-look="character"]').focus());
      await page.keyboard.press('Enter');
      assert.equal((await stats(page)).look, 'character');

      // The API, and a bad value refused with a short message, the look kept.
      await page.evaluate(() => window.playground.setView({ look: 'skeleton' }));
      assert.equal((await stats(page)).look, 'skeleton');
      assert.deepEqual(await pressed(page), ['skeleton']);
      const bad = await page.evaluate(() => {
        try {
          window.playground.setView({ look: 'wireframe' });
          return null;
        } catch (e) {
          return e.message;
        }
      });
      assert.match(bad, /look must be "skeleton", "character", "both", got "wireframe"/);
      assert.equal((await stats(page)).look, 'skeleton');
      problems.splice(0); // the refused call logs its message
    } finally {
      await context.close();
    }
  });

  test('the look link parameter opens the view in that look; a bad one is reported and the character stays', async () => {
    for (const [query, look] of [['look=both', 'both'], ['look=skeleton', 'skeleton']]) {
      const { context, page, problems } = await openPlayground(browser, `${url}?mode=walk&${query}`);
      try {
        await walking(page);
        assert.equal((await stats(page)).look, look);
        assert.deepEqual(await pressed(page), [look]);
        assert.deepEqual(problems, []);
      } finally {
        await context.close();
      }
    }
    const { context, page } = await openPlayground(browser, `${url}?mode=walk&look=wire`);
    try {
      await walking(page);
      assert.equal((await stats(page)).look, 'character');
      const error = await page.evaluate(() => window.playground.lastError());
      assert.match(error, /look="wire": must be one of skeleton, character, both/);
    } finally {
      await context.close();
    }
  });

  test('a skeleton that is not a humanoid keeps the stick figure, with no error', async () => {
    const { context, page, problems } = await openPlayground(browser, url);
    try {
      const s = await page.evaluate(() => {
        const frames = 30, positions = new Float32Array(frames * 3 * 3);
        for (let f = 0; f < frames; f++) for (let j = 0; j < 3; j++) positions.set([f * 0.02, 0.3 + j * 0.4, 0], (f * 3 + j) * 3);
        window.playground.show({ fps: 30, frames, joints: ['base', 'middle', 'tip'], parents: [-1, 0, 1], positions }, 'snake');
        return window.playground.stats();
      });
      assert.equal(s.look, 'character');
      assert.equal(s.characterVertices, 0, 'no character for a snake');
      assert.equal(await page.evaluate(() => window.playground.lastError()), null);
      await nextFrames(page, 3);
      assert.deepEqual(problems, []);
    } finally {
      await context.close();
    }
  });

  test('the element: the look attribute, changed and removed, and a bad one fires error', async () => {
    const context = await browser.newContext({ viewport: { width: 900, height: 700 }, deviceScaleFactor: 1 });
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (e) => problems.push(e.message));
    await page.addInitScript(installUiLookups);
    const body = sitePage(`<motion-playground id="a" mode="walk" look="skeleton" autoplay></motion-playground>`);
    await page.route(`${url}site/**`, (route) => route.fulfill({ status: 200, contentType: 'text/html', body }));
    try {
      await page.goto(`${url}site/look.html`, { waitUntil: 'load' });
      await waitUntil(page, () => window.events.some((e) => e.type === 'load'), undefined, { timeout: 90_000, message: 'the element never loaded' });
      const look = () => page.evaluate(() => document.getElementById('a').playground.stats().look);
      assert.equal(await look(), 'skeleton');
      await page.evaluate(() => document.getElementById('a').setAttribute('look', 'both'));
      assert.equal(await look(), 'both');
      await page.evaluate(() => document.getElementById('a').removeAttribute('look'));
      assert.equal(await look(), 'character', 'no attribute: the default look');
      await page.evaluate(() => document.getElementById('a').setAttribute('look', 'boxes'));
      assert.equal(await look(), 'character', 'a bad value changes nothing');
      const errors = await page.evaluate(() => window.events.filter((e) => e.type === 'error').map((e) => e.detail.reason));
      assert.deepEqual(errors, ['attribute look="boxes": must be one of skeleton, character, both']);
      assert.deepEqual(problems, []);
    } finally {
      await context.close();
    }
  });
});
