import { describe, expect, it } from 'vitest';
import { importMotion, validateMotion } from '../../web/motion/io';
import { exportBVH } from '../../web/motion/bvh';
import { MotionFormatError, type Motion } from '../../web/motion/types';
import { readCorpus } from './corpus';

describe('importMotion', () => {
  it('imports a BVH with contacts attached', () => {
    const m = importMotion(readCorpus('cmu/bvh/07_04.bvh.gz'), 'bvh');
    expect(m.frames).toBe(450);
    expect(m.positions).toBeInstanceOf(Float32Array);
    expect(m.contacts).toBeInstanceOf(Uint8Array);
    expect(m.contacts!.length).toBe(900);
    expect(m.positions.every(Number.isFinite)).toBe(true);
  });

  it('imports an AMC with its ASF, with contacts', () => {
    const m = importMotion(readCorpus('cmu/amc/16_11.amc.gz'), 'amc', readCorpus('cmu/asf/16.asf'));
    expect(m.frames).toBe(534);
    expect(m.fps).toBe(120);
    expect(m.contacts!.length).toBe(534 * 2);
  });

  it('leaves contacts out when the feet cannot be identified', () => {
    const m: Motion = { fps: 30, frames: 2, joints: ['a', 'b', 'c'], parents: [-1, 0, 0], positions: new Float32Array([0, 1, 0, 0, 1.8, 0, 0, 0, 0, 0, 1, 0.1, 0, 1.8, 0.1, 0, 0, 0.1]) };
    const back = importMotion(exportBVH(m), 'bvh');
    expect(back.joints).toEqual(['a', 'b', 'c']);
    expect(back.contacts).toBeUndefined();
  });

  it('reports results that fail validation as format errors', () => {
    // Duplicate joint names are legal BVH but not a valid Motion.
    const text = readCorpus('cmu/bvh/07_04.bvh.gz').replace('JOINT LeftLeg', 'JOINT LeftUpLeg');
    expect(() => importMotion(text, 'bvh')).toThrow(MotionFormatError);
    expect(() => importMotion(text, 'bvh')).toThrow(/^BVH: Invalid motion: duplicate joint name "LeftUpLeg"$/);
  });

  it('rejects an unknown format', () => {
    expect(() => importMotion('x', 'fbx' as 'bvh')).toThrow(/unknown format "fbx"/);
  });
});

describe('validateMotion', () => {
  const good = (): Record<string, unknown> => ({
    fps: 30, frames: 2, joints: ['hips', 'head'], parents: [-1, 0],
    positions: new Float32Array([0, 1, 0, 0, 1.7, 0, 0, 1, 0.1, 0, 1.7, 0.1]),
  });
  const invalid = (change: (m: Record<string, unknown>) => void, message: RegExp) => {
    const m = good();
    change(m);
    expect(() => validateMotion(m)).toThrow(message);
  };

  it('accepts a valid motion and converts plain arrays', () => {
    const m = validateMotion({ ...good(), positions: [0, 1, 0, 0, 1.7, 0, 0, 1, 0.1, 0, 1.7, 0.1], contacts: [1, 0, 0, 1] });
    expect(m.positions).toBeInstanceOf(Float32Array);
    expect(m.contacts).toEqual(new Uint8Array([1, 0, 0, 1]));
    expect(validateMotion(good()).joints).toEqual(['hips', 'head']);
  });

  it('says what is wrong', () => {
    expect(() => validateMotion(null)).toThrow(/^Invalid motion: expected an object/);
    expect(() => validateMotion('motion')).toThrow(/expected an object/);
    invalid((m) => delete m.fps, /fps must be a positive number/);
    invalid((m) => (m.fps = -30), /fps must be a positive number/);
    invalid((m) => (m.frames = 2.5), /frames must be an integer from 1 to 1000000, got 2\.5/);
    // A string shows as a string, NaN as NaN (String() would print 10 and JSON null).
    invalid((m) => ((m as { frames: unknown }).frames = '10'), /frames must be an integer from 1 to 1000000, got "10"$/);
    invalid((m) => (m.fps = NaN), /fps must be a positive number \(≤ 10000\), got NaN$/);
    invalid((m) => (m.frames = 3), /positions has 12 values, expected frames × joints × 3 = 3 × 2 × 3 = 18/);
    invalid((m) => (m.joints = []), /joints must be a non-empty array/);
    invalid((m) => (m.joints = ['hips', 'hips']), /duplicate joint name "hips"/);
    invalid((m) => (m.joints = ['hips', 7]), /joints\[1\] must be a non-empty string/);
    invalid((m) => (m.parents = [-1]), /parents must be an array with one entry per joint \(2\), got 1/);
    invalid((m) => (m.parents = [0, -1]), /the first joint must be the root/);
    invalid((m) => (m.parents = [-1, 1]), /parents\[1\] = 1: every non-root joint needs a parent listed before it/);
    invalid((m) => (m.parents = [-1, 0.5]), /parents\[1\] must be an integer/);
    invalid((m) => (m.positions = 'none'), /positions must be a Float32Array or an array of numbers/);
    invalid((m) => ((m.positions as Float32Array)[7] = NaN), /non-finite value \(NaN\) at frame 1, joint "hips"/);
    invalid((m) => ((m.positions as Float32Array)[4] = Infinity), /non-finite value \(Infinity\) at frame 0, joint "head"/);
    invalid((m) => ((m.positions as Float32Array)[10] = -2e6), /^Invalid motion: frame 1 puts joint "head" at y = -2000000 m \(at most ±1000000 m on each axis\)$/);
    invalid((m) => (m.contacts = new Uint8Array(3)), /contacts has 3 values, expected frames × 2 = 4/);
    invalid((m) => (m.contacts = [0, 2, 0, 1]), /contacts\[1\] must be 0 or 1, got 2/);
  });
});
