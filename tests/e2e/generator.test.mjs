// End-to-end tests of the generator in the page: playground.generate, ONNX parity in the browser, and
// the Random walk mode. Run with `npm run test:e2e`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { before, describe, test } from 'node:test';
import { openPlayground, ROOT, usePlayground, waitUntil } from './harness.mjs';

const CANONICAL = JSON.parse(readFileSync(path.join(ROOT, 'public', 'models', 'generator.json'), 'utf8')).skeleton.joints;
const REFERENCE = JSON.parse(readFileSync(path.join(ROOT, 'tests', 'fixtures', 'generator_reference.json'), 'utf8'));

/** In-page: generate and return a JSON-friendly copy with some derived checks (`shownUnchanged`: current() is what it was before). */
async function generate(page, options) {
  return page.evaluate(async (o) => {
    const before = window.playground.current();
    const m = await window.playground.generate(o);
    const J = m.joints.length;
    return {
      shownUnchanged: window.playground.current() === before,
      fps: m.fps,
      frames: m.frames,
      joints: m.joints,
      parents: m.parents,
      positionsType: Object.prototype.toString.call(m.positions),
      contactsType: Object.prototype.toString.call(m.contacts),
      positions: Array.from(m.positions),
      contacts: Array.from(m.contacts),
      J,
    };
  }, options);
}

