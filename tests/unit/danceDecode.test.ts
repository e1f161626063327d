// The dance feature decoder against the Python one (training/data/dance.py decode) via the fixture the
// export writes (tests/fixtures/aclstm_reference.json), and the dance model JSON checks.
import { describe, expect, it } from 'vitest';
import { decodeDance } from '../../web/runtime/aclstm/danceDecode';
import { DanceInfoError, parseDanceInfo, seedsOfStyle } from '../../web/runtime/aclstm/danceModel';
import { readRepoFile } from './corpus';

const raw = JSON.parse(readRepoFile('public/models/aclstm.json'));
const info = parseDanceInfo(raw, 'public/models/aclstm.json');
const fixture = JSON.parse(readRepoFile('tests/fixtures/aclstm_reference.json')).decode as { features: number[]; frames: number; positions: number[] };
const J = info.skeleton.joints.length;

function maxDifference(a: ArrayLike<number>, b: ArrayLike<number>): number {
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]));
  return worst;
}

describe('decodeDance', () => {
  it('matches the Python decoder', () => {
    const { positions } = decodeDance(fixture.features, J);
    expect(positions.length).toBe(fixture.positions.length);
    expect(maxDifference(positions, fixture.positions)).toBeLessThan(1e-5);
  });

  it('continues a chunked decode where the previous chunk ended', () => {
    const D = 3 * J;
    const whole = decodeDance(fixture.features, J);
    const first = decodeDance(fixture.features.slice(0, 4 * D), J);
    const rest = decodeDance(fixture.features.slice(4 * D), J, first.end);
    const joined = new Float32Array(whole.positions.length);
    joined.set(first.positions);
    joined.set(rest.positions, first.positions.length);
    expect(maxDifference(joined, whole.positions)).toBeLessThan(1e-6);
    expect(rest.end.x).toBeCloseTo(whole.end.x, 12);
  });

  it('puts the root at the integrated steps and absolute height, the points around it', () => {
    const D = 3 * J;
    const features = new Float32Array(2 * D);
    features.set([0.1, 0.9, -0.2], 0);
    features.set([0.1, 0.8, -0.2], D);
    features.set([0, 0.5, 0], D + 3); // point 1, 0.5 m above the root
    const { positions, end } = decodeDance(features, J, { x: 1, z: 1 });
    expect(Array.from(positions.subarray(0, 3))).toEqual([1.1, 0.9, 0.8].map(Math.fround));
    expect(Array.from(positions.subarray(D, D + 6))).toEqual([1.2, 0.8, 0.6, 1.2, 1.3, 0.6].map(Math.fround));
    expect(end.x).toBeCloseTo(1.2, 6);
    expect(end.z).toBeCloseTo(0.6, 6);
  });

  it('rejects a partial frame', () => {
    expect(() => decodeDance(new Float32Array(3 * J + 1), J)).toThrow(/not a whole number of 171-value frames/);
  });
});

describe('parseDanceInfo', () => {
  it('accepts both shipped models, with seeds for every style', () => {
    const sampled = parseDanceInfo(JSON.parse(readRepoFile('public/models/aclstm-mdn.json')), 'aclstm-mdn.json');
    for (const m of [info, sampled]) {
      expect(m.styles).toEqual(['salsa', 'indian', 'martial']);
      expect(m.onnx.dim).toBe(3 * m.skeleton.joints.length);
      for (const style of m.styles) {
        expect(seedsOfStyle(m, style).length).toBeGreaterThan(0);
        expect(seedsOfStyle(m, style).every((i) => m.seeds[i].style === style)).toBe(true);
      }
    }
  });

  it('names the first bad field', () => {
    const broken = (edit: (j: Record<string, any>) => void) => {
      const j = structuredClone(raw);
      edit(j);
      return () => parseDanceInfo(j, 'test.json');
    };
    expect(broken((j) => (j.onnx.inputs = ['x', 'h', 'c']))).toThrow(/test\.json: onnx\.inputs is \[x,h,c\], expected \[x,style,h,c,steps\]/);
    expect(broken((j) => (j.onnx.dim = 170))).toThrow(/onnx\.dim is 170 but 57 skeleton points need 171/);
    expect(broken((j) => (j.seeds[3].style = 'tango'))).toThrow(/seeds\[3\]\.style must be one of salsa, indian, martial/);
    expect(broken((j) => j.seeds[0].frames.pop())).toThrow(/seeds\[0\]\.frames must hold 10 frames/);
    expect(broken((j) => (j.seeds = j.seeds.filter((s: { style: string }) => s.style !== 'indian')))).toThrow(/no seed motion for style "indian"/);
    expect(broken((j) => delete j.real_pose_change.martial)).toThrow(/real_pose_change\.martial must be a finite number/);
    expect(broken((j) => (j.normalisation.std[5] = 0))).toThrow(/normalisation\.std\[5\] = 0 must be positive/);
    expect(broken((j) => (j.skeleton.parents[4] = 9))).toThrow(/skeleton\.parents\[4\] = 9/);
    expect(broken((j) => (j.onnx.styles = 2))).toThrow(/onnx\.styles is 2 but there are 3 styles/);
    expect(broken((j) => (j.fps = 0))).toThrow(DanceInfoError);
    expect(broken(() => undefined)).not.toThrow();
  });
});
