// End-to-end tests of the latent ERD in the page (issue 14): the model choice of Steer and Path modes (the
// stream steered live, a drawn path followed, the choice kept across mode switches, and back to the
// generator), playground.generate with and without a control signal, followPath and simulateControl with
// model 'latent-erd', refusals that leave the page as it was, and parity in the browser (one ERD step, one decoder window and the fixture's whole stream run by the
// worker against tests/fixtures/latent_erd_reference.json). Every number compared comes from the fixture
// or the model JSON (the models are replaced by retrained ones). Run with `node --test tests/e2e/latentErd.test.mjs`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { describe, test } from 'node:test';
import { apiFailure, drawStroke, ROOT, usePlayground, waitUntil } from './harness.mjs';

const REFERENCE = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/latent_erd_reference.json'), 'utf8'));
const ERD = JSON.parse(readFileSync(path.join(ROOT, 'public/models/latent-erd.json'), 'utf8'));
const MANIFOLD = JSON.parse(readFileSync(path.join(ROOT, 'public/models/manifold.json'), 'utf8'));
const J = MANIFOLD.skeleton.joints.length;
const BEND = [[0, 0], [0, 2], [1.5, 3.5]];

const worst = (a, b) => {
  assert.equal(a.length, b.length, 'same length');
  let w = 0;
  for (let i = 0; i < a.length; i++) w = Math.max(w, Math.abs(a[i] - b[i]));
  return w;
};

/** In-page generate, returned as plain data. */
function generate(page, options) {
  return page.evaluate(async (o) => {
    const before = window.playground.current();
    const m = await window.playground.generate(o);
    return {
      fps: m.fps, frames: m.frames, joints: m.joints, parents: m.parents, positions: Array.from(m.positions), contacts: Array.from(m.contacts),
      positionsType: Object.prototype.toString.call(m.positions), shownUnchanged: window.playground.current() === before,
    };
  }, options);
}

/** Worst bone-length error (m) of a motion of the manifold skeleton. */
function worstBone(m) {
  let w = 0;
  for (let f = 0; f < m.frames; f++) {
    for (let j = 1; j < J; j++) {
      const o = (f * J + j) * 3, p = (f * J + m.parents[j]) * 3;
      const len = Math.hypot(m.positions[o] - m.positions[p], m.positions[o + 1] - m.positions[p + 1], m.positions[o + 2] - m.positions[p + 2]);
      w = Math.max(w, Math.abs(len - Math.hypot(...MANIFOLD.skeleton.offsets[j])));
    }
  }
  return w;
}

const STATS = /error mean (\d+\.\d) cm · max (\d+\.\d) cm · (\d+) % of the path · (\d+\.\d) s for (\d+\.\d) s of motion/;

const steerStatus = (page) =>
  page.evaluate(() => {
    const s = $ui('steer-status');
    return { model: s.dataset.model, frame: Number(s.dataset.frame), text: s.textContent, meta: $ui('clip-meta').textContent };
  });

/** Waits until Steer mode streams from `model` and has shown more than `frames` frames of it. */
function steerStreams(page, model, frames = 8) {
  return waitUntil(
    page,
    ({ model, frames }) => {
      const s = $ui('steer-status');
      // The status names the stream's model once it describes a frame of it ("… latent ERD · 2.1 ms per 4 frames", "… 24 particles").
      const marker = model === 'latent-erd' ? / · latent ERD · / : / particles$/;
      return s.dataset.model === model && marker.test(s.textContent) && Number(s.dataset.frame) > frames && $ui('clip-meta').textContent.includes(model === 'latent-erd' ? 'latent ERD' : 'generator');
    },
    { model, frames },
    { timeout: 90_000, message: `Steer mode streams from the ${model}` },
  );
}

/** The values of both model selects. */
const choices = (page) => page.evaluate(() => [$ui('steer-model').value, $ui('path-model').value]);

