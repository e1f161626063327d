// End-to-end tests of the VAE-LSTM in the page (issue 15): Path mode's model choice (the walk appears as soon
// as the path is drawn, Vary draws another, Steer keeps its own model), Compare (two models walk the same path
// side by side, each with its numbers), playground.generate and followPath with model 'vae-lstm' (the seed
// picks z, so the same seed gives the same motion), refusals that leave the page as it was, and parity in the
// browser (the four graphs and a whole generation run by the worker against
// tests/fixtures/vae_lstm_reference.json). Every number compared comes from the fixture or the model JSON.
// Run with `node --test tests/e2e/vaeLstm.test.mjs`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { describe, test } from 'node:test';
import { apiFailure, drawStroke, ROOT, usePlayground, waitUntil } from './harness.mjs';

const REFERENCE = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/vae_lstm_reference.json'), 'utf8'));
const VAE = JSON.parse(readFileSync(path.join(ROOT, 'public/models/vae-lstm.json'), 'utf8'));
const REPORT = JSON.parse(readFileSync(path.join(ROOT, 'docs/models/vae-lstm.json'), 'utf8'));
const BENCHMARK = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/benchmark_paths.json'), 'utf8'));
/** The reports' freeze line: a second below this share of the real clips' median pose change has stopped moving. */
const FREEZE_FRACTION = 0.2;
const J = VAE.skeleton.joints.length;
const BEND = [[0, 0], [0, 2], [1.5, 3.5]];
const STATS = /error mean (\d+\.\d) cm · max (\d+\.\d) cm · (\d+) % of the path · (\d+\.\d) s for (\d+\.\d) s of motion/;

const worst = (a, b) => {
  assert.equal(a.length, b.length, 'same length');
  let w = 0;
  for (let i = 0; i < a.length; i++) w = Math.max(w, Math.abs(a[i] - b[i]));
  return w;
};

const pathStatus = (page) =>
  page.evaluate(() => {
    const s = $ui('path-status');
    const m = window.playground.current();
    return {
      state: s.dataset.state, walkedBy: s.dataset.walkedBy, comparedWith: s.dataset.comparedWith, text: s.textContent,
      lines: [...s.querySelectorAll('.path-stats')].map((l) => [l.dataset.model, l.textContent]),
      meta: $ui('clip-meta').textContent, seed: $ui('path-seed').value,
      positions: m ? Array.from(m.positions.subarray(0, 600)) : [], frames: m?.frames ?? 0,
      labels: [...$uiAll('.figure-label')].map((l) => l.textContent),
    };
  });

const choices = (page) => page.evaluate(() => [$ui('steer-model').value, $ui('path-model').value]);

