// The latent ERD's runtime (web/runtime/latent_erd/latentErdCore.ts and the online stream web/model/latentStream.ts,
// the port of training/latent_erd/streaming.py) on the shipped models, run by onnxruntime-web's Node build
// (the same wasm runtime the browser worker uses): parity with tests/fixtures/latent_erd_reference.json (one
// ERD step, one decoder window, a whole stream from a seed), that the look-ahead matters, chunked streams,
// the skeleton fit and the foot lock, seeds, the control requests, and the model files' checks. Every
// number compared comes from the fixture or the model JSON: the models are replaced by retrained ones.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { randomControl } from '../../web/motion/control';
import {
  checkControlSignal,
  checkLatentErdPair,
  latentSeedIndex,
  parseLatentErdInfo,
  parseManifoldInfo,
  type LatentErdModel,
} from '../../web/model/latentErdInfo';
import { LatentErdCore } from '../../web/runtime/latent_erd/latentErdCore';
import { LatentErdRequests } from '../../web/runtime/latent_erd/latentErdRequests';
import { readRepoFile } from './corpus';
import { bytes, maxAbsDiff, ort, shippedSession } from './shippedModel';

interface Fixture {
  step: { inputs: { batch: number; z: number[]; control: number[]; h: number[]; c: number[] }; outputs: Record<'z_next' | 'h_out' | 'c_out', number[]> };
  decode: { latent: number[]; steps: number; rows: number[] };
  stream: { seed: number; lookahead: number; control: number[]; frames: number; rows: number[]; positions: number[]; roots: number[]; contacts: number[] };
}

/** As the other runtime parity tests: network outputs and rows within 1e-4, world positions within 1 mm over the stream. */
const PARITY = 1e-4;
const POSITION_TOLERANCE = 1e-3;

const erdJson = JSON.parse(readRepoFile('public/models/latent-erd.json'));
const manifoldJson = JSON.parse(readRepoFile('public/models/manifold.json'));
const erd = parseLatentErdInfo(erdJson, 'public/models/latent-erd.json');
const manifold = parseManifoldInfo(manifoldJson, 'public/models/manifold.json');
const model: LatentErdModel = { erd, manifold, decoderUrl: manifold.files.decoder };
const fixture = JSON.parse(readRepoFile('tests/fixtures/latent_erd_reference.json')) as Fixture;
const J = manifold.skeleton.joints.length;
const D = manifold.rows.dim;
const [contact0] = manifold.rows.contacts;

let core: LatentErdCore;

beforeAll(async () => {
  core = new LatentErdCore(await shippedSession(erd.file), model, ort.Tensor, 1, () => shippedSession(manifold.files.decoder));
  await core.check();
});

afterAll(() => core?.release());

/** The fixture's stream run by the page: its seed and control, guesses from the repeated control (known_future=False). */
function fixtureStream(lookahead = fixture.stream.lookahead) {
  const s = fixture.stream;
  return core.generate({ seed: s.seed, frames: s.frames, control: s.control, knownFuture: false, footLock: false }, undefined, { lookahead });
}

/** Contact bits must agree except where the decoded channel is within `margin` of the 0.5 threshold. */
function contactMismatches(got: ArrayLike<number>, want: ArrayLike<number>, rows: ArrayLike<number>, margin = 1e-3): number {
  let bad = 0;
  for (let i = 0; i < want.length; i++) {
    const value = rows[Math.floor(i / 2) * D + contact0 + (i % 2)];
    if (got[i] !== want[i] && Math.abs(value - 0.5) > margin) bad++;
  }
  return bad;
}

