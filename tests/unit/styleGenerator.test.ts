// A style-conditioned generator in the page (issue 39): generator.json's optional `styles` (checked, with the step's
// fourth input `style`), and GeneratorCore feeding a style vector, on tests/fixtures/style_generator/ (a tiny model
// exported by python -m training.style_generator.export's code; python -m training.fixtures.style_generator). The
// reference step (two one-hot rows and one blended row) is Python onnxruntime's; the core must reproduce it.
import { readFileSync } from 'node:fs';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { parseGeneratorInfo, styleNames, styleSeeds, styleVector, type GeneratorInfo } from '../../web/model/generatorInfo';
import { gaitSeeds } from '../../web/optimizer/pathFollower';
import { OptimizerRequests } from '../../web/runtime/generator/optimizerRequests';
import { readRepoFile, REPO_ROOT } from './corpus';
import { bytes, ort, shippedSession } from './shippedModel';

const DIR = 'tests/fixtures/style_generator/';
const raw = JSON.parse(readRepoFile(`${DIR}style-tiny.json`));
const info = parseGeneratorInfo(raw, `${DIR}style-tiny.json`);
const reference = JSON.parse(readRepoFile(`${DIR}style-tiny_reference.json`)) as {
  seeds: number[];
  inputs: { batch: number; x: number[]; h: number[]; c: number[]; style: number[] };
  outputs: Record<'weights' | 'mu' | 'sigma' | 'h_out' | 'c_out', number[]>;
};
const PARITY_TOLERANCE = 1e-4;

/** |a - b| / max(1, |b|), the Python export check's measure. */
function maxScaledDiff(a: ArrayLike<number>, b: ArrayLike<number>): number {
  if (a.length !== b.length) return Infinity;
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]) / Math.max(1, Math.abs(b[i])));
  return worst;
}

let core: GeneratorCore;

beforeAll(async () => {
  ort.env.wasm.numThreads = 1;
  core = new GeneratorCore(await ort.InferenceSession.create(readFileSync(`${REPO_ROOT}${DIR}${info.file}`)), info, ort.Tensor);
  await core.check();
});

afterAll(() => core?.release());

