// The TypeScript feature decoder against the Python one (training/data/features.py), via the fixture the
// Python export writes (tests/fixtures/generator_reference.json), plus the generator JSON checks.
import { describe, expect, it } from 'vitest';
import { decodeFeatures } from '../../web/model/featureDecode';
import { GeneratorInfoError, parseGeneratorInfo, type GeneratorInfo } from '../../web/model/generatorInfo';
import { readRepoFile } from './corpus';

const TOLERANCE = 0.001; // metres

interface DecodeFixture {
  features: number[];
  frames: number;
  positions: number[];
}

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json');
const fixture = JSON.parse(readRepoFile('tests/fixtures/generator_reference.json')).decode as DecodeFixture;

function maxDistance(a: Float32Array, b: ArrayLike<number>): number {
  let worst = 0;
  for (let i = 0; i < a.length; i += 3) worst = Math.max(worst, Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]));
  return worst;
}

describe('decodeFeatures', () => {
  it('matches the Python decoder within 1 mm', () => {
    const decoded = decodeFeatures(info, Float32Array.from(fixture.features));
    expect(decoded.positions.length).toBe(fixture.positions.length);
    expect(maxDistance(decoded.positions, fixture.positions)).toBeLessThan(TOLERANCE);
  });

  it('continues a chunked decode exactly where the previous chunk ended', () => {
    const D = info.onnx.dim;
    const features = Float32Array.from(fixture.features);
    const whole = decodeFeatures(info, features);
    const first = decodeFeatures(info, features.subarray(0, 3 * D));
    const rest = decodeFeatures(info, features.subarray(3 * D), first.end);
    const joined = new Float32Array(whole.positions.length);
    joined.set(first.positions);
    joined.set(rest.positions, first.positions.length);
    expect(maxDistance(joined, whole.positions)).toBeLessThan(1e-6);
  });

  it('turns the root step by the previous heading and thresholds contacts at 0.5', () => {
    const D = info.onnx.dim;
    const features = new Float32Array(2 * D);
    features[1] = 1; // frame 0: 1 m forward (heading 0 → +z), then turn a quarter left
    features[2] = Math.PI / 2;
    features[D + 1] = 1; // frame 1: 1 m forward in the new heading (π/2 → +x)
    features[D - 2] = 0.6;
    features[D - 1] = 0.4;
    const { positions, contacts, rootHeading, end } = decodeFeatures(info, features);
    const J = info.skeleton.joints.length;
    expect([positions[0], positions[2]].map((v) => +v.toFixed(6))).toEqual([0, 1]);
    expect([positions[J * 3], positions[J * 3 + 2]].map((v) => +v.toFixed(6))).toEqual([1, 1]);
    expect(Array.from(contacts)).toEqual([1, 0, 0, 0]);
    expect(rootHeading[1]).toBeCloseTo(Math.PI / 2, 6);
    expect(end.x).toBeCloseTo(1, 6);
    expect(end.z).toBeCloseTo(1, 6);
  });

  it('rejects malformed input with a clear message', () => {
    expect(() => decodeFeatures(info, new Float32Array(info.onnx.dim + 1))).toThrow(/whole number/);
  });
});

describe('parseGeneratorInfo', () => {
  const clone = (): GeneratorInfo => JSON.parse(JSON.stringify(info));

  it('accepts the shipped file', () => {
    expect(info.onnx.dim).toBe(7 + 3 * info.features.joints.length + 2);
  });

  it.each([
    ['a wrong dim', (g: GeneratorInfo) => (g.onnx.dim += 1), /onnx\.dim/],
    ['a short seed state', (g: GeneratorInfo) => g.seeds[1].h.pop(), /seeds\[1\]\.h/],
    ['a zero std', (g: GeneratorInfo) => (g.normalisation.std[3] = 0), /normalisation\.std\[3\]/],
    ['renamed outputs', (g: GeneratorInfo) => (g.onnx.outputs[1] = 'means'), /onnx\.outputs/],
    ['a bad parent', (g: GeneratorInfo) => (g.skeleton.parents[4] = 9), /skeleton\.parents\[4\]/],
    ['a missing joint', (g: GeneratorInfo) => g.features.fixed_joints.pop(), /every non-root joint/],
  ])('rejects %s', (_, mutate, message) => {
    const g = clone();
    mutate(g);
    expect(() => parseGeneratorInfo(g, 'test.json')).toThrow(GeneratorInfoError);
    expect(() => parseGeneratorInfo(g, 'test.json')).toThrow(message);
  });
});
