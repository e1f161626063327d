// A style switch without a pop (issue 39): the style input ramps from the old style to the new one over a second,
// one convex blend per frame (web/model/styleRamp.ts), in a stream (GeneratorCore.switchStreamStyle) and in the live
// controller's stream (OptimizerRequests.controlStyle); and `style` as the API checks it (checkStyleOption), on the
// tiny style generator of tests/fixtures/style_generator/.
import { readFileSync } from 'node:fs';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { blendWeights, rampShare, StyleRamp, STYLE_SWITCH_FRAMES } from '../../web/model/styleRamp';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { OptimizerRequests } from '../../web/runtime/generator/optimizerRequests';
import { checkStyleOption } from '../../web/runtime/descriptor';
import { Registry } from '../../web/runtime/registry';
import type { ModelInfo } from '../../web/model/manifest';
import { readRepoFile, REPO_ROOT } from './corpus';
import { ort } from './shippedModel';
import { messageOf } from './messageOf';

const DIR = 'tests/fixtures/style_generator/';
const info = parseGeneratorInfo(JSON.parse(readRepoFile(`${DIR}style-tiny.json`)), `${DIR}style-tiny.json`);

/** Every row is a convex combination: weights ≥ 0 summing to 1 (float32). */
function expectConvex(w: ArrayLike<number>): void {
  let sum = 0;
  for (let i = 0; i < w.length; i++) {
    expect(w[i]).toBeGreaterThanOrEqual(0);
    sum += w[i];
  }
  expect(Math.abs(sum - 1)).toBeLessThan(1e-6);
}

describe('the style ramp', () => {
  it('rises monotonically from 0 to 1 over its frames, the last frame the new style alone', () => {
    const n = STYLE_SWITCH_FRAMES;
    expect(n).toBe(30); // one second at 30 fps
    const shares = Array.from({ length: n }, (_, k) => rampShare(k, n));
    for (let k = 1; k < n; k++) expect(shares[k]).toBeGreaterThan(shares[k - 1]);
    expect(shares[0]).toBeGreaterThan(0);
    expect(shares[0]).toBeLessThan(0.01); // gentle at the start: no step
    expect(shares[n - 1]).toBe(1);
    // The largest change between two frames is a small part of the whole switch (no jump).
    const steps = shares.map((s, k) => s - (k ? shares[k - 1] : 0));
    expect(Math.max(...steps)).toBeLessThan(0.06);
    expect(() => rampShare(0, 0)).toThrow(/at least 1 frame/);
  });

  it("gives each stream frame's weights: the old one-hot before, convex blends moving toward the new one, then the new one-hot", () => {
    const ramp = new StyleRamp([1, 0, 0]);
    expect(Array.from(ramp.at(0))).toEqual([1, 0, 0]);
    ramp.switchTo([0, 0, 1], 100);
    expect(Array.from(ramp.at(99))).toEqual([1, 0, 0]);
    let last = ramp.at(99);
    for (let f = 100; f < 100 + STYLE_SWITCH_FRAMES; f++) {
      const w = ramp.at(f);
      expectConvex(w);
      expect(w[2]).toBeGreaterThan(last[2]); // the new style's weight only grows
      expect(w[0]).toBeLessThan(last[0]); // the old one's only falls
      expect(w[1]).toBe(0); // a third style never enters
      last = w;
    }
    expect(Array.from(ramp.at(100 + STYLE_SWITCH_FRAMES - 1))).toEqual([0, 0, 1]);
    expect(Array.from(ramp.at(100 + STYLE_SWITCH_FRAMES + 500))).toEqual([0, 0, 1]);
    expect(Array.from(ramp.target)).toEqual([0, 0, 1]);
  });

  it('a switch during a switch carries on from the blend reached, without a jump', () => {
    const ramp = new StyleRamp([1, 0, 0]);
    ramp.switchTo([0, 1, 0], 0);
    const reached = ramp.at(9); // a third of the way
    ramp.switchTo([0, 0, 1], 10);
    const next = ramp.at(10);
    expectConvex(next);
    // The first frame of the new ramp is within one ramp step of where the old one stood.
    for (let i = 0; i < 3; i++) expect(Math.abs(next[i] - reached[i])).toBeLessThan(0.06);
    expect(Array.from(ramp.at(10 + STYLE_SWITCH_FRAMES - 1))).toEqual([0, 0, 1]);
    expect(() => ramp.switchTo([1, 0], 20)).toThrow(/needs 3 weights/);
  });

  it('blends convexly', () => {
    expect(Array.from(blendWeights([1, 0], [0, 1], 0.25))).toEqual([0.75, 0.25]);
    expect(() => blendWeights([1, 0], [0, 0, 1], 0.5)).toThrow(/different lengths/);
  });
});