describe('generator in the page', { timeout: 240_000 }, () => {
  // The shared page; every test checks the console and page errors of its own steps (usePlayground).
  const suite = usePlayground();
  let url, browser, page;
  before(() => ({ url, browser, page } = suite));

  test('generate: shape, canonical skeleton, contacts, plausible and moving', async () => {
    const m = await generate(page, { model: 'generator', frames: 300, seed: 7 });
    assert.equal(m.fps, 30);
    assert.equal(m.frames, 300);
    assert.deepEqual(m.joints, CANONICAL);
    assert.equal(m.joints.length, 25);
    assert.ok(m.joints.includes('Hips') && m.joints.includes('LeftFoot'));
    assert.equal(m.parents.length, 25);
    assert.equal(m.parents[0], -1);
    assert.equal(m.positionsType, '[object Float32Array]');
    assert.equal(m.positions.length, 300 * 25 * 3);
    assert.ok(m.positions.every(Number.isFinite), 'no NaN or infinite positions');

    assert.equal(m.contactsType, '[object Uint8Array]');
    assert.equal(m.contacts.length, 300 * 2);
    assert.ok(m.contacts.every((c) => c === 0 || c === 1));
    assert.ok(m.contacts.includes(0) && m.contacts.includes(1), 'both contact values appear');
    for (const foot of [0, 1]) {
      const planted = m.contacts.filter((c, i) => i % 2 === foot && c === 1).length;
      assert.ok(planted > 10, `foot ${foot} is planted sometimes (${planted} of 300 frames)`);
    }

    const hips = m.joints.indexOf('Hips');
    let minY = Infinity, maxY = -Infinity;
    for (let f = 0; f < m.frames; f++) {
      const y = m.positions[(f * m.J + hips) * 3 + 1];
      minY = Math.min(minY, y);
      maxY = Math.max(maxY, y);
    }
    assert.ok(minY > 0.6 && maxY < 1.2, `root height within 0.6–1.2 m (got ${minY.toFixed(3)}–${maxY.toFixed(3)})`);
    const o0 = hips * 3, o1 = (299 * m.J + hips) * 3;
    const travel = Math.hypot(m.positions[o1] - m.positions[o0], m.positions[o1 + 2] - m.positions[o0 + 2]);
    assert.ok(travel > 1, `the character moves (root travels ${travel.toFixed(2)} m in 300 frames)`);

    assert.equal(m.shownUnchanged, true, 'generate does not show the motion');
  });

  test('generate is deterministic per seed and differs between seeds', async () => {
    const digest = (seed, temperature) =>
      page.evaluate(
        async ({ seed, temperature }) => {
          const m = await window.playground.generate({ model: 'generator', frames: 120, seed, temperature });
          return Array.from(new Uint8Array(m.positions.buffer, m.positions.byteOffset, m.positions.byteLength));
        },
        { seed, temperature },
      );
    const a = await digest(11, 0.5);
    const b = await digest(11, 0.5);
    const c = await digest(12, 0.5);
    assert.deepEqual(a, b, 'the same seed gives byte-identical positions');
    assert.notDeepEqual(a, c, 'another seed gives another motion');
    // The same seed state (11 and 19 mod 8) with another random stream still differs.
    const d = await digest(19, 0.5);
    assert.notDeepEqual(a, d);
  });

  test('bad generate arguments reject with clear messages and leave the scene unchanged', async () => {
    const results = await page.evaluate(async () => {
      const pg = window.playground;
      const motion = await pg.generate({ model: 'generator', frames: 40, seed: 1 });
      pg.show(motion, 'generated');
      const before = pg.current();
      const cases = [
        { model: 'nope', frames: 10, seed: 1 },
        { model: 'generator', frames: 0, seed: 1 },
        { model: 'generator', frames: 2.5, seed: 1 },
        { model: 'generator', frames: 100001, seed: 1 },
        { model: 'generator', frames: 10, seed: 1, temperature: 3 },
        { model: 'generator', frames: 10, seed: 1, temperature: -0.1 },
        { model: 'generator', frames: 10, seed: 1, refine: 'yes' },
        { model: 'generator', frames: 10, seed: -1 },
        { model: 'generator', frames: 10, seed: 1, colour: 'red' },
        null,
      ];
      const messages = [];
      for (const c of cases) {
        try {
          await pg.generate(c);
          messages.push('resolved');
        } catch (e) {
          messages.push(e.message);
        }
      }
      return { messages, same: pg.current() === before, lastError: pg.lastError(), state: pg.state() };
    });
    const m = results.messages;
    // Every model generate can run is offered: the generator and the dance models.
    assert.match(m[0], /^generate: unknown model "nope" \(available: [^)]*\bgenerator\b[^)]*\)/);
    assert.match(m[0], /\baclstm\b/);
    assert.match(m[1], /^generate: frames must be an integer from 1 to 100000, got 0/);
    assert.match(m[2], /frames must be an integer/);
    assert.match(m[3], /frames must be an integer/);
    assert.match(m[4], /^generate: temperature must be a number from 0 to 2, got 3/);
    assert.match(m[5], /temperature must be a number from 0 to 2/);
    assert.match(m[6], /^generate: refine must be true or false, got "yes"/);
    assert.match(m[7], /seed must be an integer/);
    assert.match(m[8], /unknown option "colour"/);
    assert.match(m[9], /options must be an object/);
    assert.equal(results.same, true, 'current() is unchanged');
    assert.equal(results.lastError, m[9]);
    assert.equal(results.state.frames, 40);
  });

  test('ONNX parity in the browser: one step matches the Python reference within 1e-4', async () => {
    const outputs = await page.evaluate(async () => {
      const { GeneratorClient } = await import('/runtime/generator/generatorClient.ts');
      const client = new GeneratorClient({ threads: 1 });
      try {
        await client.init();
        const r = await client.parity();
        return Object.fromEntries(Object.entries(r.outputs).map(([k, v]) => [k, Array.from(v)]));
      } finally {
        client.dispose();
      }
    });
    const expected = REFERENCE.step.outputs;
    for (const key of ['weights', 'mu', 'sigma', 'h_out', 'c_out']) {
      assert.equal(outputs[key].length, expected[key].length, `${key} length`);
      let worst = 0;
      for (let i = 0; i < expected[key].length; i++) {
        worst = Math.max(worst, Math.abs(outputs[key][i] - expected[key][i]) / Math.max(1, Math.abs(expected[key][i])));
      }
      assert.ok(worst <= 1e-4, `${key}: worst |a−b|/max(1,|b|) = ${worst}`);
    }
  });

  test('Random walk mode streams in the page, and Clip mode restores the clip', async () => {
    // A clip to come back to.
    const before = await page.evaluate(async () => {
      const m = await window.playground.generate({ model: 'generator', frames: 40, seed: 1 });
      window.playground.show(m, 'clip');
      return { frames: window.playground.current().frames };
    });
    await page.click('#mode-walk');
    await waitUntil(page, () => Number($ui('walk-status').dataset.frame) > 5, null, { timeout: 60_000, message: 'the walk starts' });
    const f1 = await page.evaluate(() => Number($ui('walk-status').dataset.frame));
    await waitUntil(page, (f) => Number($ui('walk-status').dataset.frame) > f + 30, f1, { timeout: 60_000, message: `the walk advances 30 frames from frame ${f1}` });
    const s = await page.evaluate(() => ({
      frame: Number($ui('walk-status').dataset.frame),
      state: window.playground.state(),
      current: window.playground.current() && { frames: window.playground.current().frames, joints: window.playground.current().joints.length },
      walk: $uiFrame().classList.contains('walk-mode'),
      loading: $ui('model-status').hidden,
    }));
    assert.ok(s.walk);
    assert.ok(s.frame > f1 + 30, `the walk advances (frame ${f1} → ${s.frame})`);
    assert.equal(s.state.playing, true);
    assert.equal(s.current.joints, 25);
    assert.equal(s.loading, true, 'the loading indicator is hidden once the model is loaded');

    // A new temperature restarts the walk from the start.
    await page.evaluate(() => {
      const t = $ui('walk-temperature');
      t.value = '0.2';
      t.dispatchEvent(new Event('change'));
    });
    await waitUntil(page, () => /τ 0\.20/.test($ui('walk-status').textContent), null, { timeout: 20_000, message: 'the walk restarts at τ 0.20' });

    await page.click('#mode-clip');
    const back = await page.evaluate(() => ({ frames: window.playground.current()?.frames, walk: $uiFrame().classList.contains('walk-mode') }));
    assert.equal(back.walk, false);
    assert.equal(back.frames, before.frames, 'the clip shown before is back');
  });

  test('Random walk in a fresh page: frames grow past 20 s, of which only the last 20 s are kept; no console errors', async () => {
    const fresh = await openPlayground(browser, url);
    try {
      await fresh.page.click('#mode-walk');
      await waitUntil(fresh.page, () => Number($ui('walk-status').dataset.frame) > 0, null, { timeout: 60_000, message: 'the walk starts' });
      const a = await fresh.page.evaluate(() => Number($ui('walk-status').dataset.frame));
      // Frames keep coming: a few seconds of the stream (its rate against the wall clock is `npm run bench`'s random-walk).
      await waitUntil(fresh.page, (a) => Number($ui('walk-status').dataset.frame) > a + 90, a, { timeout: 60_000, message: `the walk advances 90 frames from frame ${a}` });
      // Past 20 s (600 frames at 30 fps) the window keeps the last 600 frames behind the playhead and the
      // few generated ahead (under 120), so it can run for hours. (Dance and Steer share this LiveMode window.)
      await waitUntil(fresh.page, () => Number($ui('walk-status').dataset.frame) > 700, null, { timeout: 120_000, message: 'the walk passes frame 700' });
      const s = await fresh.page.evaluate(() => ({ frames: window.playground.current().frames, playing: window.playground.state().playing }));
      assert.ok(s.frames >= 600 && s.frames <= 600 + 120, `only the last 20 s and what is ready ahead are kept (${s.frames} frames)`);
      assert.equal(s.playing, true);
      assert.deepEqual(fresh.problems, []);
    } finally {
      await fresh.context.close();
    }
  });
});
