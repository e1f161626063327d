// The dance step loop (web/runtime/aclstm/danceCore.ts) on the shipped acLSTM model, run by onnxruntime-web's
// Node build (the same wasm runtime the browser worker uses): one-step parity with the Python
// onnxruntime fixture, determinism, streams that continue exactly, fitted frames at exact bone lengths, and
// feet planted by their contact labels locked in place.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { DanceCore, STEPS_PER_CALL } from '../../web/runtime/aclstm/danceCore';
import { denormalise } from '../../web/model/sampler';
import { parseDanceInfo, seedsOfStyle } from '../../web/runtime/aclstm/danceModel';
import { readRepoFile } from './corpus';
import { bytes, maxAbsDiff, ort, shippedSession } from './shippedModel';

const info = parseDanceInfo(JSON.parse(readRepoFile('public/models/aclstm.json')), 'public/models/aclstm.json');
interface ReferenceCall {
  inputs: { batch: number; steps: number; x: number[]; style: number[]; h: number[]; c: number[] };
  outputs: Record<'ys' | 'h_out' | 'c_out', number[]>;
}
const reference = JSON.parse(readRepoFile('tests/fixtures/aclstm_reference.json')) as { step: ReferenceCall; steps: ReferenceCall };
const J = info.skeleton.joints.length;

let core: DanceCore;

beforeAll(async () => {
  core = new DanceCore(await shippedSession(info.file), info, ort.Tensor);
  await core.check();
});

afterAll(() => core?.release());