describe('the model choice of Steer and Path modes', { timeout: 400_000 }, () => {
  const suite = usePlayground();

  test('Steer mode: the latent ERD is chosen from the keyboard, steered live, kept across mode switches; back to the generator', async () => {
    const page = suite.page;
    await page.click('#mode-steer');
    const labels = await page.evaluate(() => [...$ui('steer-model').options].map((o) => [o.value, o.textContent]));
    assert.deepEqual(labels, [['generator', 'Generator + MAP optimiser'], ['style-generator', 'style-generator (non-commercial)'], ['latent-erd', 'Latent ERD']]);
    assert.deepEqual(await choices(page), ['generator', 'generator'], 'the generator by default');
    await steerStreams(page, 'generator');
    assert.match((await steerStatus(page)).text, /particles/, 'the MAP controller runs');

    // Keyboard: the select is in the tab order, and typing an option's first letter picks it.
    assert.equal(await page.evaluate(() => $ui('steer-model').tabIndex), 0);
    await page.focus('#steer-model');
    await page.keyboard.press('l');
    assert.deepEqual(await choices(page), ['latent-erd', 'latent-erd'], 'one choice for both modes');
    await page.evaluate(() => $uiActive()?.blur());
    await steerStreams(page, 'latent-erd');
    const erd = await steerStatus(page);
    assert.match(erd.text, /latent ERD · \d+\.\d ms per 4 frames/);
    assert.doesNotMatch(erd.text, /particles/);
    const m = await page.evaluate(() => {
      const c = window.playground.current();
      return { joints: c.joints.length, fps: c.fps, finite: c.positions.every(Number.isFinite), contacts: c.contacts?.length === c.frames * 2 };
    });
    assert.deepEqual(m, { joints: J, fps: ERD.fps, finite: true, contacts: true });

    // The keys steer the latent ERD: the target turns, and the stream goes on.
    const before = await steerStatus(page);
    await page.keyboard.down('ArrowLeft');
    try {
      await waitUntil(page, () => Number($ui('steer-readout').dataset.targetHeading) > 0.6, null, { timeout: 20_000, message: '← turns the target heading' });
    } finally {
      await page.keyboard.up('ArrowLeft');
    }
    await waitUntil(page, (f) => Number($ui('steer-status').dataset.frame) > f + 30, before.frame, { timeout: 60_000, message: 'the latent ERD stream goes on' });
    const readout = await page.evaluate(() => ({ ...$ui('steer-readout').dataset }));
    assert.ok(Number.isFinite(Number(readout.speed)) && readout.speed !== '', `an achieved speed is shown (${readout.speed})`);

    // Away and back: still the latent ERD.
    await page.click('#mode-clip');
    await page.click('#mode-steer');
    assert.deepEqual(await choices(page), ['latent-erd', 'latent-erd']);
    await steerStreams(page, 'latent-erd');

    await page.selectOption('#steer-model', 'generator');
    await steerStreams(page, 'generator');
    assert.match((await steerStatus(page)).text, /particles/);
    await page.click('#mode-clip');
  });

  test('Path mode: a drawn path is followed by the latent ERD with progress; the generator walks it again when chosen back', async () => {
    const page = suite.page;
    await page.click('#mode-path');
    if (await page.locator('#path-clear').isEnabled()) await page.click('#path-clear');
    await page.selectOption('#path-model', 'latent-erd');
    assert.deepEqual(await choices(page), ['latent-erd', 'latent-erd']);
    assert.equal(await page.locator('#path-fit').isDisabled(), true, 'no fit tolerance for the latent ERD');
    await drawStroke(page, Array.from({ length: 31 }, (_, i) => [0.3 + (0.4 * i) / 30, 0.45]));
    assert.equal(await page.evaluate(() => $ui('path-status').dataset.state), 'drawn');
    await page.evaluate(() => ($ui('path-progress').value = 0));
    await page.click('#path-go');
    await waitUntil(page, () => $ui('path-status').dataset.state === 'done', null, { timeout: 120_000, message: 'the latent ERD walks the path' });
    const done = await page.evaluate(() => {
      const s = $ui('path-status');
      const m = window.playground.current();
      return {
        walkedBy: s.dataset.walkedBy, text: s.textContent, meta: $ui('clip-meta').textContent,
        progress: $ui('path-progress').value, progressHidden: $ui('path-progress').hidden,
        frames: m.frames, joints: m.joints.length, finite: m.positions.every(Number.isFinite), playing: window.playground.state().playing,
      };
    });
    assert.equal(done.walkedBy, 'latent-erd');
    assert.match(done.text, /^latent ERD: /);
    assert.ok(STATS.test(done.text), `the stats are shown: ${done.text}`);
    assert.match(done.meta, /latent ERD · walk · \d+ frames/);
    assert.equal(done.progress, 1, 'the progress bar went to the end');
    assert.equal(done.progressHidden, true);
    assert.equal(done.joints, J);
    assert.ok(done.frames > 0 && done.finite && done.playing);
    const motionSeconds = Number(STATS.exec(done.text)[5]);
    assert.ok(Math.abs((done.frames - 1) / ERD.fps - motionSeconds) < 0.1, 'the stats describe the shown walk');

    // Away and back: the choice and the walk stay; then the generator walks the same path.
    await page.click('#mode-clip');
    await page.click('#mode-path');
    assert.deepEqual(await choices(page), ['latent-erd', 'latent-erd']);
    assert.equal(await page.evaluate(() => $ui('path-status').dataset.walkedBy), 'latent-erd');
    await page.selectOption('#path-model', 'generator');
    assert.equal(await page.locator('#path-fit').isDisabled(), false);
    await page.click('#path-go');
    await waitUntil(page, () => $ui('path-status').dataset.walkedBy === 'generator' && $ui('path-status').dataset.state === 'done', null, { timeout: 180_000, message: 'the generator walks the path' });
    const generator = await page.evaluate(() => ({ text: $ui('path-status').textContent, meta: $ui('clip-meta').textContent }));
    assert.doesNotMatch(generator.text, /latent ERD/);
    assert.ok(STATS.test(generator.text));
    assert.match(generator.meta, /generator · walk/);
    await page.click('#mode-clip');
  });
});