describe('latent ERD parity with the Python reference', () => {
  it('one ERD step at batch 2 matches onnxruntime within 1e-4', async () => {
    const { step } = await core.parity({ step: fixture.step.inputs });
    for (const name of ['z_next', 'h_out', 'c_out'] as const) {
      expect(step![name].length, name).toBe(fixture.step.outputs[name].length);
      expect(maxAbsDiff(step![name], fixture.step.outputs[name]), name).toBeLessThan(PARITY);
    }
  });

  it('one decoder window (2 × radius + 1 latent steps) gives the 4 rows of its centre step within 1e-4', async () => {
    expect(fixture.decode.steps).toBe(2 * erd.radius + 1);
    const { decode } = await core.parity({ decode: { latent: fixture.decode.latent, steps: fixture.decode.steps } });
    expect(decode!.length).toBe(erd.pooling * D);
    expect(maxAbsDiff(decode!, fixture.decode.rows)).toBeLessThan(PARITY);
  });

  it('the whole stream from the seed: rows within 1e-4, positions and roots within 1 mm, the same contacts', async () => {
    const s = fixture.stream;
    const m = await fixtureStream();
    expect(m.frames).toBe(s.frames);
    const rowsErr = maxAbsDiff(m.rows, s.rows);
    const posErr = maxAbsDiff(m.predicted, s.positions);
    const rootErr = maxAbsDiff(m.roots, s.roots);
    console.log(`# latent ERD stream parity: rows ${rowsErr.toExponential(2)}, positions ${posErr.toExponential(2)} m, roots ${rootErr.toExponential(2)}`);
    expect(rowsErr).toBeLessThan(PARITY);
    expect(posErr).toBeLessThan(POSITION_TOLERANCE);
    expect(rootErr).toBeLessThan(POSITION_TOLERANCE);
    expect(contactMismatches(m.contacts, s.contacts, s.rows)).toBe(0);
    // The contacts are the decoded channel > 0.5, and the control is what was asked for.
    for (let i = 0; i < m.contacts.length; i++) expect(m.contacts[i]).toBe(m.rows[Math.floor(i / 2) * D + contact0 + (i % 2)] > 0.5 ? 1 : 0);
    expect(maxAbsDiff(m.control, s.control)).toBeLessThan(1e-6);
  });

  it('the look-ahead guesses matter: the same stream without them, or with the known future, is another stream', async () => {
    const s = fixture.stream;
    expect(s.lookahead).toBeGreaterThan(0);
    const none = await fixtureStream(0);
    expect(maxAbsDiff(none.rows, s.rows)).toBeGreaterThan(100 * PARITY);
    // The fixture's control changes at 0.5 s and 0.8 s: seeing those steps coming changes the frames before them.
    const known = await core.generate({ seed: s.seed, frames: s.frames, control: s.control, footLock: false });
    expect(maxAbsDiff(known.rows, s.rows)).toBeGreaterThan(100 * PARITY);
  });
});