describe('a style switch in the generator core', () => {
  let core: GeneratorCore;
  beforeAll(async () => {
    ort.env.wasm.numThreads = 1;
    core = new GeneratorCore(await ort.InferenceSession.create(readFileSync(`${REPO_ROOT}${DIR}${info.file}`)), info, ort.Tensor);
  });
  afterAll(() => core?.release());

  it('ramps a stream one frame at a time across chunks, from its next frame, and ends at the one-hot', async () => {
    const stream = core.createStream({ seed: 3, temperature: 0.5, style: 'cmu' });
    await core.advance(stream, 7);
    core.switchStreamStyle(stream, 'elderly');
    expect(core.streamInfo(stream).style).toBe('elderly');
    const fed: number[][] = [];
    // Chunks of 4 frames, as a stream is pulled: the weights fed at each frame are recorded after it.
    for (let chunk = 0; chunk < 10; chunk++) {
      for (let f = 0; f < 4; f++) {
        await core.advance(stream, 1);
        fed.push(Array.from(stream.style!));
      }
    }
    for (const w of fed) expectConvex(w);
    const elderly = fed.map((w) => w[2]);
    for (let k = 1; k < STYLE_SWITCH_FRAMES; k++) expect(elderly[k]).toBeGreaterThan(elderly[k - 1]);
    expect(elderly[0]).toBeGreaterThan(0); // the frame right after the switch already blends a little
    expect(elderly[0]).toBeLessThan(0.01);
    expect(fed[STYLE_SWITCH_FRAMES - 1]).toEqual([0, 0, 1]);
    expect(fed.at(-1)).toEqual([0, 0, 1]);
    // Chunked or frame by frame, the same frames: a stream switched then advanced by 40 frames at once ends alike.
    const a = core.createStream({ seed: 3, temperature: 0.5, style: 'cmu' });
    const b = core.createStream({ seed: 3, temperature: 0.5, style: 'cmu' });
    await core.advance(a, 7);
    await core.advance(b, 7);
    core.switchStreamStyle(a, 'elderly');
    core.switchStreamStyle(b, 'elderly');
    const whole = await core.advance(a, 40);
    const parts = [await core.advance(b, 13), await core.advance(b, 27)];
    expect(Array.from(whole.features)).toEqual([...parts[0].features, ...parts[1].features]);
    expect(() => core.switchStreamStyle(a, 'jazzy')).toThrow(/unknown style "jazzy"/);
  });

  it("switches the live controller's stream the same way, from its next batch", async () => {
    const requests = new OptimizerRequests(core);
    expect(() => requests.controlStyle('active')).toThrow(/no control stream/);
    requests.controlStart({ seed: 0, gait: 'walk', style: 'cmu' });
    await requests.controlPull({ frames: 6, speed: 1, heading: 0, particles: 4 });
    expect(requests.controlStyle('active')).toMatchObject({ style: 'active' });
    // The weights each step of the search feeds: every particle row of a step carries its stream frame's weights.
    const seen: { first: number; rows: number }[] = [];
    const step = core.step.bind(core);
    core.step = (batch, x, h, c, signal, style) => {
      const w = Array.from(style ?? []);
      seen.push({ first: w[1], rows: batch });
      return step(batch, x, h, c, signal, style);
    };
    try {
      for (let k = 0; k < 6; k++) await requests.controlPull({ frames: 6, speed: 1, heading: 0, particles: 4 });
    } finally {
      core.step = step;
    }
    // A search looks 12 frames ahead of the committed ones: its steps ramp within a batch, and batch after batch.
    const shares = seen.map((s) => s.first);
    expect(shares.every((s) => s >= 0 && s <= 1)).toBe(true);
    expect(shares[0]).toBeLessThan(0.01);
    expect(shares.at(-1)).toBe(1);
    // Per frame, not per batch: the searches fed every one of the ramp's 29 blends between the two one-hots.
    expect(new Set(shares.filter((s) => s > 0 && s < 1)).size).toBe(STYLE_SWITCH_FRAMES - 1);
    expect(() => requests.controlStyle('jazzy')).toThrow(/unknown style "jazzy"/);
  });
});

describe('style as the API checks it', () => {
  const styled: ModelInfo = { id: 'style-generator', kind: 'lstm-gmm', skeleton: 'cmu-canonical', fps: 30, bytes: 1, styles: ['cmu', 'elderly'], commercial: false };
  const plain: ModelInfo = { id: 'generator', kind: 'lstm-gmm', skeleton: 'cmu-canonical', fps: 30, bytes: 1 };

  it('takes one of the model\'s styles, is left out without one, and refuses the rest with a short reason', () => {
    expect(checkStyleOption(undefined, styled)).toBeUndefined();
    expect(checkStyleOption('elderly', styled)).toBe('elderly');
    expect(checkStyleOption(undefined, plain)).toBeUndefined();
    expect(messageOf(() => checkStyleOption('elderly', plain))).toBe('style is not an option of model "generator": it has no styles; leave it out');
    expect(messageOf(() => checkStyleOption('tired', styled))).toBe('unknown style "tired" for model "style-generator" (styles: cmu, elderly)');
    expect(messageOf(() => checkStyleOption(3, styled))).toBe('unknown style 3 for model "style-generator" (styles: cmu, elderly)');
  });
});

describe('a style model beside the generator in the page', () => {
  it('is told apart in titles and labelled non-commercial in pickers', () => {
    const entry = (id: string, extra: Partial<ModelInfo> = {}): ModelInfo => ({ id, kind: 'lstm-gmm', skeleton: 'cmu-canonical', fps: 30, bytes: 1, ...extra });
    const registry = new Registry([entry('generator'), entry('style-generator', { styles: ['cmu', 'elderly'], commercial: false })]);
    expect(registry.shortName('generator')).toBe('generator');
    expect(registry.shortName('style-generator')).toBe('style-generator');
    expect(registry.label('style-generator')).toBe('style-generator (non-commercial)');
    expect(registry.defaultFor('walk')?.info.id).toBe('generator'); // the CMU-only model stays the default
    // Alone, a model of the kind keeps the kind's short name.
    expect(new Registry([entry('style-generator', { styles: ['cmu'] })]).shortName('style-generator')).toBe('generator');
  });
});
