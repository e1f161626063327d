// End-to-end tests of the refiner in the page: playground.generate({ refine: true }), refiner parity in the
// browser against the Python fixture, foot skating raw vs refined + foot lock, and Random walk's refine
// toggle, side-by-side view and skating readout. Run with `node --test tests/e2e/refiner.test.mjs`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { describe, test } from 'node:test';
import { openPlayground, ROOT, usePlayground, waitUntil } from './harness.mjs';

const GENERATOR = JSON.parse(readFileSync(path.join(ROOT, 'public', 'models', 'generator.json'), 'utf8'));
const J = GENERATOR.skeleton.joints.length;
const REFERENCE = JSON.parse(readFileSync(path.join(ROOT, 'tests', 'fixtures', 'refiner_reference.json'), 'utf8'));

/**
 * In-page: generate and return a JSON-friendly copy, with its foot skating (the app's
 * web/motion/footSkating.ts) and whether current() is what it was before (`shownUnchanged`).
 */
function generate(page, options) {
  return page.evaluate(async (o) => {
    const before = window.playground.current();
    const m = await window.playground.generate(o);
    const { footSkating, lowFootSliding } = await import('/motion/footSkating.ts');
    return {
      shownUnchanged: window.playground.current() === before,
      skating: footSkating(m),
      sliding: lowFootSliding(m),
      fps: m.fps,
      frames: m.frames,
      joints: m.joints,
      positionsType: Object.prototype.toString.call(m.positions),
      contactsType: Object.prototype.toString.call(m.contacts),
      positions: Array.from(m.positions),
      contacts: Array.from(m.contacts),
    };
  }, options);
}

const worstScaled = (a, b) => a.reduce((w, v, i) => Math.max(w, Math.abs(v - b[i]) / Math.max(1, Math.abs(b[i]))), 0);

