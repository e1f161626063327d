// The API's and optimiser's input checks (docs/api.md): how a bad value reads in a message
// (motion/describe.ts), generate's checks, "only a left-out option takes its default", the
// manifest's errors naming models/index.json, and the ?threads cap.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { checkGenerate, type ModelInfo } from '../../web/api/playground';
import { describeValue, MAX_DESCRIPTION } from '../../web/motion/describe';
import { loadManifest, parseManifest } from '../../web/model/manifest';
import { checkFitSigma, checkFootLock, checkGait, checkSeconds, checkSeed, optional } from '../../web/optimizer/options';
import { checkSchedule, checkTarget } from '../../web/optimizer/liveControl';
import { checkPathPoints } from '../../web/optimizer/path';
import { threadCount } from '../../web/ui/modelHost';
import { messageOf } from './messageOf';

const MODELS: ModelInfo[] = [
  { id: 'generator', kind: 'lstm-gmm', skeleton: 'cmu-canonical', fps: 30, bytes: 1 },
  { id: 'aclstm', kind: 'aclstm', skeleton: 'aclstm-standard', fps: 30, styles: ['salsa', 'indian', 'martial'], bytes: 1 },
  { id: 'refiner', kind: 'refiner', skeleton: 'cmu-canonical', fps: 30, bytes: 1 },
];

describe('describeValue', () => {
  it('shows what JSON.stringify and String hide', () => {
    expect(describeValue(NaN)).toBe('NaN');
    expect(describeValue([1, NaN])).toBe('[1, NaN]');
    expect(describeValue([Infinity, -Infinity])).toBe('[Infinity, -Infinity]');
    expect(describeValue('10')).toBe('"10"');
    expect(describeValue(10)).toBe('10');
    expect(describeValue(-0)).toBe('-0');
    expect(describeValue(undefined)).toBe('undefined');
    expect(describeValue(null)).toBe('null');
    expect(describeValue(true)).toBe('true');
    expect(describeValue(12n)).toBe('12n');
    expect(describeValue({ t: 0, speed: '1' })).toBe('{ t: 0, speed: "1" }');
    expect(describeValue([[1, 2], { a: 1 }, [], {}])).toBe('[[…2 items], {…}, [], {}]');
    expect(describeValue(new Float32Array(30))).toBe('Float32Array(30)');
    expect(describeValue(new Map())).toBe('a Map');
    expect(describeValue(() => 1)).toBe('a function');
    expect(describeValue('a\u2028b')).toBe('"a\\u2028b"');
  });

  it('stays short whatever the value', () => {
    const huge = 'x'.repeat(5e6);
    expect(describeValue(huge)).toBe(`"${'x'.repeat(40)}…"`);
    expect(describeValue(Array.from({ length: 1e5 }, (_, i) => i))).toBe('[0, 1, 2, 3, … 100000 items]');
    const wide = Object.fromEntries(Array.from({ length: 1000 }, (_, i) => [`k${i}`, huge]));
    const cases = [wide, [huge, huge, huge, huge, huge], { [huge]: huge }, '\u2028'.repeat(1000), 10n ** 1000n, Symbol(huge), new (class extends Array {})()];
    for (const v of cases) expect(describeValue(v).length).toBeLessThanOrEqual(MAX_DESCRIPTION + 1);
    const hostile = new Proxy({}, { ownKeys: () => { throw new Error('no'); } });
    expect(describeValue(hostile)).toBe('an unreadable value');
  });
});

describe('generate checks', () => {
  it('quotes a string where a number belongs, and says NaN', () => {
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: '10', seed: 0 }, MODELS))).toBe('frames must be an integer from 1 to 100000, got "10"');
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: 10, seed: NaN }, MODELS))).toMatch(/seed must be an integer .*, got NaN$/);
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: 10, seed: 0, temperature: '0.5' }, MODELS))).toMatch(/got "0\.5"$/);
    expect(messageOf(() => checkGenerate({ model: 'aclstm', frames: 10, seed: 0, style: 7 }, MODELS))).toMatch(/^unknown style 7 for model "aclstm"/);
    // A style generator (issue 39) takes one of its styles, default its first; the CMU-only generator takes none.
    const styled = [...MODELS, { id: 'style-generator', kind: 'lstm-gmm', skeleton: 'cmu-canonical', fps: 30, styles: ['cmu', 'elderly'], bytes: 1, commercial: false }];
    expect(checkGenerate({ model: 'style-generator', frames: 10, seed: 0 }, styled)).toMatchObject({ style: 'cmu' });
    expect(checkGenerate({ model: 'style-generator', frames: 10, seed: 0, style: 'elderly' }, styled)).toMatchObject({ style: 'elderly' });
    expect(messageOf(() => checkGenerate({ model: 'style-generator', frames: 10, seed: 0, style: 'tired' }, styled))).toMatch(/^unknown style "tired" for model "style-generator" \(styles: cmu, elderly\)/);
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: 10, seed: 0, style: 'elderly' }, styled))).toMatch(/^style is not an option of model "generator": it has no styles/);
    expect(checkGenerate({ model: 'generator', frames: 10, seed: 0 }, styled)).not.toHaveProperty('style');
    expect(messageOf(() => checkGenerate({ model: 'style-generator', frames: 10, seed: 0, refine: true }, [...styled, { id: 'refiner', kind: 'refiner', skeleton: 'cmu-canonical', fps: 30, bytes: 1 }]))).toMatch(/^refine is not available for model "style-generator"/);
    expect(messageOf(() => checkGenerate({ model: 'x'.repeat(1e6), frames: 10, seed: 0 }, MODELS)).length).toBeLessThan(150);
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: 10, seed: 0, ['y'.repeat(1e6)]: 1 }, MODELS)).length).toBeLessThan(150);
  });

  it('takes the default temperature only when it is left out: null is refused', () => {
    expect(checkGenerate({ model: 'generator', frames: 10, seed: 0 }, MODELS)).toMatchObject({ temperature: 0.5 });
    expect(checkGenerate({ model: 'generator', frames: 10, seed: 0, temperature: undefined }, MODELS)).toMatchObject({ temperature: 0.5 });
    expect(messageOf(() => checkGenerate({ model: 'generator', frames: 10, seed: 0, temperature: null }, MODELS))).toBe('temperature must be a number from 0 to 2, got null');
  });
});

