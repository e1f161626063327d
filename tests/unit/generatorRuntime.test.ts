// The generator step loop (web/runtime/generator/generatorCore.ts) on the shipped model, run by onnxruntime-web's
// Node build (the same wasm runtime the browser worker uses): one-step parity with the Python
// onnxruntime fixture, seeded determinism, and streams that continue exactly where they stopped.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { readRepoFile } from './corpus';
import { bytes, maxAbsDiff, ort, shippedSession } from './shippedModel';

interface StepFixture {
  inputs: { batch: number; x: number[]; h: number[]; c: number[] };
  outputs: Record<'weights' | 'mu' | 'sigma' | 'h_out' | 'c_out', number[]>;
}

const PARITY_TOLERANCE = 1e-4;
const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json');
const step = JSON.parse(readRepoFile('tests/fixtures/generator_reference.json')).step as StepFixture;

let core: GeneratorCore;

beforeAll(async () => {
  core = new GeneratorCore(await shippedSession(info.file), info, ort.Tensor);
  await core.check();
});

afterAll(() => core?.release());

/** Like maxAbsDiff, but relative for values above 1: unused mixture components can have sigmas in the
 * hundreds, where float32 rounding alone exceeds an absolute 1e-4 (the Python export check does the same). */
function maxScaledDiff(a: ArrayLike<number>, b: ArrayLike<number>): number {
  if (a.length !== b.length) return Infinity;
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]) / Math.max(1, Math.abs(b[i])));
  return worst;
}


describe('GeneratorCore', () => {
  it('builds the fixture inputs from the seed states and matches Python onnxruntime', async () => {
    const { inputs, outputs } = await core.parity();
    expect(maxAbsDiff(inputs.x, step.inputs.x)).toBe(0);
    expect(maxAbsDiff(inputs.h, step.inputs.h)).toBe(0);
    expect(maxAbsDiff(inputs.c, step.inputs.c)).toBe(0);
    for (const name of Object.keys(step.outputs) as (keyof StepFixture['outputs'])[]) {
      expect(maxScaledDiff(outputs[name], step.outputs[name]), name).toBeLessThan(PARITY_TOLERANCE);
    }
  });

  it('gives bit-identical frames for the same seed, different frames for another', async () => {
    const a = await core.generate({ frames: 60, seed: 11, temperature: 1 });
    const b = await core.generate({ frames: 60, seed: 11, temperature: 1 });
    const c = await core.generate({ frames: 60, seed: 12, temperature: 1, seedIndex: a.seedIndex });
    expect(a.seedIndex).toBe(11 % info.seeds.length);
    expect(bytes(b.features)).toEqual(bytes(a.features));
    expect(bytes(b.positions)).toEqual(bytes(a.positions));
    expect(bytes(c.features)).not.toEqual(bytes(a.features));
    expect(a.positions.every(Number.isFinite)).toBe(true);
    expect(a.positions.length).toBe(60 * info.skeleton.joints.length * 3);
    // Contact features are fed back and returned as exact bits.
    const D = info.onnx.dim;
    for (let f = 0; f < 60; f++) for (const d of [D - 2, D - 1]) expect([0, 1]).toContain(Math.round(a.features[f * D + d] * 1e5) / 1e5);
  });

  it('at temperature 0 ignores the PRNG seed', async () => {
    const a = await core.generate({ frames: 30, seed: 1, temperature: 0, seedIndex: 2 });
    const b = await core.generate({ frames: 30, seed: 99, temperature: 0, seedIndex: 2 });
    expect(bytes(b.positions)).toEqual(bytes(a.positions));
  });

  it('streams in chunks exactly what generate gives in one go, and restarts', async () => {
    const whole = await core.generate({ frames: 45, seed: 5, temperature: 0.8 });
    const stream = core.createStream({ seed: 5, temperature: 0.8 });
    const chunks = [await core.advance(stream, 20), await core.advance(stream, 25)];
    expect(chunks.map((c) => c.startFrame)).toEqual([0, 20]);
    const joined = new Float32Array(whole.positions.length);
    joined.set(chunks[0].positions);
    joined.set(chunks[1].positions, chunks[0].positions.length);
    expect(bytes(joined)).toEqual(bytes(whole.positions));
    const again = await core.advance(core.createStream(stream.params), 20);
    expect(bytes(again.positions)).toEqual(bytes(chunks[0].positions));
  });

  it('rejects bad requests with clear messages', async () => {
    await expect(core.generate({ frames: 0, seed: 1, temperature: 1 })).rejects.toThrow(/frames must be an integer/);
    await expect(core.generate({ frames: 5, seed: 1, temperature: -1 })).rejects.toThrow(/temperature/);
    await expect(core.generate({ frames: 5, seed: 1, temperature: 1, seedIndex: info.seeds.length })).rejects.toThrow(/seedIndex/);
    await expect(core.benchmark(0, 5)).rejects.toThrow(/batch/);
    await expect(core.parity({ batch: 2, x: [1, 2], h: [], c: [] })).rejects.toThrow(/parity inputs/);
  });

  it('times batched calls', async () => {
    const result = await core.benchmark(8, 5);
    expect(result.batch).toBe(8);
    expect(result.particleStepsPerSecond).toBeCloseTo(result.stepsPerSecond * 8, 6);
    expect(result.msPerCall).toBeGreaterThan(0);
  });
});
