// A sampled dance model (issue 42: `head: "mdn"`, the phrase sampler and the output filter in the graph) in
// DanceCore, on a fake session that runs the interface's step rule in JavaScript (danceMdnFake.ts): the JSON's
// checks, what each call is fed (warm-up, the sampler's state, the stream's seeded random numbers, the style's
// settings), what is drawn (the filtered display) and fed back (ys), and the same dance for the same style and seed
// however the frames are split into calls.
import { describe, expect, it } from 'vitest';
import { DanceCore, drawStepRandoms, STEPS_PER_CALL } from '../../web/runtime/aclstm/danceCore';
import { DanceInfoError, isSampledDance, parseDanceInfo, seedsOfStyle, type DanceInfo } from '../../web/runtime/aclstm/danceModel';
import { denormalise } from '../../web/model/sampler';
import { Rng } from '../../web/motion/random';
import { readRepoFile } from './corpus';
import { fakeMdnInfo, fakeMdnSession, firstBitDifference, FAKE_COMPONENTS, FAKE_HIDDEN } from './danceMdnFake';
import { ort } from './shippedModel';

const info = parseDanceInfo(fakeMdnInfo(), 'fake-mdn.json');
const D = info.onnx.dim;
const SEED_FRAMES = info.features.seed_frames;

function fakeCore(model: DanceInfo = info) {
  const session = fakeMdnSession(model);
  return { core: new DanceCore(session, model, ort.Tensor), calls: session.calls };
}

const mean = Float32Array.from(info.normalisation.mean), std = Float32Array.from(info.normalisation.std);
/** A seed frame normalised as the core does it (with float32 mean and std). */
const normalise = (frame: number[]) => Float32Array.from(frame, (v, d) => (v - mean[d]) / std[d]);
const ints = (a: ArrayLike<bigint>) => Array.from(a, Number);