describe('optimiser option checks', () => {
  it('name the bad value as it is', () => {
    expect(messageOf(() => checkGait(null))).toBe('gait must be "walk" or "run", got null');
    expect(messageOf(() => checkSeed('3'))).toMatch(/got "3"$/);
    expect(messageOf(() => checkFootLock('yes'))).toBe('footLock must be true or false, got "yes"');
    expect(messageOf(() => checkFitSigma(NaN))).toMatch(/got NaN$/);
    expect(messageOf(() => checkSeconds('6'))).toMatch(/got "6"$/);
    expect(messageOf(() => checkPathPoints([[0, 0], [NaN, 5]]))).toBe('points[1] must be a pair of finite numbers [x, z], got [NaN, 5]');
    expect(messageOf(() => checkPathPoints([[0, 0], ['1', 5]]))).toMatch(/got \["1", 5\]$/);
    expect(messageOf(() => checkSchedule([{ t: 0, speed: '1', heading: 0 }]))).toMatch(/schedule\[0\]\.speed must be .*, got "1"$/);
    expect(messageOf(() => checkSchedule([5]))).toMatch(/schedule\[0\] must be an object .*, got 5$/);
    expect(messageOf(() => checkTarget({ speed: 1, heading: Infinity }))).toMatch(/got Infinity$/);
  });

  it('take a default only for a left-out option', () => {
    expect(optional(undefined, 0)).toBe(0);
    expect(optional(null, 0)).toBe(null);
    expect(() => checkSeed(optional(null, 0))).toThrow(/got null/);
  });
});

describe('the model manifest', () => {
  afterEach(() => vi.unstubAllGlobals());
  const serve = (body: string, status = 200) => vi.stubGlobal('fetch', async () => new Response(body, { status }));

  it('names models/index.json in every error, and a bad entry by index and model file', async () => {
    serve('{"models": [');
    await expect(loadManifest('models/index.json')).rejects.toThrow(/^models\/index\.json: not valid JSON/);
    serve('gone', 404);
    await expect(loadManifest('models/index.json')).rejects.toThrow(/^models\/index\.json: HTTP 404/);
    vi.stubGlobal('fetch', async () => {
      throw new TypeError('Failed to fetch');
    });
    await expect(loadManifest('models/index.json')).rejects.toThrow(/^models\/index\.json: could not fetch \(Failed to fetch\)/);
    serve('[]');
    await expect(loadManifest('models/index.json')).rejects.toThrow('models/index.json: expected { "models": [...] }, got []');
    expect(() => parseManifest({ models: [{ id: 'g', kind: 'lstm-gmm', skeleton: 's', fps: 30, bytes: 1, file: 'g.onnx' }, { id: 'x', file: 'x.onnx' }] })).toThrow(
      'models/index.json: entry 1 ("x.onnx") needs id, kind, skeleton (strings), fps and bytes (numbers)',
    );
    expect(() => parseManifest({ models: [{ id: 'a', kind: 'aclstm', skeleton: 's', fps: 30, bytes: 1, styles: 'salsa', file: 'a.onnx' }] })).toThrow(/entry 0 \("a\.onnx"\): styles must be an array of strings, got "salsa"/);
  });

  it('reads the shipped manifest without the internal file names', () => {
    const shipped = parseManifest({ models: [{ id: 'a', kind: 'aclstm', skeleton: 's', fps: 30, bytes: 5, styles: ['salsa'], file: 'a.onnx' }] });
    expect(shipped).toEqual([{ id: 'a', kind: 'aclstm', skeleton: 's', fps: 30, bytes: 5, styles: ['salsa'] }]);
  });
});

describe('?threads', () => {
  it('is capped at the core count', () => {
    expect(threadCount('?threads=64', 2, true)).toBe(2);
    expect(threadCount('?threads=3', 16, true)).toBe(3);
    expect(threadCount('?threads=0', 2, true)).toBe(1);
    expect(threadCount('?threads=abc', 8, true)).toBe(4);
    expect(threadCount('', 2, true)).toBe(1);
    expect(threadCount('', 16, false)).toBe(1);
  });
});