describe('latent ERD streams', () => {
  it('chunks of any size join up exactly into the whole; the same arguments give the same motion', async () => {
    const whole = await core.generate({ seed: 3, frames: 50 });
    const again = await core.generate({ seed: 3, frames: 50 });
    expect(bytes(again.positions)).toEqual(bytes(whole.positions));
    const stream = await core.createStream({ seed: 3 });
    const parts = [await core.advance(stream, 5), await core.advance(stream, 7), await core.advance(stream, 38)];
    expect(parts.map((p) => p.startFrame)).toEqual([0, 5, 12]);
    const joined = new Float32Array(whole.positions.length);
    let at = 0;
    for (const p of parts) {
      joined.set(p.positions, at);
      at += p.positions.length;
    }
    expect(bytes(joined)).toEqual(bytes(whole.positions));
  });

  it('without a control it follows randomControl(seed) and sees its future', async () => {
    const frames = 30;
    const steps = Math.ceil(frames / erd.pooling) + erd.lookahead;
    const control = Array.from(randomControl(7, steps * erd.pooling, erd.fps));
    const random = await core.generate({ seed: 7, frames });
    const given = await core.generate({ seed: 7, frames, control });
    expect(bytes(given.positions)).toEqual(bytes(random.positions));
    expect(maxAbsDiff(random.control, control.slice(0, frames * 3))).toBeLessThan(1e-6);
  });

  it('picks seed states by seed mod their count, among a gait category when asked', async () => {
    const n = erd.seeds.length;
    expect(latentSeedIndex(erd, 0)).toBe(0);
    expect(latentSeedIndex(erd, n + 2)).toBe(2);
    for (const gait of ['walk', 'run']) {
      const pool = erd.seeds.flatMap((s, i) => (s.category === gait ? [i] : []));
      if (!pool.length) continue;
      expect(latentSeedIndex(erd, 1, gait)).toBe(pool[1 % pool.length]);
      expect(erd.seeds[latentSeedIndex(erd, 5, gait)].category).toBe(gait);
    }
    expect(() => latentSeedIndex(erd, 0, 'crawl')).toThrow(/no "crawl" seeds/);
    const a = await core.generate({ seed: 0, frames: 8 });
    const b = await core.generate({ seed: n, frames: 8, control: Array.from(randomControl(0, 64, erd.fps)) });
    expect(b.seedIndex).toBe(a.seedIndex);
  });

  it('fits every frame to the skeleton (exact bone lengths, near the decoded points) and locks planted feet', async () => {
    const m = await core.generate({ seed: 1, frames: 60 });
    const raw = await core.generate({ seed: 1, frames: 60, footLock: false });
    const { parents, offsets } = core.skeleton;
    let worstBone = 0, meanShift = 0;
    for (let f = 0; f < 60; f++) {
      for (let j = 0; j < J; j++) {
        const o = (f * J + j) * 3;
        meanShift += Math.hypot(raw.positions[o] - raw.predicted[o], raw.positions[o + 1] - raw.predicted[o + 1], raw.positions[o + 2] - raw.predicted[o + 2]) / (60 * J);
        if (j === 0) continue;
        for (const p of [m.positions, raw.positions]) {
          const q = (f * J + parents[j]) * 3;
          const len = Math.hypot(p[o] - p[q], p[o + 1] - p[q + 1], p[o + 2] - p[q + 2]);
          worstBone = Math.max(worstBone, Math.abs(len - Math.hypot(offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2])));
        }
      }
    }
    expect(worstBone).toBeLessThan(1e-4);
    expect(meanShift).toBeLessThan(0.1);
    expect(bytes(m.predicted)).toEqual(bytes(raw.predicted));
    // The lock moves only legs; the hips stay where the decoder put them.
    for (let f = 0; f < 60; f++) expect(Array.from(m.positions.subarray(f * J * 3, f * J * 3 + 3))).toEqual(Array.from(raw.positions.subarray(f * J * 3, f * J * 3 + 3)));
    if (m.contacts.some((c) => c)) expect(bytes(m.positions)).not.toEqual(bytes(raw.positions));
  });

  it('rejects bad requests with clear messages', async () => {
    await expect(core.generate({ seed: 0, frames: 0 })).rejects.toThrow(/frames must be an integer from 1 to 100000/);
    await expect(core.generate({ seed: -1, frames: 4 })).rejects.toThrow(/seed must be an integer from 0 to 4294967295/);
    await expect(core.generate({ seed: 0, frames: 8, control: [1, 0, 0] })).rejects.toThrow(/control has 1 frames; it needs at least 8/);
    await expect(core.parity({ step: { batch: 1, z: [], control: [], h: [], c: [] } })).rejects.toThrow(/parity step inputs do not fit batch 1/);
    await expect(core.parity({})).rejects.toThrow(/parity needs/);
  });
});