describe('parseDanceInfo, sampled models', () => {
  it('reads head "mdn", its components and per-style sampling; a model without head is not sampled', () => {
    expect(isSampledDance(info)).toBe(true);
    expect(info.components).toBe(FAKE_COMPONENTS);
    expect(info.sampling!.params.indian.max_hold).toBe(20);
    expect(info.sampling!.filter.martial.a).toEqual([1, 0.6202041, 0.24040821]);
    const shipped = parseDanceInfo(JSON.parse(readRepoFile('public/models/aclstm.json')), 'aclstm.json');
    expect(isSampledDance(shipped)).toBe(false);
    // The sampled graph's names go by name: any order is accepted.
    const reordered = fakeMdnInfo();
    reordered.onnx.inputs.reverse();
    reordered.onnx.outputs.reverse();
    expect(() => parseDanceInfo(reordered, 'test.json')).not.toThrow();
  });

  it('names the first bad field of a malformed sampled model', () => {
    const broken = (edit: (j: Record<string, any>) => void) => {
      const j = fakeMdnInfo();
      edit(j);
      return () => parseDanceInfo(j, 'test.json');
    };
    const p = (j: Record<string, any>) => j.sampling.params;
    const f = (j: Record<string, any>) => j.sampling.filter;
    expect(broken(() => undefined)).not.toThrow();
    expect(broken((j) => (j.head = 'gauss'))).toThrow(/test\.json: head must be "mdn" or left out, got "gauss"/);
    expect(broken((j) => delete j.components)).toThrow(/components must be a finite number/);
    expect(broken((j) => (j.components = 1))).toThrow(/components must be at least 2 for head "mdn", got 1/);
    expect(broken((j) => delete j.sampling)).toThrow(/sampling must be an object/);
    expect(broken((j) => (j.sampling.rule = 'frame'))).toThrow(/sampling\.rule must be "phrase", got "frame"/);
    expect(broken((j) => delete p(j).indian)).toThrow(/sampling\.params\.indian must be an object/);
    expect(broken((j) => (p(j).tango = p(j).salsa))).toThrow(/sampling\.params has "tango", which is not a style \(styles: salsa, indian, martial\)/);
    expect(broken((j) => (p(j).salsa.temperature = -0.1))).toThrow(/sampling\.params\.salsa\.temperature must be ≥ 0, got -0\.1/);
    expect(broken((j) => delete p(j).salsa.temperature)).toThrow(/sampling\.params\.salsa\.temperature must be a finite number/);
    expect(broken((j) => (p(j).martial.rho = 1))).toThrow(/sampling\.params\.martial\.rho must be from 0 up to \(not including\) 1, got 1/);
    expect(broken((j) => (p(j).martial.threshold = 1.2))).toThrow(/sampling\.params\.martial\.threshold must be from 0 up to \(not including\) 1/);
    expect(broken((j) => (p(j).indian.max_hold = 0))).toThrow(/sampling\.params\.indian\.max_hold must be an integer ≥ 1, got 0/);
    expect(broken((j) => (p(j).indian.min_hold = 2.5))).toThrow(/sampling\.params\.indian\.min_hold must be an integer ≥ 0, got 2\.5/);
    expect(broken((j) => (p(j).indian.min_hold = 21))).toThrow(/sampling\.params\.indian\.min_hold \(21\) must not exceed max_hold \(20\)/);
    expect(broken((j) => delete f(j).martial)).toThrow(/sampling\.filter\.martial must be an object/);
    expect(broken((j) => (f(j).salsa.cutoff_hz = 15))).toThrow(/sampling\.filter\.salsa\.cutoff_hz must be above 0 and below half the frame rate \(15 Hz\), got 15/);
    expect(broken((j) => f(j).salsa.b.pop())).toThrow(/sampling\.filter\.salsa\.b has 2 values, expected 3/);
    expect(broken((j) => (f(j).salsa.a[0] = 2))).toThrow(/sampling\.filter\.salsa\.a\[0\] must be 1/);
    expect(broken((j) => (f(j).salsa.a = [1, -2.1, 1.2]))).toThrow(/sampling\.filter\.salsa\.a = \[1,-2\.1,1\.2\] is not a stable filter/);
    expect(broken((j) => (j.onnx.inputs = j.onnx.inputs.filter((n: string) => n !== 'uniforms')))).toThrow(
      /onnx\.inputs is \[.*\], expected \[.*\] in any order \(missing uniforms\)/,
    );
    expect(broken((j) => (j.onnx.outputs = ['ys', 'h_out', 'c_out']))).toThrow(/onnx\.outputs .* \(missing display, held_out/);
    // A deterministic model (no head) keeps its exact names and takes no sampling fields.
    expect(broken((j) => delete j.head)).toThrow(/components is only read with head "mdn", and there is no head/);
    expect(
      broken((j) => {
        delete j.head;
        delete j.components;
      }),
    ).toThrow(/sampling is only read with head "mdn"/);
    expect(
      broken((j) => {
        for (const k of ['head', 'components', 'sampling']) delete j[k];
      }),
    ).toThrow(/onnx\.inputs is \[.*\], expected \[x,style,h,c,steps\]/);
    expect(broken((j) => (j.head = 'mdn '))).toThrow(DanceInfoError);
    // The exporter's onnx block also names the head and K: they must agree with the file's.
    expect(broken((j) => (j.onnx.components = FAKE_COMPONENTS))).not.toThrow();
    expect(broken((j) => (j.onnx.components = 9))).toThrow(/onnx\.components is 9 but components is 4/);
    expect(broken((j) => (j.onnx.head = 'mean'))).toThrow(/onnx\.head is "mean" but the file's head is "mdn"/);
    const shipped = JSON.parse(readRepoFile('public/models/aclstm.json'));
    shipped.onnx.head = 'mean';
    expect(() => parseDanceInfo(shipped, 'test.json')).not.toThrow();
    shipped.onnx.head = 'mdn';
    expect(() => parseDanceInfo(shipped, 'test.json')).toThrow(/onnx\.head is "mdn" but the file's head is not "mdn"/);
  });
});

describe('DanceCore, sampled model (fake session)', () => {
  it('says it samples, and refuses the deterministic step', async () => {
    const { core } = fakeCore();
    await core.check();
    expect(core.describe(0).sampled).toBe(true);
    await expect(core.step(1, new Float32Array(D), new Float32Array(3), new Float32Array(FAKE_HIDDEN), new Float32Array(FAKE_HIDDEN), 1)).rejects.toThrow(
      /samples its frames \(head "mdn"\)/,
    );
  });

  it('warms up on the seed frames, then feeds the sampler fresh state, the stream’s seeded randoms and the style’s settings', async () => {
    const { core, calls } = fakeCore();
    const seed = 3;
    const stream = await core.createStream({ style: 'indian', seed });
    const seedFrames = info.seeds[stream.seedIndex].frames;
    // Warm-up: every seed frame but the last, one step each, h and c carried.
    expect(calls.length).toBe(SEED_FRAMES - 1);
    calls.forEach((call, k) => {
      expect(Number((call.feeds.steps.data as BigInt64Array)[0])).toBe(1);
      expect(firstBitDifference(call.feeds.x.data as Float32Array, normalise(seedFrames[k]))).toBe(-1);
      if (k > 0) expect(firstBitDifference(call.feeds.h.data as Float32Array, calls[k - 1].outputs.h_out.data as Float32Array)).toBe(-1);
    });

    const frames = STEPS_PER_CALL + 8;
    const chunk = await core.advance(stream, frames);
    const [first, second] = calls.slice(SEED_FRAMES - 1);
    expect(calls.length).toBe(SEED_FRAMES + 1);
    const last = normalise(seedFrames[SEED_FRAMES - 1]);
    const feed = (call: typeof first, name: string) => call.feeds[name].data as Float32Array;
    // The first sampled call: the last seed frame in, nothing held, the filter at rest on the last seed frame.
    expect(Number((first.feeds.steps.data as BigInt64Array)[0])).toBe(STEPS_PER_CALL);
    expect(firstBitDifference(feed(first, 'x'), last)).toBe(-1);
    expect(firstBitDifference(feed(first, 'h'), calls[SEED_FRAMES - 2].outputs.h_out.data as Float32Array)).toBe(-1);
    expect(ints(first.feeds.held.data as BigInt64Array)).toEqual([-1]);
    expect(ints(first.feeds.age.data as BigInt64Array)).toEqual([0]);
    for (let i = 0; i < 4; i++) expect(firstBitDifference(feed(first, 'filt').subarray(i * D, (i + 1) * D), last)).toBe(-1);
    // Randoms: Rng(seed)'s first D normals are the wander, then per step one uniform and D normals.
    const rng = new Rng(seed);
    const wander = Float32Array.from({ length: D }, () => rng.normal());
    expect(firstBitDifference(feed(first, 'wander'), wander)).toBe(-1);
    const a = drawStepRandoms(rng, STEPS_PER_CALL, D), b = drawStepRandoms(rng, 8, D);
    expect(firstBitDifference(feed(first, 'uniforms'), a.uniforms)).toBe(-1);
    expect(firstBitDifference(feed(first, 'normals'), a.normals)).toBe(-1);
    expect(firstBitDifference(feed(second, 'uniforms'), b.uniforms)).toBe(-1);
    expect(firstBitDifference(feed(second, 'normals'), b.normals)).toBe(-1);
    expect(a.uniforms.every((u) => u >= 0 && u < 1)).toBe(true);
    // The style's settings, per row.
    const p = info.sampling!.params.indian, flt = info.sampling!.filter.indian;
    for (const call of [first, second]) {
      expect(Array.from(feed(call, 'temperature'))).toEqual([Math.fround(p.temperature)]);
      expect(Array.from(feed(call, 'rho'))).toEqual([Math.fround(p.rho)]);
      expect(Array.from(feed(call, 'threshold'))).toEqual([Math.fround(p.threshold)]);
      expect(ints(call.feeds.max_hold.data as BigInt64Array)).toEqual([p.max_hold]);
      expect(ints(call.feeds.min_hold.data as BigInt64Array)).toEqual([p.min_hold]);
      expect(Array.from(feed(call, 'filter_b'))).toEqual(flt.b.map(Math.fround));
      expect(Array.from(feed(call, 'filter_a'))).toEqual(flt.a.slice(1).map(Math.fround));
    }
    // The second call continues from the first's outputs: ys fed back (not display), every state carried.
    const out = (name: string) => first.outputs[name].data as Float32Array;
    expect(firstBitDifference(feed(second, 'x'), out('ys').slice((STEPS_PER_CALL - 1) * D))).toBe(-1);
    for (const [input, output] of [['h', 'h_out'], ['c', 'c_out'], ['wander', 'wander_out'], ['filt', 'filt_out']]) {
      expect(firstBitDifference(feed(second, input), out(output)), input).toBe(-1);
    }
    expect(first.feeds.held.data).not.toBe(undefined);
    expect(ints(second.feeds.held.data as BigInt64Array)).toEqual(ints(first.outputs.held_out.data as BigInt64Array));
    expect(ints(second.feeds.age.data as BigInt64Array)).toEqual(ints(first.outputs.age_out.data as BigInt64Array));
    // What is drawn is the filtered display, which differs from the draws that are fed back.
    const display = new Float32Array(frames * D), ys = new Float32Array(frames * D);
    display.set(out('display'));
    display.set(second.outputs.display.data as Float32Array, STEPS_PER_CALL * D);
    ys.set(out('ys'));
    ys.set(second.outputs.ys.data as Float32Array, STEPS_PER_CALL * D);
    expect(firstBitDifference(chunk.features, denormalise(display, core.mean, core.std))).toBe(-1);
    expect(firstBitDifference(chunk.features, denormalise(ys, core.mean, core.std))).not.toBe(-1);
    expect(chunk.positions.every(Number.isFinite)).toBe(true);
  });

  it('gives the same dance for the same style and seed, however the frames are split into calls', async () => {
    const frames = 2 * STEPS_PER_CALL + 11;
    const whole = await fakeCore().core.generate({ style: 'salsa', seed: 5, frames });
    const { core } = fakeCore();
    const stream = await core.createStream({ style: 'salsa', seed: 5 });
    const chunks = [];
    for (const n of [1, STEPS_PER_CALL + 3, 7, frames - STEPS_PER_CALL - 11]) chunks.push(await core.advance(stream, n));
    const features = new Float32Array(frames * D), positions = new Float32Array(whole.positions.length);
    let at = 0;
    for (const c of chunks) {
      expect(c.startFrame).toBe(at);
      features.set(c.features, at * D);
      positions.set(c.positions, (at * whole.positions.length) / frames);
      at += c.frames;
    }
    expect(at).toBe(frames);
    expect(firstBitDifference(features, whole.features)).toBe(-1);
    expect(firstBitDifference(positions, whole.positions)).toBe(-1);
  });

  it('draws another dance for another seed, even one with the same seed motion', async () => {
    const { core } = fakeCore();
    const count = seedsOfStyle(info, 'martial').length;
    const a = await core.generate({ style: 'martial', seed: 1, frames: 40 });
    const again = await core.generate({ style: 'martial', seed: 1, frames: 40 });
    const sameMotion = await core.generate({ style: 'martial', seed: 1 + count, frames: 40 });
    expect(firstBitDifference(again.features, a.features)).toBe(-1);
    expect(sameMotion.seedIndex).toBe(a.seedIndex);
    expect(firstBitDifference(sameMotion.features, a.features)).not.toBe(-1);
  });

  it('checks raw parity inputs of a sampled model, and runs them', async () => {
    const { core } = fakeCore();
    const B = 2, steps = 3, H = FAKE_HIDDEN;
    const inputs = {
      batch: B, steps, x: new Array(B * D).fill(0.1), style: [1, 0, 0, 0, 0, 1], h: new Array(B * H).fill(0), c: new Array(B * H).fill(0),
      held: [-1, 2], age: [0, 4], wander: new Array(B * D).fill(0.5), temperature: [0.3, 0.2], rho: [0.9, 0.95], threshold: [0.1, 0.15],
      max_hold: [12, 8], min_hold: [3, 2], uniforms: [0.1, 0.9, 0.5, 0.5, 0.99, 0.2], normals: new Array(steps * B * D).fill(-0.3),
      filt: new Array(B * 4 * D).fill(0), filter_b: [0.2, 0.4, 0.2, 0.5, 0.9, 0.5], filter_a: [-0.4, 0.2, 0.6, 0.2],
    };
    const { outputs } = await core.parity(inputs);
    expect(Object.keys(outputs).sort()).toEqual(['age_out', 'c_out', 'display', 'filt_out', 'h_out', 'held_out', 'wander_out', 'weights', 'ys']);
    expect((outputs as { weights: Float32Array }).weights.length).toBe(steps * B * FAKE_COMPONENTS);
    await expect(core.parity({ ...inputs, uniforms: [0.5] })).rejects.toThrow(/parity input uniforms has 1 values, expected 6 \(batch 2, 3 steps\) for a sampled model/);
    await expect(core.parity({ ...inputs, held: [-1, 0.5] })).rejects.toThrow(/parity input held must hold integers/);
  });

  it('benchmarks a sampled model with its sampler state fed back', async () => {
    const { core, calls } = fakeCore();
    const result = await core.benchmark(3, 8, 4);
    expect(result.batch).toBe(3);
    expect(result.steps).toBe(8);
    const later = calls[calls.length - 1];
    expect(Array.from(later.feeds.temperature.data as Float32Array)).toEqual([0.3, 0.5, 0.2].map(Math.fround));
    expect(ints(later.feeds.age.data as BigInt64Array).every((n) => n > 0)).toBe(true);
  });
});