describe('the VAE-LSTM in Path mode', { timeout: 400_000 }, () => {
  const suite = usePlayground();

  test('chosen, it walks a path as soon as it is drawn; Vary draws another walk; Steer keeps a model it can steer', async () => {
    const page = suite.page;
    await page.click('#mode-path');
    const options = await page.evaluate(() => [...$ui('path-model').options].map((o) => o.value));
    assert.deepEqual(options, ['generator', 'style-generator', 'latent-erd', 'vae-lstm']);
    assert.equal(await page.locator('#path-vary').isHidden(), true, 'Vary is the VAE-LSTM\'s');
    await page.selectOption('#path-model', 'vae-lstm');
    assert.deepEqual(await choices(page), ['generator', 'vae-lstm'], 'Steer cannot run the VAE-LSTM and keeps the generator');
    assert.equal(await page.locator('#path-fit').isDisabled(), true, 'no fit tolerance');
    assert.equal(await page.locator('#path-speed').isDisabled(), false, 'a speed instead');
    assert.equal(await page.locator('#path-vary').isVisible(), true);

    await drawStroke(page, Array.from({ length: 31 }, (_, i) => [0.3 + (0.4 * i) / 30, 0.45 + 0.1 * Math.sin(i / 6)]));
    // No Go: the walk appears once the path is drawn.
    await waitUntil(page, () => $ui('path-status').dataset.state === 'done', null, { timeout: 120_000, message: 'the VAE-LSTM walks the drawn path' });
    const first = await pathStatus(page);
    assert.equal(first.walkedBy, 'vae-lstm');
    assert.equal(first.lines.length, 1);
    assert.equal(first.lines[0][0], 'vae-lstm');
    assert.match(first.lines[0][1], /^VAE-LSTM: /);
    assert.ok(STATS.test(first.text), `the stats are shown: ${first.text}`);
    assert.match(first.meta, /VAE-LSTM · walk · \d+ frames/);
    assert.ok(first.positions.every(Number.isFinite) && first.frames > 0);

    // Vary: the next seed, another walk of the same path.
    await page.click('#path-vary');
    await waitUntil(page, (seed) => {
      const s = $ui('path-status');
      return s.dataset.state === 'done' && $ui('path-seed').value !== seed;
    }, first.seed, { timeout: 120_000, message: 'Vary walks the path again' });
    const varied = await pathStatus(page);
    assert.equal(Number(varied.seed), Number(first.seed) + 1);
    assert.equal(varied.walkedBy, 'vae-lstm');
    assert.ok(worst(varied.positions, first.positions) > 0.01, 'another z, another walk');
    assert.doesNotMatch(varied.lines[0][1], /runs stop stepping/, 'a walk has no running note');

    // Running: the line says how long the VAE-LSTM's runs last.
    await page.selectOption('#path-gait', 'run');
    await page.click('#path-go');
    await waitUntil(page, () => $ui('path-status').dataset.state === 'done' && $ui('clip-meta').textContent.includes('· run ·'), null,
      { timeout: 120_000, message: 'the VAE-LSTM runs the path' });
    assert.match((await pathStatus(page)).lines[0][1], /its runs stop stepping after about 2 s/);
    await page.selectOption('#path-gait', 'walk');

    // Steer runs the generator meanwhile.
    await page.click('#mode-steer');
    await waitUntil(page, () => $ui('steer-status').dataset.model === 'generator', null, { timeout: 60_000, message: 'Steer streams from the generator' });
    await page.click('#mode-path');
    assert.deepEqual(await choices(page), ['generator', 'vae-lstm'], 'the choice stays');
    await page.click('#mode-clip');
  });

  test('Compare: a second model walks the same path beside the first, each with its numbers', async () => {
    const page = suite.page;
    await page.click('#mode-path');
    await page.selectOption('#path-model', 'vae-lstm');
    await page.selectOption('#path-compare', 'latent-erd');
    await page.click('#path-go');
    await waitUntil(page, () => {
      const s = $ui('path-status');
      return s.dataset.state === 'done' && s.dataset.comparedWith === 'latent-erd';
    }, null, { timeout: 180_000, message: 'both models walk the path' });
    const r = await pathStatus(page);
    assert.deepEqual(r.lines.map(([m]) => m), ['vae-lstm', 'latent-erd']);
    assert.match(r.lines[0][1], /^VAE-LSTM: /);
    assert.match(r.lines[1][1], /^latent ERD: /);
    for (const [, line] of r.lines) assert.ok(STATS.test(line) && /sliding \d+\.\d\d m\/s/.test(line), `error, progress, time and sliding: ${line}`);
    assert.deepEqual(r.labels, ['VAE-LSTM', 'latent ERD'], 'the two figures are labelled');
    assert.match(r.meta, /VAE-LSTM vs latent ERD/);
    // Compare off: one walk again.
    await page.selectOption('#path-compare', '');
    await page.click('#path-go');
    await waitUntil(page, () => {
      const s = $ui('path-status');
      return s.dataset.state === 'done' && !s.dataset.comparedWith;
    }, null, { timeout: 120_000, message: 'one walk' });
    assert.deepEqual((await pathStatus(page)).labels, []);
    await page.click('#mode-clip');
  });
});