describe('refiner in the page', { timeout: 300_000 }, () => {
  const suite = usePlayground();

  test('generate with refine: shape, contacts, finite, deterministic, not the raw motion', async () => {
    const m = await generate(suite.page, { model: 'generator', frames: 300, seed: 4, refine: true });
    assert.equal(m.fps, 30);
    assert.equal(m.frames, 300);
    assert.deepEqual(m.joints, GENERATOR.skeleton.joints);
    assert.equal(m.positionsType, '[object Float32Array]');
    assert.equal(m.positions.length, 300 * J * 3);
    assert.ok(m.positions.every(Number.isFinite), 'no NaN or infinite positions');
    assert.equal(m.contactsType, '[object Uint8Array]');
    assert.equal(m.contacts.length, 600);
    assert.ok(m.contacts.every((c) => c === 0 || c === 1));
    for (const foot of [0, 1]) {
      const planted = m.contacts.filter((c, i) => i % 2 === foot && c === 1).length;
      assert.ok(planted > 20 && planted < 290, `foot ${foot} is planted some of the time (${planted} of 300 frames)`);
    }
    const hips = GENERATOR.skeleton.joints.indexOf('Hips');
    const travel = Math.hypot(m.positions[(299 * J + hips) * 3] - m.positions[hips * 3], m.positions[(299 * J + hips) * 3 + 2] - m.positions[hips * 3 + 2]);
    assert.ok(travel > 1, `the refined character walks (root travels ${travel.toFixed(2)} m)`);

    const again = await generate(suite.page, { model: 'generator', frames: 300, seed: 4, refine: true });
    assert.deepEqual(again.positions, m.positions, 'the same seed gives the same refined motion');
    assert.deepEqual(again.contacts, m.contacts);
    const raw = await generate(suite.page, { model: 'generator', frames: 300, seed: 4, refine: false });
    assert.notDeepEqual(raw.positions, m.positions, 'refine: true is not the raw motion');
    // The same samples: both start from the same seed state at the origin, facing the same way.
    assert.ok(Math.hypot(raw.positions[0] - m.positions[0], raw.positions[2] - m.positions[2]) < 0.05);
    const other = await generate(suite.page, { model: 'generator', frames: 300, seed: 5, refine: true });
    assert.notDeepEqual(other.positions, m.positions, 'another seed gives another refined motion');
    assert.ok([m, again, raw, other].every((g) => g.shownUnchanged), 'generate does not show the motion');
  });

  test('refined + foot lock skates far less than the raw motion (same seeds)', async () => {
    const rows = [];
    for (const seed of [0, 1, 2]) {
      const raw = await generate(suite.page, { model: 'generator', frames: 900, seed });
      const refined = await generate(suite.page, { model: 'generator', frames: 900, seed, refine: true });
      rows.push({ seed, raw: raw.skating, refined: refined.skating, rawSliding: raw.sliding, refinedSliding: refined.sliding });
    }
    const mean = (k) => rows.reduce((a, r) => a + r[k], 0) / rows.length;
    console.log(`# foot skating (m/s), 900 frames, τ 0.5: ${rows.map((r) => `seed ${r.seed} raw ${r.raw.toFixed(3)} refined ${r.refined.toFixed(3)}`).join('; ')}`);
    assert.ok(mean('raw') > 0.5, `the raw generator skates (${mean('raw').toFixed(3)} m/s)`);
    for (const r of rows) assert.ok(r.refined < 0.5 * r.raw, `seed ${r.seed}: refined ${r.refined.toFixed(3)} vs raw ${r.raw.toFixed(3)} m/s`);
    assert.ok(mean('refined') < 0.25 * mean('raw'), `refined + foot lock ${mean('refined').toFixed(3)} vs raw ${mean('raw').toFixed(3)} m/s`);
    // The independent measure (lowest foot point within 4 cm of the floor; no contacts, so the labels cannot flatter it).
    console.log(`# foot sliding, lowest point (m/s): ${rows.map((r) => `seed ${r.seed} raw ${r.rawSliding.toFixed(3)} refined ${r.refinedSliding.toFixed(3)}`).join('; ')}`);
    for (const r of rows) assert.ok(r.refinedSliding < 0.5 * r.rawSliding, `seed ${r.seed}: sliding refined ${r.refinedSliding.toFixed(3)} vs raw ${r.rawSliding.toFixed(3)} m/s`);
  });

  test('refiner parity in the browser: the fixture calls (3 frames, then 1) within 1e-4, and the end effectors', async () => {
    const results = await suite.page.evaluate(async (ref) => {
      const { GeneratorClient } = await import('/runtime/generator/generatorClient.ts');
      const client = new GeneratorClient({ threads: 1 });
      try {
        await client.init();
        const out = [];
        for (const [k, call] of ref.calls.entries()) {
          const r = await client.refinerParity({ batch: ref.batch, frames: call.frames, ...call.inputs }, k === 0 ? ref.frames_physical : undefined);
          out.push({ outputs: Object.fromEntries(Object.entries(r.outputs).map(([n, v]) => [n, Array.from(v)])), ends: r.ends && Array.from(r.ends) });
        }
        return out;
      } finally {
        client.dispose();
      }
    }, REFERENCE);
    let worst = 0;
    results.forEach((r, k) => {
      for (const name of ['x_refined', 'h_out', 'c_out']) {
        const expected = REFERENCE.calls[k].outputs[name];
        assert.equal(r.outputs[name].length, expected.length, `call ${k} ${name} length`);
        worst = Math.max(worst, worstScaled(r.outputs[name], expected));
      }
    });
    console.log(`# refiner parity in the browser: worst |a−b|/max(1,|b|) = ${worst.toExponential(2)}`);
    assert.ok(worst <= 1e-4, `refiner calls: worst ${worst}`);
    assert.equal(results[0].ends.length, REFERENCE.ends.length);
    assert.ok(worstScaled(results[0].ends, REFERENCE.ends) <= 1e-5, 'root-frame end effectors match the Python side');
  });

  test('bad refine values reject with clear messages and leave the scene as it was', async () => {
    const r = await suite.page.evaluate(async () => {
      const pg = window.playground;
      pg.show(await pg.generate({ model: 'generator', frames: 40, seed: 2 }), 'before');
      const before = pg.current();
      const messages = [];
      for (const refine of ['yes', 1, null]) {
        try {
          await pg.generate({ model: 'generator', frames: 10, seed: 1, refine });
          messages.push('resolved');
        } catch (e) {
          messages.push(e.message);
        }
      }
      const one = await pg.generate({ model: 'generator', frames: 1, seed: 1, refine: true });
      return { messages, unchanged: pg.current() === before, frames: pg.state().frames, one: { frames: one.frames, contacts: one.contacts.length, finite: Array.from(one.positions).every(Number.isFinite) } };
    });
    assert.match(r.messages[0], /^generate: refine must be true or false, got "yes"/);
    assert.match(r.messages[1], /refine must be true or false, got 1/);
    assert.match(r.messages[2], /refine must be true or false, got null/);
    assert.equal(r.unchanged, true, 'current() is unchanged');
    assert.equal(r.frames, 40);
    assert.deepEqual(r.one, { frames: 1, contacts: 2, finite: true });
  });

  test('a refiner that cannot load gives a message, and works once it can', async () => {
    const fresh = await openPlayground(suite.browser, suite.url);
    try {
      await fresh.context.route('**/models/refiner.onnx', (route) => route.fulfill({ status: 404, body: 'not here' }));
      const failed = await fresh.page.evaluate(async () => {
        try {
          await window.playground.generate({ model: 'generator', frames: 30, seed: 1, refine: true });
          return 'resolved';
        } catch (e) {
          return { message: e.message, lastError: window.playground.lastError() };
        }
      });
      assert.match(failed.message, /^generate: .*refiner model .*refiner\.onnx: HTTP 404/);
      assert.equal(failed.lastError, failed.message);
      // The generator itself still works, and the refiner loads once it is there.
      await fresh.context.unroute('**/models/refiner.onnx');
      const ok = await fresh.page.evaluate(async () => {
        const raw = await window.playground.generate({ model: 'generator', frames: 30, seed: 1 });
        const refined = await window.playground.generate({ model: 'generator', frames: 30, seed: 1, refine: true });
        return [raw.frames, refined.frames];
      });
      assert.deepEqual(ok, [30, 30]);
    } finally {
      await fresh.context.close();
    }
  });

  test('Random walk: refine toggle, side-by-side view and the skating readout', async () => {
    const status = () =>
      suite.page.evaluate(() => {
        const s = $ui('walk-status');
        const card = $ui('walk-skating');
        const labels = [...$uiAll('.figure-label')].filter((l) => !l.hidden).map((l) => ({ text: l.textContent, box: l.getBoundingClientRect().toJSON() }));
        return {
          frame: Number(s.dataset.frame),
          text: s.textContent,
          skating: { ...card.dataset },
          card: getComputedStyle(card).display,
          rawLine: !$ui('walk-skating-raw').closest('.skate-line').hidden,
          refinedLine: !$ui('walk-skating-refined').closest('.skate-line').hidden,
          rawText: $ui('walk-skating-raw').textContent,
          refinedText: $ui('walk-skating-refined').textContent,
          labels,
          meta: $ui('clip-meta').textContent,
          sideBySide: $ui('walk-side-by-side').checked,
          refine: $ui('walk-refine').checked,
        };
      });
    const waitFrame = (n, text = '') =>
      waitUntil(
        suite.page,
        ([n, text]) => Number($ui('walk-status').dataset.frame) > n && $ui('walk-status').textContent.includes(text),
        [n, text],
        { timeout: 90_000, message: `the walk passes frame ${n}${text ? ` (${text})` : ''}` },
      );

    // The walk starts raw, one figure.
    await suite.page.click('#mode-walk');
    await suite.page.uncheck('#walk-side-by-side');
    await suite.page.uncheck('#walk-refine');
    await waitFrame(60);
    let s = await status();
    assert.equal(s.card, 'block', 'the skating readout shows in Random walk mode');
    assert.equal(s.skating.shown, 'raw');
    assert.ok(s.rawLine && !s.refinedLine);
    assert.ok(Number(s.skating.raw) > 0.2, `raw skating shown (${s.skating.raw} m/s)`);
    assert.equal(s.rawText, Number(s.skating.raw).toFixed(2));
    assert.doesNotMatch(s.text, /refined/);

    // Refine: the stream restarts refined; one figure, the refined readout.
    await suite.page.check('#walk-refine');
    await waitUntil(suite.page, () => /refined/.test($ui('walk-status').textContent), null, { timeout: 60_000, message: 'the walk restarts refined' });
    await waitFrame(90, 'refined');
    s = await status();
    assert.equal(s.skating.shown, 'refined');
    assert.ok(!s.rawLine && s.refinedLine);
    assert.ok(Number.isFinite(Number(s.skating.refined)) && s.skating.refined !== '', `refined skating shown (${s.skating.refined})`);
    assert.equal(s.skating.raw, '');
    assert.equal(s.labels.length, 0, 'no side-by-side labels yet');
    assert.match(s.meta, /generator \+ refiner/);
    const shown = await suite.page.evaluate(() => {
      const m = window.playground.current();
      return { joints: m.joints.length, contacts: m.contacts.length === m.frames * 2, finite: Array.from(m.positions).every(Number.isFinite) };
    });
    assert.deepEqual(shown, { joints: J, contacts: true, finite: true });

    // Side by side: no restart (the refined stream carries the raw frames), both figures labelled, both numbers.
    // The lowest stream frame shown from here on is watched: a restart would start again from 0.
    const before = s.frame;
    await suite.page.evaluate(() => {
      const el = $ui('walk-status');
      window.lowestWalkFrame = Number(el.dataset.frame);
      new MutationObserver(() => (window.lowestWalkFrame = Math.min(window.lowestWalkFrame, Number(el.dataset.frame)))).observe(el, { attributes: true, attributeFilter: ['data-frame'] });
    });
    await suite.page.check('#walk-side-by-side');
    await waitUntil(
      suite.page,
      () => /side by side/.test($ui('walk-status').textContent) && $uiAll('.figure-label:not([hidden])').length === 2,
      null,
      { timeout: 20_000, message: 'both figures are labelled' },
    );
    // A second of the walk side by side, with both numbers in the readout.
    await waitUntil(
      suite.page,
      (f) => Number($ui('walk-status').dataset.frame) > f + 30 && $ui('walk-skating').dataset.shown === 'both',
      before,
      { timeout: 60_000, message: `the walk goes on side by side from frame ${before}` },
    );
    s = await status();
    const lowest = await suite.page.evaluate(() => window.lowestWalkFrame);
    assert.ok(lowest >= before, `the walk went on without restarting (frame ${before} → ${s.frame}, lowest ${lowest})`);
    assert.equal(s.skating.shown, 'both');
    assert.ok(s.rawLine && s.refinedLine);
    const raw = Number(s.skating.raw), refined = Number(s.skating.refined);
    console.log(`# Random walk side by side, skating readout at frame ${s.frame}: raw ${raw} refined ${refined} m/s`);
    // The raw generator skates (docs/models/refiner.md: about 1.2 m/s); refined + foot lock at most half of
    // that, as generate({ refine: true }) does per seed above.
    assert.ok(raw > 0.3 && refined < 0.5 * raw, `readout: raw ${raw} vs refined ${refined} m/s`);
    assert.deepEqual(s.labels.map((l) => l.text).sort(), ['raw', 'refined + foot lock']);
    const [a, b] = s.labels.map((l) => l.box.x + l.box.width / 2);
    assert.ok(Math.abs(a - b) > 80, `the two figures are drawn apart (labels at ${a.toFixed(0)} and ${b.toFixed(0)} px)`);
    const rawLabel = s.labels.find((l) => l.text === 'raw'), refinedLabel = s.labels.find((l) => l.text !== 'raw');
    assert.ok(rawLabel.box.x < refinedLabel.box.x, 'the raw figure is on the left');

    // Side by side off: one figure again, same stream.
    await suite.page.uncheck('#walk-side-by-side');
    await waitUntil(suite.page, () => $uiAll('.figure-label').length === 0, null, { timeout: 10_000, message: 'the labels go' });
    s = await status();
    assert.equal(s.refine, true);
    assert.equal(s.skating.shown, 'refined');

    // Refine off (turns side by side off too): back to the raw generator.
    await suite.page.check('#walk-side-by-side');
    await waitUntil(suite.page, () => $uiAll('.figure-label').length === 2, null, { timeout: 10_000, message: 'both figures are labelled again' });
    await suite.page.uncheck('#walk-refine');
    assert.equal(await suite.page.evaluate(() => $uiAll('.figure-label').length), 0, 'the raw figure goes at once');
    await waitUntil(
      suite.page,
      () => {
        const s = $ui('walk-status');
        return /τ/.test(s.textContent) && !/refined/.test(s.textContent) && Number(s.dataset.frame) > 30;
      },
      null,
      { timeout: 60_000, message: 'the walk restarts raw' },
    );
    s = await status();
    assert.equal(s.sideBySide, false);
    assert.equal(s.labels.length, 0);
    assert.equal(s.skating.shown, 'raw');

    await suite.page.click('#mode-clip');
    assert.equal(await suite.page.evaluate(() => getComputedStyle($ui('walk-skating')).display), 'none');
  });
});
