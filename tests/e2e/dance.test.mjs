// End-to-end tests of the dance models in the page: playground.generate with the acLSTM models (deterministic and
// sampled), onnxruntime-web parity in the browser, argument errors, and the Dance mode (streaming, the
// pose-change plot, switching style and model, Export BVH). Run with `npm run test:e2e`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { describe, test } from 'node:test';
import { openPlayground, ROOT, startServer, usePlayground, waitUntil } from './harness.mjs';

const INFO = JSON.parse(readFileSync(path.join(ROOT, 'public', 'models', 'aclstm.json'), 'utf8'));
const REFERENCE = JSON.parse(readFileSync(path.join(ROOT, 'tests', 'fixtures', 'aclstm_reference.json'), 'utf8'));
const { joints: JOINTS, parents: PARENTS, offsets: OFFSETS } = INFO.skeleton;
const J = JOINTS.length;
const BONE = JOINTS.map((_, j) => Math.hypot(OFFSETS[3 * j], OFFSETS[3 * j + 1], OFFSETS[3 * j + 2]));
/**
 * The freeze line of the pose-change plot: 20 % of the real dance's median for the style
 * (FREEZE_FRACTION in web/ui/poseChangePlot.ts). docs/models/aclstm.md: acLSTM from the first salsa seed
 * motion ("salsa 10 @5.0s", the Dance mode's default) has its first frozen second at 34 s.
 */
const SALSA_FREEZE = 0.2 * INFO.real_pose_change.salsa;

/** In-page: generate, then summarise (the positions stay in the page; only derived numbers come back). */
function summarise(page, options) {
  return page.evaluate(
    async ({ options, parents, bone }) => {
      const before = window.playground.current();
      const m = await window.playground.generate(options);
      const J = m.joints.length;
      const P = m.positions;
      let worstBone = 0;
      let finite = true;
      let relMotion = 0;
      for (let f = 0; f < m.frames; f++) {
        for (let j = 0; j < J; j++) {
          const o = (f * J + j) * 3;
          if (!Number.isFinite(P[o]) || !Number.isFinite(P[o + 1]) || !Number.isFinite(P[o + 2])) finite = false;
          if (j === 0) continue;
          const p = (f * J + parents[j]) * 3;
          worstBone = Math.max(worstBone, Math.abs(Math.hypot(P[o] - P[p], P[o + 1] - P[p + 1], P[o + 2] - P[p + 2]) - bone[j]));
          if (f > 0) {
            // Joint speed relative to the root, summed: a frozen pose gives ~0.
            const q = o - J * 3, r = f * J * 3, s = r - J * 3;
            relMotion += Math.hypot(P[o] - P[r] - (P[q] - P[s]), P[o + 1] - P[r + 1] - (P[q + 1] - P[s + 1]), P[o + 2] - P[r + 2] - (P[q + 2] - P[s + 2]));
          }
        }
      }
      const rootY = [];
      for (let f = 0; f < m.frames; f++) rootY.push(P[f * J * 3 + 1]);
      return {
        fps: m.fps,
        frames: m.frames,
        joints: m.joints,
        parents: m.parents,
        type: Object.prototype.toString.call(m.positions),
        length: P.length,
        finite,
        worstBone,
        meanJointSpeed: (relMotion / ((m.frames - 1) * J)) * m.fps,
        rootY: [Math.min(...rootY), Math.max(...rootY)],
        contacts: m.contacts ? m.contacts.length : null,
        shownUnchanged: window.playground.current() === before,
      };
    },
    { options, parents: PARENTS, bone: BONE },
  );
}

function digest(page, options) {
  return page.evaluate(async (o) => {
    const m = await window.playground.generate(o);
    return Array.from(new Uint8Array(m.positions.buffer, m.positions.byteOffset, m.positions.byteLength));
  }, options);
}

const status = (page) => page.evaluate(() => Number($ui('dance-status').dataset.frame));

/** In-page: the message generate rejects with, or "resolved". */
const rejection = (page, options) => page.evaluate((o) => window.playground.generate(o).then(() => 'resolved', (e) => e.message), options);