describe('the VAE-LSTM through window.playground', { timeout: 300_000 }, () => {
  const suite = usePlayground();

  test('models() lists it; generate with and without control is deterministic and the seed picks z', async () => {
    const page = suite.page;
    const r = await page.evaluate(async () => {
      await window.playground.ready;
      const entry = window.playground.models().find((m) => m.id === 'vae-lstm');
      const control = Array.from({ length: 90 }, () => [1.3, 0, 0.3]);
      const a = await window.playground.generate({ model: 'vae-lstm', frames: 90, seed: 3, control });
      const b = await window.playground.generate({ model: 'vae-lstm', frames: 90, seed: 3, control });
      const c = await window.playground.generate({ model: 'vae-lstm', frames: 90, seed: 4, control });
      const free = await window.playground.generate({ model: 'vae-lstm', frames: 60, seed: 3 });
      const diff = (x, y) => x.positions.reduce((w, v, i) => Math.max(w, Math.abs(v - y.positions[i])), 0);
      const end = (m) => [m.positions[(m.frames - 1) * m.joints.length * 3], m.positions[(m.frames - 1) * m.joints.length * 3 + 2]];
      return { entry, same: diff(a, b), other: diff(a, c), free: free.frames, joints: a.joints.length, contacts: a.contacts.length, end: end(a) };
    });
    assert.equal(r.entry?.kind, 'vae-lstm');
    assert.equal(r.same, 0, 'the same arguments give the same motion');
    assert.ok(r.other > 0.01, 'another seed, another z');
    assert.equal(r.free, 60);
    assert.equal(r.joints, J);
    assert.equal(r.contacts, 180);
    // 3 s at 1.3 m/s turning 0.3 rad/s: the root went about 3.9 m of arc from the origin.
    assert.ok(Math.hypot(...r.end) > 3, `it went where it was sent: ${r.end}`);
  });

  test('a 3,000-frame stream on its random control does not sag: no second below the freeze line (issue 43)', async () => {
    // The stream (seed 9) and the deepest sag found over seeds 0-39 before the fix (seed 30: 0.14x the real
    // median at 1.8 m/s, where the control walks on), measured as the reports measure it (poseChange.ts, per whole
    // second, against the real clips' median in docs/models/vae-lstm.json).
    const real = REPORT.long_runs.real_median_pose_change;
    const r = await suite.page.evaluate(async (seeds) => {
      const { poseChangePerSecond } = await import('/motion/poseChange.ts');
      const out = [];
      for (const seed of seeds) {
        const m = await window.playground.generate({ model: 'vae-lstm', frames: 3000, seed });
        const seconds = poseChangePerSecond(m.positions, m.joints.length, m.fps);
        out.push({ seed, lowest: Math.min(...seconds), at: seconds.indexOf(Math.min(...seconds)) });
      }
      return out;
    }, [9, 30]);
    for (const { seed, lowest, at } of r) {
      console.log(`# VAE-LSTM random control, seed ${seed}: lowest second ${(lowest / real).toFixed(2)}x the real median (second ${at})`);
      assert.ok(lowest >= FREEZE_FRACTION * real, `seed ${seed}: second ${at} at ${(lowest / real).toFixed(2)}x the real median pose change`);
    }
  });

  test('followPath with the VAE-LSTM: the path walked, the same seed the same motion, refusals leave the page as it was', async () => {
    const page = suite.page;
    const r = await page.evaluate(async (points) => {
      const a = await window.playground.followPath({ model: 'vae-lstm', points, seed: 2 });
      const b = await window.playground.followPath({ model: 'vae-lstm', points, seed: 2 });
      const diff = a.positions.reduce((w, v, i) => Math.max(w, Math.abs(v - b.positions[i])), 0);
      return { stats: a.stats, diff, frames: a.frames };
    }, BEND);
    assert.equal(r.diff, 0);
    assert.ok(r.stats.meanError < 0.15 && r.stats.arcProgress > 0.95, JSON.stringify(r.stats));
    const live = await apiFailure(page, 'simulateControl', { model: 'vae-lstm', seconds: 1, schedule: [{ t: 0, speed: 1, heading: 0 }] });
    assert.match(live.message, /simulateControl: the VAE-LSTM makes the whole motion .* takes no live control/);
    const fit = await apiFailure(page, 'followPath', { model: 'vae-lstm', points: BEND, fitTolerance: 0.1 });
    assert.match(fit.message, /followPath: unknown option "fitTolerance"/);
    const bad = await apiFailure(page, 'generate', { model: 'vae-lstm', frames: 10, seed: 0, control: [[1, 0, 0]] });
    assert.match(bad.message, /generate: control has 1 frames/);
    const temp = await apiFailure(page, 'generate', { model: 'vae-lstm', frames: 10, seed: 0, temperature: 1 });
    assert.match(temp.message, /unknown option "temperature" for model "vae-lstm"/);
  });

  test('followPath walks a path that doubles back (issue 43): >= 95% of its length within 0.15 m, walking and running', async () => {
    // The benchmark's back-and-forth scribble (four reversals), measured on the returned motion's root (the hips) with
    // the shared measure (web/motion/pathCoverage.ts). Before: 30% walking, 52% running (pure pursuit cut each reversal).
    const points = BENCHMARK.paths['back-and-forth'].points;
    const r = await suite.page.evaluate(async (points) => {
      const { pathCoverage, rootGroundTrack } = await import('/motion/pathCoverage.ts');
      const out = [];
      for (const gait of ['walk', 'run']) {
        const m = await window.playground.followPath({ model: 'vae-lstm', points, gait, seed: 0 });
        out.push({ gait, coverage: pathCoverage(points, rootGroundTrack(m.positions, m.joints.length)), stats: m.stats, frames: m.frames });
      }
      return out;
    }, points);
    for (const { gait, coverage, stats, frames } of r) {
      console.log(`# VAE-LSTM back-and-forth, ${gait}: ${(coverage * 100).toFixed(1)}% within 0.15 m, mean error ${stats.meanError.toFixed(3)} m, ${frames} frames`);
      assert.ok(coverage >= 0.95, `${gait}: ${(coverage * 100).toFixed(1)}% of the path followed within 0.15 m`);
    }
  });

  test('parity in the browser: the four graphs and a whole generation over two chunks of the cell', async () => {
    const r = await suite.page.evaluate(async ({ graphs, generate, steps }) => {
      const { VaeLstmClient } = await import('/runtime/vae_lstm/vaeLstmClient.ts');
      const client = new VaeLstmClient({ threads: 1 });
      try {
        await client.init();
        const inputs = Object.fromEntries(Object.entries(graphs).map(([g, c]) => [g, c.inputs]));
        const p = await client.parity({ graphs: inputs, generate: { control: generate.control, z1: generate.z1 } });
        const t = await client.parity({ generate: { control: generate.control, z1: generate.z1, zs: steps.zs } });
        return {
          graphs: Object.fromEntries(Object.keys(graphs).map((g) => [g, Object.fromEntries(Object.entries(p[g]).map(([k, v]) => [k, Array.from(v)]))])),
          rows: Array.from(p.rows), teacher: Array.from(t.rows),
        };
      } finally {
        client.dispose();
      }
    }, { graphs: REFERENCE.graphs, generate: REFERENCE.generate, steps: REFERENCE.generate_steps });
    for (const [g, c] of Object.entries(REFERENCE.graphs)) {
      for (const [name, want] of Object.entries(c.outputs)) assert.ok(worst(r.graphs[g][name], want) <= REFERENCE.tolerance, `${g}.${name}`);
    }
    const { mean, std } = VAE.normalisation;
    const D = VAE.rows.dim;
    const normalise = (rows) => rows.map((v, i) => (v - mean[i % D]) / std[i % D]);
    const err = worst(normalise(r.rows), REFERENCE.generate.rows);
    const teacher = worst(normalise(r.teacher), REFERENCE.generate_steps.rows);
    console.log(`# VAE-LSTM generation parity in the browser: ${err.toExponential(2)} (one z1), ${teacher.toExponential(2)} (a latent per step)`);
    assert.ok(err <= REFERENCE.tolerance, `generation ${err}`);
    assert.ok(teacher <= REFERENCE.tolerance, `teacher-mode generation ${teacher}`);
  });
});