describe('latent ERD control requests', () => {
  it('follows a path in closed loop from its start, the same way for the same seed, and stops', async () => {
    const requests = new LatentErdRequests(core);
    const points: [number, number][] = [[1, 2], [1, 5]];
    const fractions: number[] = [];
    const a = await requests.followPath({ points, gait: 'walk', seed: 2 }, (f) => fractions.push(f));
    expect(a.frames % erd.pooling).toBe(0);
    // Stopped at the frame cap at the latest: 2.5 × the time at 1.2 m/s, plus 2 s.
    expect(a.frames).toBeLessThanOrEqual(Math.ceil(((3 / 1.2) * 2.5 + 2) * erd.fps) + erd.pooling);
    expect(a.positions.length).toBe(a.frames * J * 3);
    expect(a.positions.every(Number.isFinite)).toBe(true);
    expect(a.stats.windows).toBe(a.frames / erd.pooling);
    expect(a.stats.particleSteps).toBe(a.stats.windows * (1 + erd.lookahead) + erd.seeds[0].latents.length - 1);
    for (const k of ['meanError', 'maxError', 'arcProgress', 'optimizeMs', 'skating', 'skatingBeforeLock'] as const) expect(Number.isFinite(a.stats[k]), k).toBe(true);
    expect(a.stats.meanError).toBeLessThanOrEqual(a.stats.maxError);
    expect(a.stats.arcProgress).toBeGreaterThanOrEqual(0);
    expect(a.stats.arcProgress).toBeLessThanOrEqual(1);
    expect(fractions.at(-1)).toBe(1);
    // The root starts on the path's first point facing along it; the path comes back where it was drawn.
    expect(a.roots[0]).toBeCloseTo(1, 9);
    expect(a.roots[1]).toBeCloseTo(2, 9);
    expect(a.roots[2]).toBeCloseTo(0, 9);
    expect(a.path[0]).toBeCloseTo(1, 5);
    expect(a.path[1]).toBeCloseTo(2, 5);
    // The first step's control heads along the path (+z) at the walking speed.
    expect(a.control[0]).toBeCloseTo(1.2, 6);
    const b = await requests.followPath({ points, gait: 'walk', seed: 2 }, () => undefined);
    expect(bytes(b.positions)).toEqual(bytes(a.positions));
    const raw = await requests.followPath({ points, gait: 'walk', seed: 2, footLock: false }, () => undefined);
    expect(raw.stats.skating).toBeCloseTo(a.stats.skatingBeforeLock, 9);
    const run = await requests.followPath({ points, gait: 'run', seed: 0, speed: 2 }, () => undefined);
    expect(run.control[0]).toBeCloseTo(2, 6);
    expect(erd.seeds[run.seedIndex].category).toBe('run');
    await expect(requests.followPath({ points, gait: 'walk', seed: 0, speed: 9 }, () => undefined)).rejects.toThrow(/speed must be a number above 0 and at most 4 m\/s, got 9/);
  });

  it('simulateControl steers each latent step toward the schedule: one value per frame', async () => {
    const requests = new LatentErdRequests(core);
    const m = await requests.simulate({ seconds: 1.5, seed: 0, schedule: [{ t: 0, speed: 1.2, heading: 0 }, { t: 0.5, speed: 1, heading: Math.PI / 2 }] }, () => undefined);
    expect(m.frames).toBe(Math.round(1.5 * erd.fps));
    for (const a of [m.speed, m.heading, m.targetSpeed, m.targetHeading, m.computeMsPerFrame]) expect(a.length).toBe(m.frames);
    expect(m.batchFrames.reduce((x, y) => x + y, 0)).toBe(m.frames);
    expect(m.targetHeading[0]).toBe(0);
    expect(m.targetHeading[m.frames - 1]).toBeCloseTo(Math.PI / 2, 6);
    expect(m.computeMsPerFrame.every((v) => v > 0)).toBe(true);
    // Turning toward +x: the control's turn is positive in the first step after the target changes.
    const changed = m.targetHeading.findIndex((h) => h > 0);
    expect(changed).toBeGreaterThan(0);
    expect(m.control[changed * 3 + 2]).toBeGreaterThan(0);
    expect(m.heading.every((h) => h > -Math.PI && h <= Math.PI)).toBe(true);
  });

  it('live control: a started stream pulled in steps continues, steered toward the target', async () => {
    const requests = new LatentErdRequests(core);
    await expect(requests.controlPull({ frames: 4, speed: 1, heading: 0 })).rejects.toThrow(/no control stream/);
    const info = await requests.controlStart({ seed: 1, gait: 'walk' });
    expect(erd.seeds[info.seedIndex].category).toBe('walk');
    const a = await requests.controlPull({ frames: 4, speed: 1.2, heading: 0 });
    const b = await requests.controlPull({ frames: 6, speed: 1.2, heading: 1 });
    expect([a.startFrame, b.startFrame]).toEqual([0, 4]);
    expect(b.frames).toBe(6);
    await expect(requests.controlPull({ frames: 13, speed: 1, heading: 0 })).rejects.toThrow(/frames must be an integer from 1 to 12/);
    await expect(requests.controlPull({ frames: 4, speed: 9, heading: 0 })).rejects.toThrow(/speed must be a number from 0 to 4/);
  });
});