describe('latent ERD in the page', { timeout: 300_000 }, () => {
  const suite = usePlayground();

  test('models() lists the latent ERD and its autoencoder', async () => {
    const models = await suite.page.evaluate(() => window.playground.models());
    const erd = models.find((m) => m.id === 'latent-erd');
    const manifold = models.find((m) => m.id === 'manifold');
    assert.deepEqual({ kind: erd?.kind, skeleton: erd?.skeleton, fps: erd?.fps }, { kind: 'latent-erd', skeleton: 'cmu-canonical', fps: ERD.fps });
    assert.deepEqual({ kind: manifold?.kind, fps: manifold?.fps }, { kind: 'autoencoder', fps: MANIFOLD.fps });
    assert.ok(erd.bytes > 0 && manifold.bytes > 0);
  });

  test('generate without control: random control from the seed, the skeleton kept, deterministic', async () => {
    const a = await generate(suite.page, { model: 'latent-erd', frames: 90, seed: 5 });
    assert.equal(a.fps, ERD.fps);
    assert.equal(a.frames, 90);
    assert.deepEqual(a.joints, MANIFOLD.skeleton.joints);
    assert.equal(a.positionsType, '[object Float32Array]');
    assert.equal(a.positions.length, 90 * J * 3);
    assert.ok(a.positions.every(Number.isFinite));
    assert.equal(a.contacts.length, 180);
    assert.ok(a.contacts.every((c) => c === 0 || c === 1));
    assert.ok(a.shownUnchanged, 'generate does not show the motion');
    assert.ok(worstBone(a) < 1e-4, 'bone lengths kept');
    const b = await generate(suite.page, { model: 'latent-erd', frames: 90, seed: 5 });
    assert.deepEqual(b.positions, a.positions);
    const c = await generate(suite.page, { model: 'latent-erd', frames: 90, seed: 6 });
    assert.notDeepEqual(c.positions, a.positions);
    // The random control is randomControl(seed) (web/motion/control.ts): passing it gives the same motion.
    const same = await suite.page.evaluate(async ({ frames, steps, fps }) => {
      const { randomControl } = await import('/motion/control.ts');
      const r = randomControl(5, steps * 4, fps);
      const control = Array.from({ length: steps * 4 }, (_, f) => [r[3 * f], r[3 * f + 1], r[3 * f + 2]]);
      const m = await window.playground.generate({ model: 'latent-erd', frames, seed: 5, control });
      return Array.from(m.positions);
    }, { frames: 90, steps: Math.ceil(90 / ERD.pooling) + ERD.lookahead, fps: ERD.fps });
    assert.deepEqual(same, a.positions);
  });

  test('generate with a control signal: it drives the root (forward vs standing, turning left vs right)', async () => {
    const frames = 60;
    const run = (fwd, turn) => generate(suite.page, { model: 'latent-erd', frames, seed: 0, control: Array.from({ length: frames }, () => [fwd, 0, turn]) });
    const [still, walk] = [await run(0, 0), await run(1.4, 0)];
    const travel = (m) => Math.hypot(m.positions[(frames - 1) * J * 3] - m.positions[0], m.positions[(frames - 1) * J * 3 + 2] - m.positions[2]);
    assert.ok(still.positions.every(Number.isFinite) && walk.positions.every(Number.isFinite));
    assert.notDeepEqual(walk.positions, still.positions, 'another control, another motion');
    console.log(`# latent ERD: travel ${travel(still).toFixed(2)} m standing, ${travel(walk).toFixed(2)} m asked to walk 1.4 m/s for 2 s`);
    // A longer control than frames is accepted (its end is the look-ahead's known future).
    const longer = await generate(suite.page, { model: 'latent-erd', frames: 10, seed: 0, control: Array.from({ length: 40 }, () => [1, 0, 0]) });
    assert.equal(longer.frames, 10);
  });

  test('followPath with the latent ERD: closed loop from the path start, the generator\'s stats, deterministic, feet locked', async () => {
    const run = (o) => suite.page.evaluate(async (o) => {
      const m = await window.playground.followPath(o);
      return { frames: m.frames, fps: m.fps, joints: m.joints, positions: Array.from(m.positions), contacts: m.contacts.length, stats: m.stats };
    }, o);
    const a = await run({ model: 'latent-erd', points: BEND, gait: 'walk', seed: 1 });
    assert.deepEqual(Object.keys(a.stats).sort(), ['arcProgress', 'maxError', 'meanError', 'optimizeMs', 'skating', 'skatingBeforeLock', 'sliding', 'slidingBeforeLock']);
    for (const [k, v] of Object.entries(a.stats)) assert.ok(Number.isFinite(v), `${k} = ${v}`);
    assert.ok(a.frames > 0 && a.frames % ERD.pooling === 0, `${a.frames} frames, whole latent steps`);
    assert.equal(a.positions.length, a.frames * J * 3);
    assert.equal(a.contacts, a.frames * 2);
    assert.ok(a.stats.arcProgress >= 0 && a.stats.arcProgress <= 1);
    assert.ok(a.stats.meanError <= a.stats.maxError);
    assert.ok(Math.hypot(a.positions[0], a.positions[2]) < 0.5, 'starts near the first point');
    const b = await run({ model: 'latent-erd', points: BEND, gait: 'walk', seed: 1 });
    assert.deepEqual(b.positions, a.positions);
    const raw = await run({ model: 'latent-erd', points: BEND, gait: 'walk', seed: 1, footLock: false });
    assert.ok(Math.abs(raw.stats.skating - a.stats.skatingBeforeLock) < 1e-6, 'skating before the lock is the unlocked motion\'s');
    assert.ok(Math.abs(raw.stats.sliding - a.stats.slidingBeforeLock) < 1e-6, 'sliding before the lock is the unlocked motion\'s');
    assert.ok(a.stats.sliding < a.stats.slidingBeforeLock, `sliding ${a.stats.sliding} vs ${a.stats.slidingBeforeLock} before the lock`);
    const slow = await run({ model: 'latent-erd', points: BEND, seed: 1, speed: 0.8 });
    assert.notDeepEqual(slow.positions, a.positions, 'speed changes the walk');
    console.log(`# latent ERD followPath (placeholder models): ${JSON.stringify(a.stats)}`);
  });

  test('simulateControl with the latent ERD: one speed, heading and compute time per frame', async () => {
    const m = await suite.page.evaluate(async () => {
      const r = await window.playground.simulateControl({ model: 'latent-erd', seconds: 3, seed: 0, schedule: [{ t: 0, speed: 1.2, heading: 0 }, { t: 1, speed: 1.2, heading: Math.PI / 2 }] });
      return { frames: r.frames, fps: r.fps, speed: Array.from(r.speed), heading: Array.from(r.heading), computeMs: Array.from(r.computeMs), positions: r.positions.length, contacts: r.contacts.length, keys: Object.keys(r).sort() };
    });
    assert.equal(m.frames, 3 * ERD.fps);
    assert.deepEqual(m.keys, ['computeMs', 'contacts', 'fps', 'frames', 'heading', 'joints', 'parents', 'positions', 'speed']);
    assert.equal(m.speed.length, m.frames);
    assert.equal(m.heading.length, m.frames);
    assert.ok(m.computeMs.every((v) => v > 0 && Number.isFinite(v)));
    assert.ok(m.heading.every((h) => h > -Math.PI && h <= Math.PI));
    assert.equal(m.positions, m.frames * J * 3);
    assert.equal(m.contacts, m.frames * 2);
  });

  test('bad control, bad model and options of the other model are refused; the page stays as it was', async () => {
    const page = suite.page;
    await page.evaluate(async () => {
      const m = await window.playground.generate({ model: 'latent-erd', frames: 40, seed: 1 });
      window.playground.show(m, 'before');
    });
    const cases = [
      ['generate', { model: 'latent-erd', frames: 4, seed: 0, control: [[1, 0, 0]] }, /^generate: control has 1 frames; it needs at least one per frame \(4\)$/],
      ['generate', { model: 'latent-erd', frames: 2, seed: 0, control: [[1, 0, 0], [1, NaN, 0]] }, /^generate: control\[1\] must be a triple of finite numbers \[forward m\/s, sideways m\/s, turn rad\/s\], got \[1, NaN, 0\]$/],
      ['generate', { model: 'latent-erd', frames: 2, seed: 0, control: [[1, 0, 0], [1, 0, 40]] }, /^generate: control\[1\] \[1, 0, 40\] is out of range/],
      ['generate', { model: 'latent-erd', frames: 2, seed: 0, control: 'forward' }, /^generate: control must be an array of/],
      ['generate', { model: 'latent-erd', frames: 2, seed: 0, temperature: 0.5 }, /^generate: unknown option "temperature" for model "latent-erd" \(known: model, frames, seed, control, signal\)$/],
      ['generate', { model: 'manifold', frames: 2, seed: 0 }, /^generate: unknown model "manifold" \(available: .*latent-erd/],
      ['generate', { model: 'generator', frames: 2, seed: 0, control: [[1, 0, 0], [1, 0, 0]] }, /^generate: unknown option "control" for model "generator"/],
      ['followPath', { model: 'walker', points: BEND }, /^followPath: unknown model "walker" \(available: generator, style-generator, latent-erd, vae-lstm\)$/],
      ['followPath', { model: 'latent-erd', points: BEND, fitTolerance: 0.2 }, /^followPath: unknown option "fitTolerance" \(known: model, points, gait, seed, speed, footLock, signal\)$/],
      ['followPath', { model: 'latent-erd', points: BEND, speed: 12 }, /^followPath: speed must be a number above 0 and at most 4 m\/s, got 12$/],
      ['followPath', { points: BEND, speed: 1 }, /^followPath: unknown option "speed" \(known: model, points, gait, seed, fitTolerance, footLock, signal\)$/],
      ['followPath', { model: 'latent-erd', points: [[0, 0], [0, 0.2]] }, /^followPath: the path is 0\.20 m long; it must be at least 0\.5 m$/],
      ['simulateControl', { model: 7, seconds: 1, schedule: [{ t: 0, speed: 1, heading: 0 }] }, /^simulateControl: model must be one of "generator", "style-generator", "latent-erd", got 7$/],
      ['simulateControl', { model: 'latent-erd', seconds: 1, schedule: [{ t: 0, speed: 9, heading: 0 }] }, /speed must be a number from 0 to 4/],
    ];
    for (const [method, options, expected] of cases) {
      const r = await apiFailure(page, method, options);
      assert.match(String(r.message), expected, `${method}(${JSON.stringify(options)})`);
      assert.equal(r.lastError, r.message, 'the message is shown on the page');
      assert.equal(r.shown, 40, 'the motion shown stays');
    }
    assert.equal(await page.evaluate(() => window.playground.state().playing), true);
  });

  test('latent ERD requests cancel like the others: AbortError at once, nothing shown, the next call works', async () => {
    const r = await suite.page.evaluate(async () => {
      const pg = window.playground;
      const before = pg.lastError();
      const outcome = async (start) => {
        const c = new AbortController();
        const run = start(c.signal);
        c.abort();
        return run.then(() => ({ name: 'resolved' }), (e) => ({ name: e.name, message: e.message }));
      };
      const path = await outcome((signal) => pg.followPath({ model: 'latent-erd', points: [[0, 0], [0, 60]], signal }));
      const sim = await outcome((signal) => pg.simulateControl({ model: 'latent-erd', seconds: 300, schedule: [{ t: 0, speed: 1.2, heading: 0 }], signal }));
      const gen = await outcome((signal) => pg.generate({ model: 'latent-erd', frames: 50000, seed: 0, signal }));
      const next = await pg.generate({ model: 'latent-erd', frames: 8, seed: 0 });
      return { path, sim, gen, lastErrorUnchanged: pg.lastError() === before, next: next.frames };
    });
    assert.deepEqual(r.path, { name: 'AbortError', message: 'followPath: cancelled' });
    assert.deepEqual(r.sim, { name: 'AbortError', message: 'simulateControl: cancelled' });
    assert.deepEqual(r.gen, { name: 'AbortError', message: 'generate: cancelled' });
    assert.equal(r.lastErrorUnchanged, true, 'a cancel is not shown');
    assert.equal(r.next, 8);
  });

  test('parity in the browser: one ERD step and one decoder window within 1e-4; the fixture stream within 1e-4 (rows) and 1 mm', async () => {
    const s = REFERENCE.stream;
    const r = await suite.page.evaluate(async ({ step, decode, stream }) => {
      const { LatentErdClient } = await import('/runtime/latent_erd/latentErdClient.ts');
      const client = new LatentErdClient({ threads: 1 });
      try {
        await client.init();
        const p = await client.parity({ step: step.inputs, decode: { latent: decode.latent, steps: decode.steps } });
        const m = await client.generate({ seed: stream.seed, frames: stream.frames, control: stream.control, knownFuture: false, footLock: false });
        return {
          step: Object.fromEntries(Object.entries(p.step).map(([k, v]) => [k, Array.from(v)])),
          decode: Array.from(p.decode),
          rows: Array.from(m.rows), predicted: Array.from(m.predicted), roots: Array.from(m.roots), contacts: Array.from(m.contacts),
        };
      } finally {
        client.dispose();
      }
    }, { step: REFERENCE.step, decode: REFERENCE.decode, stream: s });
    for (const k of ['z_next', 'h_out', 'c_out']) assert.ok(worst(r.step[k], REFERENCE.step.outputs[k]) <= 1e-4, `step ${k}`);
    assert.ok(worst(r.decode, REFERENCE.decode.rows) <= 1e-4, 'decoder rows');
    const rows = worst(r.rows, s.rows), positions = worst(r.predicted, s.positions), roots = worst(r.roots, s.roots);
    console.log(`# latent ERD stream parity in the browser: rows ${rows.toExponential(2)}, positions ${positions.toExponential(2)} m, roots ${roots.toExponential(2)}`);
    assert.ok(rows <= 1e-4, `rows ${rows}`);
    assert.ok(positions <= 1e-3, `positions ${positions} m`);
    assert.ok(roots <= 1e-3, `roots ${roots}`);
    const [c0] = MANIFOLD.rows.contacts, D = MANIFOLD.rows.dim;
    const mismatched = s.contacts.filter((c, i) => c !== r.contacts[i] && Math.abs(s.rows[Math.floor(i / 2) * D + c0 + (i % 2)] - 0.5) > 1e-3);
    assert.equal(mismatched.length, 0, 'the same contacts');
  });
});