describe('dance models in the page', { timeout: 300_000 }, () => {
  const suite = usePlayground();

  test('models() lists both dance models with their styles', async () => {
    const models = await suite.page.evaluate(() => window.playground.models());
    for (const id of ['aclstm-mdn', 'aclstm']) {
      const m = models.find((x) => x.id === id);
      assert.ok(m, `${id} is listed`);
      assert.equal(m.kind, 'aclstm');
      assert.equal(m.fps, INFO.fps);
      assert.deepEqual(m.styles, INFO.styles);
    }
  });

  for (const style of INFO.styles) {
    test(`generate ${style}: frames × 57 points, finite, exact bone lengths, dancing`, async () => {
      const m = await summarise(suite.page, { model: 'aclstm', style, frames: 240, seed: 3 });
      assert.equal(m.fps, INFO.fps);
      assert.equal(m.frames, 240);
      assert.deepEqual(m.joints, JOINTS);
      assert.equal(m.joints.length, 57);
      assert.deepEqual(m.parents, PARENTS);
      assert.equal(m.type, '[object Float32Array]');
      assert.equal(m.length, 240 * 57 * 3);
      assert.ok(m.finite, 'no NaN or infinite positions');
      assert.ok(m.worstBone < 1e-4, `every bone keeps its skeleton length (worst ${m.worstBone.toExponential(2)} m)`);
      // A held pose measures ~0 (float noise); how lively the dance is, is the evaluation's business (docs/models/aclstm.md).
      assert.ok(m.meanJointSpeed > 0.03, `the pose changes (mean joint speed relative to the root ${m.meanJointSpeed.toFixed(3)} m/s)`);
      assert.ok(m.rootY[0] > 0.2 && m.rootY[1] < 1.6, `root height within 0.2–1.6 m (${m.rootY.map((v) => v.toFixed(2)).join('–')})`);
      assert.equal(m.contacts, 240 * 2, 'foot contacts, detected from the positions');
      assert.equal(m.shownUnchanged, true, 'generate does not show the motion');
    });
  }

  test('generate is deterministic; the seed picks the seed motion (mod the style’s count)', async () => {
    const count = INFO.seeds.filter((s) => s.style === 'indian').length;
    const a = await digest(suite.page, { model: 'aclstm', style: 'indian', frames: 90, seed: 1 });
    const b = await digest(suite.page, { model: 'aclstm', style: 'indian', frames: 90, seed: 1 });
    const wrapped = await digest(suite.page, { model: 'aclstm', style: 'indian', frames: 90, seed: 1 + count });
    const other = await digest(suite.page, { model: 'aclstm', style: 'indian', frames: 90, seed: 2 });
    const sampled = await digest(suite.page, { model: 'aclstm-mdn', style: 'indian', frames: 90, seed: 1 });
    assert.deepEqual(a, b, 'the same arguments give byte-identical positions');
    assert.deepEqual(wrapped, a, `seed ${1 + count} is seed 1 again (${count} indian seed motions)`);
    assert.notDeepEqual(other, a, 'another seed motion gives another dance');
    assert.notDeepEqual(sampled, a, 'the sampled model dances differently from the same seed motion');
  });

  test('ONNX parity in the browser: one step and a many-step call match the Python reference within 1e-4', async () => {
    for (const which of ['step', 'steps']) {
      const outputs = await suite.page.evaluate(async (inputs) => {
        const { DanceClient } = await import('/runtime/aclstm/danceClient.ts');
        const client = new DanceClient({ model: 'aclstm', threads: 1 });
        try {
          await client.init();
          const r = await client.parity(inputs);
          return Object.fromEntries(Object.entries(r.outputs).map(([k, v]) => [k, Array.from(v)]));
        } finally {
          client.dispose();
        }
      }, REFERENCE[which].inputs);
      for (const key of ['ys', 'h_out', 'c_out']) {
        const expected = REFERENCE[which].outputs[key];
        assert.equal(outputs[key].length, expected.length, `${which} ${key} length`);
        let worst = 0;
        for (let i = 0; i < expected.length; i++) worst = Math.max(worst, Math.abs(outputs[key][i] - expected[i]));
        assert.ok(worst <= 1e-4, `${which} ${key}: worst |a−b| = ${worst}`);
      }
    }
  });

  test('bad generate arguments reject with clear messages and leave the page working', async () => {
    const page = suite.page;
    await page.evaluate(async () => {
      const motion = await window.playground.generate({ model: 'aclstm', style: 'salsa', frames: 30, seed: 0 });
      window.playground.show(motion, 'dance');
      window.shownBefore = window.playground.current();
    });
    const cases = [
      { model: 'aclstm', style: 'tango', frames: 10, seed: 0 },
      { model: 'aclstm', frames: 10, seed: 0 },
      { model: 'aclstm', style: 3, frames: 10, seed: 0 },
      { model: 'aclstm', style: 'salsa', frames: 0, seed: 0 },
      { model: 'aclstm', style: 'salsa', frames: 2.5, seed: 0 },
      { model: 'aclstm', style: 'salsa', frames: 100001, seed: 0 },
      { model: 'aclstm', style: 'salsa', frames: 10, seed: -1 },
      { model: 'aclstm', style: 'salsa', frames: 10, seed: 1.5 },
      { model: 'aclstm', style: 'salsa', frames: 10 },
      { model: 'aclstm', style: 'salsa', frames: 10, seed: 0, temperature: 0.5 },
      { model: 'aclstm', style: 'salsa', frames: 10, seed: 0, refine: false },
      { model: 'aclstm-mdn', style: 'salsa', frames: 10, seed: 0, tempo: 2 },
      { model: 'generator', style: 'salsa', frames: 10, seed: 0 },
      { model: 'aclstm-plus', style: 'salsa', frames: 10, seed: 0 },
    ];
    const m = [];
    for (const c of cases) m.push(await rejection(page, c));
    const results = await page.evaluate(async () => {
      const pg = window.playground;
      const same = pg.current() === window.shownBefore;
      const lastError = pg.lastError();
      const still = await pg.generate({ model: 'aclstm', style: 'martial', frames: 5, seed: 0 });
      return { same, lastError, state: pg.state(), still: still.frames };
    });
    assert.equal(m[0], 'generate: unknown style "tango" for model "aclstm" (styles: salsa, indian, martial)');
    assert.equal(m[1], 'generate: style is required for model "aclstm" (styles: salsa, indian, martial)');
    assert.match(m[2], /^generate: unknown style 3 for model "aclstm"/);
    assert.match(m[3], /^generate: frames must be an integer from 1 to 100000, got 0/);
    assert.match(m[4], /frames must be an integer from 1 to 100000, got 2\.5/);
    assert.match(m[5], /frames must be an integer/);
    assert.match(m[6], /^generate: seed must be an integer from 0 to 4294967295, got -1/);
    assert.match(m[7], /seed must be an integer/);
    assert.match(m[8], /seed must be an integer .* got undefined/);
    assert.match(m[9], /^generate: temperature is not meaningful for acLSTM models/);
    assert.match(m[10], /^generate: refine is not available for acLSTM models/);
    assert.match(m[11], /^generate: unknown option "tempo" for model "aclstm-mdn" \(known: model, style, frames, seed, signal\)/);
    assert.match(m[12], /^generate: style is not an option of model "generator": it has no styles; leave it out$/);
    assert.match(m[13], /^generate: unknown model "aclstm-plus" \(available: .*\baclstm\b.*\)/);
    assert.equal(results.same, true, 'current() is unchanged');
    assert.equal(results.state.frames, 30);
    assert.equal(results.lastError, m[13], 'the last message is shown on the page');
    assert.equal(results.still, 5, 'a valid call still works afterwards');
  });

  test('Dance mode: streams, plots the pose change, switches style and model, exports BVH', async () => {
    // A clip to come back to.
    const clipFrames = await suite.page.evaluate(async () => {
      const m = await window.playground.generate({ model: 'aclstm', style: 'martial', frames: 45, seed: 0 });
      window.playground.show(m, 'clip');
      return window.playground.current().frames;
    });
    assert.equal(clipFrames, 45);
    await suite.page.click('#mode-dance');
    await waitUntil(suite.page, () => Number($ui('dance-status').dataset.frame) > 10, null, { timeout: 60_000, message: 'the dance starts' });
    const ui = await suite.page.evaluate(() => ({
      dance: $uiFrame().classList.contains('dance-mode'),
      pressed: $ui('mode-dance').getAttribute('aria-pressed'),
      styles: [...$ui('dance-style').options].map((o) => o.value),
      seeds: [...$ui('dance-seed').options].map((o) => o.textContent),
      plotVisible: getComputedStyle($ui('dance-plot-card')).display !== 'none',
    }));
    assert.ok(ui.dance);
    assert.equal(ui.pressed, 'true');
    assert.deepEqual(ui.styles, INFO.styles);
    assert.deepEqual(ui.seeds, INFO.seeds.filter((s) => s.style === INFO.styles[0]).map((s) => s.name));
    assert.ok(ui.plotVisible);

    // Frames advance and the plot gains a point per second of them.
    const f1 = await status(suite.page);
    await waitUntil(suite.page, () => Number($ui('dance-plot').dataset.seconds) >= 3, null, { timeout: 30_000, message: 'the plot shows 3 seconds' });
    const f2 = await status(suite.page);
    assert.ok(f2 > f1 + INFO.fps, `the dance advances (frame ${f1} → ${f2})`);
    const live = await suite.page.evaluate(() => {
      const m = window.playground.current();
      const plot = $ui('dance-plot').dataset;
      return { joints: m.joints.length, frames: m.frames, fps: m.fps, playing: window.playground.state().playing, last: Number(plot.last), loading: $ui('model-status').hidden };
    });
    assert.equal(live.joints, 57);
    assert.equal(live.fps, INFO.fps);
    assert.equal(live.playing, true);
    assert.ok(live.last > SALSA_FREEZE, `the plot shows the dance moving: ${live.last} m/s, above the freeze line ${SALSA_FREEZE.toFixed(3)} m/s`);
    assert.equal(live.loading, true, 'the loading indicator is hidden once the model is loaded');

    // Export BVH saves the dance: 57 joints at the skeleton's bone lengths.
    const [download] = await Promise.all([suite.page.waitForEvent('download'), suite.page.locator('#export-menu-btn').click().then(() => suite.page.locator('#export-btn').click())]);
    assert.equal(download.suggestedFilename(), 'dance.bvh');
    const text = readFileSync(await download.path(), 'utf8');
    const reimported = await suite.page.evaluate(
      async ({ text, parents, bone }) => {
        const m = await window.playground.importMotion(text, 'bvh');
        let worst = 0;
        const P = m.positions, J = m.joints.length;
        for (let f = 0; f < m.frames; f += 7) {
          for (let j = 1; j < J; j++) {
            const o = (f * J + j) * 3, p = (f * J + parents[j]) * 3;
            worst = Math.max(worst, Math.abs(Math.hypot(P[o] - P[p], P[o + 1] - P[p + 1], P[o + 2] - P[p + 2]) - bone[j]));
          }
        }
        return { joints: m.joints, frames: m.frames, fps: m.fps, worst };
      },
      { text, parents: PARENTS, bone: BONE },
    );
    assert.deepEqual(reimported.joints, JOINTS);
    assert.equal(reimported.fps, INFO.fps);
    assert.ok(reimported.frames > 60);
    assert.ok(reimported.worst < 1e-3, `exported bones keep their lengths (worst ${reimported.worst} m)`);

    // Another style restarts the dance from its first seed motion; the plot starts again.
    const style = INFO.styles[1];
    await suite.page.selectOption('#dance-style', style);
    await waitUntil(
      suite.page,
      (s) => $ui('clip-meta').textContent.includes(s) && Number($ui('dance-status').dataset.frame) < 200,
      style,
      { timeout: 30_000, message: `the dance restarts as ${style}` },
    );
    const switched = await suite.page.evaluate(() => ({
      seeds: [...$ui('dance-seed').options].map((o) => o.textContent),
      meta: $ui('clip-meta').textContent,
    }));
    assert.deepEqual(switched.seeds, INFO.seeds.filter((s) => s.style === style).map((s) => s.name));
    assert.match(switched.meta, new RegExp(`acLSTM, phrase sampling · ${style}`)); // Dance starts with the sampled model (issue 42)
    // Restarted: the plot holds no more seconds than the new stream has run (read together, so no race).
    const restarted = await suite.page.evaluate(() => ({ seconds: Number($ui('dance-plot').dataset.seconds), frame: Number($ui('dance-status').dataset.frame) }));
    assert.ok(restarted.seconds <= restarted.frame / INFO.fps + 1, `the plot restarted (${restarted.seconds} s plotted at frame ${restarted.frame})`);
    await waitUntil(suite.page, () => Number($ui('dance-plot').dataset.seconds) >= 1, null, { timeout: 30_000, message: 'the new plot gains a second' });

    // The deterministic acLSTM runs in the same mode.
    await suite.page.selectOption('#dance-model', 'aclstm');
    await waitUntil(suite.page, () => $ui('clip-meta').textContent.includes('deterministic'), null, { timeout: 60_000, message: 'the deterministic model is shown' });
    // The switch shows at once; its stream starts once its model has loaded (no fixed deadline).
    const g1 = await status(suite.page);
    await waitUntil(suite.page, (from) => Number($ui('dance-status').dataset.frame) > from + 30, g1, {
      timeout: 60_000,
      message: `the deterministic model's dance advances 30 frames from frame ${g1}`,
    });
    assert.match(await suite.page.locator('#clip-meta').textContent(), /deterministic/, 'the deterministic model dances too');

    await suite.page.click('#mode-clip');
    const back = await suite.page.evaluate(() => ({ frames: window.playground.current()?.frames, dance: $uiFrame().classList.contains('dance-mode') }));
    assert.equal(back.dance, false);
    assert.equal(back.frames, clipFrames, 'the clip shown before is back');
  });

  test('Dance mode in a fresh page: frames grow, the plot fills, no console errors', async () => {
    const fresh = await openPlayground(suite.browser, suite.url);
    try {
      await fresh.page.click('#mode-dance');
      await waitUntil(fresh.page, () => Number($ui('dance-plot').dataset.seconds) >= 2, null, { timeout: 60_000, message: 'the plot shows 2 seconds' });
      const a = await status(fresh.page);
      // Frames keep coming (their rate against the wall clock is `npm run bench`'s dance-mode) and the
      // plot gains the seconds they complete.
      await waitUntil(fresh.page, ([a, fps]) => Number($ui('dance-status').dataset.frame) > a + 2 * fps, [a, INFO.fps], {
        timeout: 60_000,
        message: `the dance advances 2 s of frames from frame ${a}`,
      });
      await waitUntil(fresh.page, () => Number($ui('dance-plot').dataset.seconds) >= 3, null, { timeout: 30_000, message: 'the plot shows 3 seconds' });
      assert.deepEqual(fresh.problems, []);
    } finally {
      await fresh.context.close();
    }
  });

  test('without cross-origin isolation the dance model runs single-threaded', async () => {
    const plain = await startServer({ headers: { 'Cross-Origin-Opener-Policy': 'unsafe-none', 'Cross-Origin-Embedder-Policy': 'unsafe-none' } });
    try {
      const { context, page, problems } = await openPlayground(suite.browser, `${plain.url}?threads=2`);
      const r = await page.evaluate(async () => {
        const { DanceClient } = await import('/runtime/aclstm/danceClient.ts');
        const client = new DanceClient({ threads: 2 });
        const info = await client.init();
        client.dispose();
        const m = await window.playground.generate({ model: 'aclstm', style: 'salsa', frames: 30, seed: 0 });
        return { isolated: globalThis.crossOriginIsolated, threads: info.threads, frames: m.frames };
      });
      await context.close();
      assert.deepEqual(r, { isolated: false, threads: 1, frames: 30 });
      assert.deepEqual(problems, []);
    } finally {
      await plain.server.close();
    }
  });
});