describe('DanceCore', () => {
  it.each(['step', 'steps'] as const)('matches Python onnxruntime on the fixture %s call within 1e-4', async (which) => {
    const call = reference[which];
    const { outputs } = await core.parity(call.inputs);
    for (const name of ['ys', 'h_out', 'c_out'] as const) {
      expect(outputs[name].length, name).toBe(call.outputs[name].length);
      expect(maxAbsDiff(outputs[name], call.outputs[name]), name).toBeLessThan(1e-4);
    }
  });

  it('gives the same frames, bit for bit, whether a call runs one step or many', async () => {
    const frames = 2 * STEPS_PER_CALL + 5;
    const chunk = await core.generate({ style: 'indian', seed: 1, frames });
    const stream = await core.createStream({ style: 'indian', seed: 1 });
    const { D } = { D: info.onnx.dim };
    const features = new Float32Array(frames * D);
    let { x, h, c } = stream;
    for (let t = 0; t < frames; t++) {
      denormalise(x, core.mean, core.std, features.subarray(t * D, (t + 1) * D));
      ({ ys: x, h_out: h, c_out: c } = await core.step(1, x, stream.style, h, c, 1));
    }
    expect(bytes(chunk.features)).toEqual(bytes(features));
  });

  it('gives identical frames for the same style and seed, other frames for another seed motion', async () => {
    const a = await core.generate({ style: 'salsa', seed: 0, frames: 30 });
    const b = await core.generate({ style: 'salsa', seed: 0, frames: 30 });
    const count = seedsOfStyle(info, 'salsa').length;
    const wrapped = await core.generate({ style: 'salsa', seed: count, frames: 30 });
    const other = await core.generate({ style: 'salsa', seed: 1, frames: 30 });
    expect(bytes(a.positions)).toEqual(bytes(b.positions));
    expect(bytes(wrapped.positions)).toEqual(bytes(a.positions));
    expect(wrapped.seedIndex).toBe(a.seedIndex);
    expect(bytes(other.positions)).not.toEqual(bytes(a.positions));
    expect(info.seeds[a.seedIndex].style).toBe('salsa');
  });

  it('continues a stream exactly where the previous pull stopped', async () => {
    const whole = await core.generate({ style: 'martial', seed: 2, frames: 50 });
    const stream = await core.createStream({ style: 'martial', seed: 2 });
    const first = await core.advance(stream, 20);
    const rest = await core.advance(stream, 30);
    expect(rest.startFrame).toBe(20);
    const joined = new Float32Array(whole.positions.length);
    joined.set(first.positions);
    joined.set(rest.positions, first.positions.length);
    expect(bytes(joined)).toEqual(bytes(whole.positions));
  });

  it('fits every frame to the skeleton: exact bone lengths, close to the network points', async () => {
    const m = await core.generate({ style: 'indian', seed: 0, frames: 120 });
    expect(m.positions.length).toBe(120 * J * 3);
    expect(m.positions.every(Number.isFinite)).toBe(true);
    let worstBone = 0;
    let meanShift = 0;
    for (let f = 0; f < 120; f++) {
      for (let j = 0; j < J; j++) {
        const o = (f * J + j) * 3;
        meanShift += Math.hypot(m.positions[o] - m.predicted[o], m.positions[o + 1] - m.predicted[o + 1], m.positions[o + 2] - m.predicted[o + 2]) / (120 * J);
        if (j === 0) continue;
        const p = (f * J + info.skeleton.parents[j]) * 3;
        const len = Math.hypot(m.positions[o] - m.positions[p], m.positions[o + 1] - m.positions[p + 1], m.positions[o + 2] - m.positions[p + 2]);
        const want = Math.hypot(...info.skeleton.offsets.slice(j * 3, j * 3 + 3));
        worstBone = Math.max(worstBone, Math.abs(len - want));
      }
    }
    expect(worstBone).toBeLessThan(1e-4);
    expect(meanShift).toBeLessThan(0.05);
    // The first frame follows the seed, whose root ends over the origin.
    expect(Math.hypot(m.positions[0], m.positions[2])).toBeLessThan(0.05);
  });

  it('labels contacts from the feet and locks planted feet: the toe tips of settled contacts stay put', async () => {
    const settled: number[] = [], free: number[] = [], rawSettled: number[] = [];
    const toes = ['lFoot_end', 'rFoot_end'].map((n) => info.skeleton.joints.indexOf(n));
    for (const style of ['indian', 'martial']) {
      for (const seed of [0, 1, 5]) {
        const m = await core.generate({ style, seed, frames: 300 });
        expect(m.contacts.length).toBe(300 * 2);
        for (let f = 4; f < 300; f++) {
          for (let side = 0; side < 2; side++) {
            const a = ((f - 1) * J + toes[side]) * 3, b = (f * J + toes[side]) * 3;
            const step = Math.hypot(m.positions[b] - m.positions[a], m.positions[b + 2] - m.positions[a + 2]);
            let held = true;
            for (let k = 0; k <= 4; k++) held &&= m.contacts[(f - k) * 2 + side] === 1;
            (held ? settled : free).push(step);
            if (held) rawSettled.push(Math.hypot(m.predicted[b] - m.predicted[a], m.predicted[b + 2] - m.predicted[a + 2]));
          }
        }
      }
    }
    // Both kinds occur; settled toes do not move, except where the network's root glides away from a resting foot
    // faster than the leg can reach (measured with the int8 model: 77 of 2,083 frame pairs over these six dances,
    // dragged at the body's pace: footLock.ts; salsa's gliding root drags more, 152 of 582 for seed 5).
    expect(settled.length).toBeGreaterThan(600);
    expect(free.length).toBeGreaterThan(120);
    expect(settled.filter((d) => d > 1e-5).length).toBeLessThan(0.1 * settled.length);
    // The network's own points do slide there (the lock is not idle).
    expect(rawSettled.reduce((x, y) => x + y, 0) / rawSettled.length).toBeGreaterThan(0.002);
  });

  it('rejects unknown styles, bad seeds and bad frame counts', async () => {
    await expect(core.generate({ style: 'tango', seed: 0, frames: 1 })).rejects.toThrow('unknown style "tango" (styles: salsa, indian, martial)');
    await expect(core.generate({ style: 'salsa', seed: -1, frames: 1 })).rejects.toThrow(/seed must be an integer ≥ 0/);
    await expect(core.generate({ style: 'salsa', seed: 0, frames: 0 })).rejects.toThrow(/frames must be an integer from 1 to 100000/);
    await expect(core.parity({ batch: 1, x: [], style: [], h: [], c: [] })).rejects.toThrow(/parity inputs do not fit batch 1/);
  });
});