describe('a style generator', () => {
  it('reads its styles, licence and style input from the JSON', () => {
    expect(styleNames(info)).toEqual(['cmu', 'active', 'elderly']);
    expect(info.onnx.inputs).toEqual(['x', 'h', 'c', 'style']);
    expect(info.licence).toMatch(/^CC BY-NC 4\.0 \(non-commercial\)/);
    expect(core.describe(0)).toMatchObject({ styles: ['cmu', 'active', 'elderly'], licence: info.licence });
    for (const style of info.styles!) expect(styleSeeds(info, style).length).toBeGreaterThan(0);
    expect(styleSeeds(info)).toEqual(styleSeeds(info, 'cmu'));
    expect(gaitSeeds(info, 'run', 'active').map((i) => info.seeds[i].name)).toEqual([expect.stringMatching(/^run active /)]);
  });

  it('refuses a JSON whose styles and step disagree', () => {
    const bad = (edit: (j: Record<string, any>) => void) => {
      const j = structuredClone(raw);
      edit(j);
      return () => parseGeneratorInfo(j, 'style-tiny.json');
    };
    expect(bad((j) => (j.onnx.inputs = ['x', 'h', 'c']))).toThrow(/onnx\.inputs is \[x,h,c\], expected \[x,h,c,style\]/);
    expect(bad((j) => delete j.styles)).toThrow(/onnx\.inputs is \[x,h,c,style\], expected \[x,h,c\]/);
    expect(bad((j) => (j.styles = ['cmu', 'cmu', 'elderly']))).toThrow(/styles has a name twice/);
    expect(bad((j) => (j.onnx.styles = 4))).toThrow(/onnx\.styles is 4 but styles names 3/);
    expect(bad((j) => (j.seeds[0].style = 'jazzy'))).toThrow(/seeds\[0\]\.style must be one of the styles/);
    expect(bad((j) => (j.seeds = j.seeds.filter((s: { style: string }) => s.style !== 'elderly')))).toThrow(/no seed state of style "elderly"/);
    expect(bad((j) => (j.licence = 3))).toThrow(/licence must be a non-empty string/);
    expect(bad((j) => (j.held_out_sliding = { cmu: 0.26, jazzy: 0.5 }))).toThrow(/held_out_sliding names "jazzy", which is not one of styles/);
    expect(bad((j) => (j.held_out_sliding = { cmu: -1 }))).toThrow(/held_out_sliding\.cmu must be a finite number ≥ 0/);
  });

  it("gives each style's held-out sliding to the page's readout when the JSON has it", async () => {
    const withSliding = parseGeneratorInfo({ ...structuredClone(raw), held_out_sliding: { cmu: 0.26, elderly: 0.63 } }, 'style-tiny.json');
    const other = new GeneratorCore(await ort.InferenceSession.create(readFileSync(`${REPO_ROOT}${DIR}${info.file}`)), withSliding, ort.Tensor);
    expect(other.describe(0).heldOutSlidingByStyle).toEqual({ cmu: 0.26, elderly: 0.63 });
    expect(core.describe(0).heldOutSlidingByStyle).toBeUndefined();
    await other.release();
  });

  it('makes style vectors: one-hots by name, the first by default, checked blends', () => {
    expect(Array.from(styleVector(info))).toEqual([1, 0, 0]);
    expect(Array.from(styleVector(info, 'elderly'))).toEqual([0, 0, 1]);
    expect(Array.from(styleVector(info, [0, 0.25, 0.75]))).toEqual([0, 0.25, 0.75]);
    expect(() => styleVector(info, 'jazzy')).toThrow(/unknown style "jazzy".*cmu, active, elderly/);
    expect(() => styleVector(info, [0.5, 0.6, 0])).toThrow(/sum to 1/);
    expect(() => styleVector(info, [1.5, -0.5, 0])).toThrow(/must be a finite number ≥ 0/);
    expect(() => styleVector(info, [1, 0])).toThrow(/needs 3 weights/);
  });

  it('reproduces the Python onnxruntime step, one-hot and blended rows', async () => {
    const { outputs } = await core.parity(reference.inputs);
    for (const name of Object.keys(reference.outputs) as (keyof typeof reference.outputs)[]) {
      expect(maxScaledDiff(outputs[name], reference.outputs[name]), name).toBeLessThan(PARITY_TOLERANCE);
    }
    // Without inputs: the first and last seeds in their own styles, the reference's first two rows.
    const own = await core.parity();
    expect(Array.from(own.inputs.style!)).toEqual(reference.inputs.style.slice(0, 2 * 3));
    const M = info.onnx.mixtures, D = info.onnx.dim;
    expect(maxScaledDiff(own.outputs.mu, reference.outputs.mu.slice(0, 2 * M * D))).toBeLessThan(PARITY_TOLERANCE);
    // The blend is neither end: the style input is really fed.
    const blended = reference.outputs.mu.slice(2 * M * D);
    const oneHot = (style: number[]) => core.parity({ ...reference.inputs, style: [...style, ...style, ...style] });
    for (const end of [[0, 1, 0], [0, 0, 1]]) expect(maxScaledDiff((await oneHot(end)).outputs.mu.slice(2 * M * D), blended)).toBeGreaterThan(1e-4);
  });

  it('streams in a style: its seeds, different frames per style, a blend switched in mid-stream', async () => {
    const cmu = await core.generate({ frames: 20, seed: 3, temperature: 0 });
    expect(styleSeeds(info, 'cmu')).toContain(cmu.seedIndex);
    const stream = core.createStream({ seed: 3, temperature: 0, style: 'elderly' });
    expect(info.seeds[stream.seedIndex].style).toBe('elderly');
    expect(core.streamInfo(stream)).toMatchObject({ style: 'elderly' });
    // The same seed state in two styles: the style input alone changes the frames.
    const a = await core.generate({ frames: 20, seed: 3, temperature: 0, seedIndex: 0, style: 'active' });
    const b = await core.generate({ frames: 20, seed: 3, temperature: 0, seedIndex: 0, style: 'active' });
    const c = await core.generate({ frames: 20, seed: 3, temperature: 0, seedIndex: 0, style: 'elderly' });
    expect(bytes(b.features)).toEqual(bytes(a.features));
    expect(bytes(c.features)).not.toEqual(bytes(a.features));
    // A stream switched to elderly after 10 frames: the first 10 frames are active's, the next differ from them.
    const s = core.createStream({ seed: 3, temperature: 0, seedIndex: 0, style: 'active' });
    const first = await core.advance(s, 10);
    core.setStreamStyle(s, [0, 0.5, 0.5]);
    const next = await core.advance(s, 10);
    const D = info.onnx.dim;
    expect(bytes(first.features)).toEqual(bytes(a.features.slice(0, 10 * D)));
    expect(bytes(next.features)).not.toEqual(bytes(a.features.slice(10 * D)));
    expect(() => core.createStream({ seed: 1, temperature: 0, style: 'jazzy' })).toThrow(/unknown style "jazzy"/);
  });
});

describe('the optimiser requests of a style generator', () => {
  it('start live control from a seed of the asked style and feed it to every step', async () => {
    const requests = new OptimizerRequests(core);
    const started = requests.controlStart({ seed: 1, gait: 'run', style: 'active' });
    expect(started).toMatchObject({ style: 'active', seedName: expect.stringMatching(/^run active /) });
    const chunk = await requests.controlPull({ speed: 2, heading: 0, frames: 5, particles: 4 });
    expect(chunk.frames).toBe(5);
    expect(chunk.positions.every(Number.isFinite)).toBe(true);
    expect(requests.controlStart({ seed: 1, gait: 'walk' })).toMatchObject({ style: 'cmu' });
    expect(() => requests.controlStart({ seed: 1, gait: 'walk', style: 'jazzy' })).toThrow(/unknown style "jazzy"/);
  });
});

describe('a generator without styles', () => {
  const plain = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json') as GeneratorInfo;
  let shipped: GeneratorCore;
  beforeAll(async () => {
    shipped = new GeneratorCore(await shippedSession(plain.file), plain, ort.Tensor);
  });
  afterAll(() => shipped?.release());

  it('has no style input and refuses one', async () => {
    expect(styleNames(plain)).toEqual([]);
    expect(shipped.describe(0)).not.toHaveProperty('styles');
    expect(styleSeeds(plain)).toEqual(plain.seeds.map((_, i) => i));
    expect(() => shipped.createStream({ seed: 1, temperature: 0.5, style: 'cmu' })).toThrow(/has no styles/);
    expect(shipped.createStream({ seed: 11, temperature: 0.5 }).seedIndex).toBe(11 % plain.seeds.length);
    expect(shipped.createStream({ seed: 11, temperature: 0.5 }).style).toBeUndefined();
    const { x, h, c } = (await shipped.parity()).inputs;
    await expect(shipped.step(1, x.slice(0, plain.onnx.dim), h, c, undefined, [1])).rejects.toThrow(/has no style input/);
  });
});
