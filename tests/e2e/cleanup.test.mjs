// End-to-end tests of motion clean-up (issue 16) in the page: playground.denoise with each method on a held-out
// CMU clip made noisy with playground.addNoise (the result keeps the clip's skeleton and has contacts; the scene is
// left as it was), bad options and a skeleton that cannot be mapped rejected with their reasons. Run with
// `node --test tests/e2e/cleanup.test.mjs`.
import assert from 'node:assert/strict';
import { describe, test } from 'node:test';
import { corpusText, usePlayground } from './harness.mjs';

// 35_13 is held out of the generator's training (generator.json training.valid_files).
const AMC = corpusText('cmu/amc/35_13.amc.gz');
const ASF = corpusText('cmu/asf/35.asf');

describe('motion clean-up', () => {
  const suite = usePlayground();

  /** Imports the clip, shows it, adds noise and cleans it with `options` (without the joints from `cut` down, when given); returns plain data about the result. */
  function cleanUp(options, cut) {
    return suite.page.evaluate(
      async ({ amc, asf, options, cut }) => {
        const pg = window.playground;
        const clip = await pg.importMotion(amc, 'amc', asf);
        pg.show(clip, 'clip');
        const shown = pg.current();
        let noisy = pg.addNoise(clip, { jitter: 0.02, outliers: 0.01, seed: 2 });
        if (cut) {
          const gone = new Set();
          noisy.parents.forEach((p, j) => (noisy.joints[j] === cut || gone.has(p)) && gone.add(j));
          const kept = noisy.joints.flatMap((_, j) => (gone.has(j) ? [] : [j]));
          const J = noisy.joints.length;
          const positions = new Float32Array(noisy.frames * kept.length * 3);
          for (let f = 0; f < noisy.frames; f++) kept.forEach((j, k) => positions.set(noisy.positions.subarray((f * J + j) * 3, (f * J + j) * 3 + 3), (f * kept.length + k) * 3));
          noisy = { ...noisy, joints: kept.map((j) => noisy.joints[j]), parents: kept.map((j) => kept.indexOf(noisy.parents[j])), positions };
        }
        const boneLengths = (m, f) => m.parents.map((p, j) => (p < 0 ? 0 : Math.hypot(...[0, 1, 2].map((a) => m.positions[(f * m.joints.length + j) * 3 + a] - m.positions[(f * m.joints.length + p) * 3 + a]))));
        try {
          const m = await pg.denoise(noisy, options);
          const first = boneLengths(m, 0), last = boneLengths(m, m.frames - 1);
          let noise = 0, error = 0;
          for (let i = 0; i < clip.positions.length; i++) {
            noise += Math.abs(noisy.positions[i] - clip.positions[i]);
            error += Math.abs(m.positions[i] - clip.positions[i]);
          }
          return {
            joints: m.joints, parents: m.parents, fps: m.fps, frames: m.frames, contacts: m.contacts.length, stats: m.stats,
            clipJoints: clip.joints, clipParents: clip.parents, clipFrames: clip.frames, clipFps: clip.fps,
            boneDrift: Math.max(...first.map((l, j) => Math.abs(l - last[j]))),
            finite: Array.from(m.positions).every(Number.isFinite),
            errorToNoise: error / noise,
            sceneKept: pg.current() === shown,
          };
        } catch (e) {
          return { message: e.message, name: e.name, lastError: pg.lastError(), sceneKept: pg.current() === shown };
        }
      },
      { amc: AMC, asf: ASF, options, cut },
    );
  }

  for (const method of ['map', 'manifold', 'lowpass']) {
    test(`denoise with ${method} keeps the clip's skeleton and returns contacts, leaving the scene as it was`, async () => {
      const r = await cleanUp({ method });
      assert.equal(r.message, undefined, `no error: ${r.message}`);
      assert.deepEqual(r.joints, r.clipJoints);
      assert.deepEqual(r.parents, r.clipParents);
      assert.equal(r.frames, r.clipFrames);
      assert.equal(r.fps, r.clipFps);
      assert.equal(r.contacts, r.frames * 2);
      assert.equal(r.stats.method, method);
      assert.ok(r.finite, 'every position is finite');
      // map and manifold give every bone one length; lowpass filters positions and lets them vary a little.
      if (method !== 'lowpass') assert.ok(r.boneDrift < 1e-4, `bone lengths constant (drift ${r.boneDrift} m)`);
      if (method === 'lowpass') assert.ok(r.errorToNoise < 0.6, `lowpass removes jitter (error / noise ${r.errorToNoise})`);
      assert.ok(r.sceneKept, 'denoise does not change what is shown');
    });
  }

  test('bad options reject with a reason naming the option, and the scene stays', async () => {
    for (const [options, reason] of [
      [{ method: 'median' }, /denoise: .*method must be one of map, manifold, lowpass/],
      [{ method: 'map', sigmaRoot: -1 }, /sigmaRoot must be a number of metres/],
      [{ method: 'map', strength: 2 }, /unknown option "strength"/],
      ['map', /options must be an object/],
    ]) {
      const r = await cleanUp(options);
      assert.match(r.message ?? '', reason);
      assert.equal(r.lastError, r.message, 'the message is shown on the page');
      assert.ok(r.sceneKept);
    }
  });

  test('a skeleton that is not a humanoid (one leg) is refused, naming what is missing, and the scene stays', async () => {
    const r = await cleanUp({ method: 'map' }, 'rhipjoint');
    assert.match(r.message ?? '', /not a humanoid the playground can map: no two legs/);
    assert.ok(r.sceneKept);
  });
});