describe('latent ERD model files', () => {
  it('name the file and the bad field', () => {
    expect(() => parseLatentErdInfo({ ...erdJson, lookahead: -1 }, 'latent-erd.json')).toThrow('latent-erd.json: lookahead must be an integer ≥ 0, got -1');
    expect(() => parseLatentErdInfo({ ...erdJson, inputs: ['x'] }, 'latent-erd.json')).toThrow(/latent-erd.json: inputs is \[x\], expected \[z,control,h,c\]/);
    expect(() => parseLatentErdInfo({ ...erdJson, control_dim: 3 }, 'latent-erd.json')).toThrow(/control_dim is 3 but 4 frames/);
    const seeds = [{ ...erdJson.seeds[0], latents: [[1, 2]] }];
    expect(() => parseLatentErdInfo({ ...erdJson, seeds }, 'latent-erd.json')).toThrow(/seeds\[0\]\.controls must hold 1 step controls|seeds\[0\]\.latents\[0\] has 2 values/);
    expect(() => parseManifoldInfo({ ...manifoldJson, normalisation: { mean: [], std: [] } }, 'manifold.json')).toThrow(/manifold.json: normalisation.mean has 0 values, expected 80/);
    expect(() => parseManifoldInfo({ ...manifoldJson, rows: { ...manifoldJson.rows, contacts: [78, 81] } }, 'manifold.json')).toThrow(/rows.contacts is \[78, 81\]/);
    expect(() => checkLatentErdPair({ ...erd, latent: 7 }, manifold)).toThrow(/latent-erd.json: latent is 7 but manifold.json has 256/);
  });

  it('control signals are checked frame by frame', () => {
    expect(Array.from(checkControlSignal([[1, 0, 0.5], [1.2, 0.1, 0]], 2))).toEqual([1, 0, 0.5, 1.2, 0.1, 0]);
    expect(() => checkControlSignal('fast', 2)).toThrow(/control must be an array of \[forward m\/s, sideways m\/s, turn rad\/s\] triples, one per frame, got "fast"/);
    expect(() => checkControlSignal([[1, 0, 0]], 2)).toThrow('control has 1 frames; it needs at least one per frame (2)');
    expect(() => checkControlSignal([[1, 0, 0], [1, NaN, 0]], 2)).toThrow(/control\[1\] must be a triple of finite numbers/);
    expect(() => checkControlSignal([[1, 0, 0], [1, 0]], 2)).toThrow(/control\[1\] must be a triple/);
    expect(() => checkControlSignal([[1, 0, 0], [40, 0, 0]], 2)).toThrow(/control\[1\] \[40, 0, 0\] is out of range: forward and sideways within ±5 m\/s, turn within ±6.28 rad\/s/);
  });
});
