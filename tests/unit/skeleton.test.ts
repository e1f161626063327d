import { describe, expect, it } from 'vitest';
import { boneLengths, forwardKinematics } from '../../web/motion/skeleton';
import { DEG, eulerToQuat, type Quat } from '../../web/motion/math';
import type { Skeleton } from '../../web/motion/types';

// root → mid (offset +y 1) → tip (offset +y 1)
const skeleton: Skeleton = {
  joints: ['root', 'mid', 'tip'],
  parents: [-1, 0, 1],
  offsets: new Float32Array([0, 0, 0, 0, 1, 0, 0, 1, 0]),
};
const I: Quat = [0, 0, 0, 1];

function fk(root: number[], rots: Quat[][]): number[] {
  return Array.from(forwardKinematics(skeleton, new Float32Array(root), new Float32Array(rots.flat(2))));
}

describe('forwardKinematics', () => {
  it('places the rest pose by offsets', () => {
    expect(fk([1, 2, 3], [[I, I, I]])).toEqual([1, 2, 3, 1, 3, 3, 1, 4, 3]);
  });

  it('uses bone-end semantics: the rotation at a joint turns the segment ending there', () => {
    // Only "mid" rotated 90° about x: the root→mid segment turns from +y to +z, and mid→tip follows.
    const p = fk([0, 0, 0], [[I, eulerToQuat([90 * DEG], 'X'), I]]);
    const expected = [0, 0, 0, 0, 0, 1, 0, 0, 2];
    p.forEach((v, i) => expect(v).toBeCloseTo(expected[i], 6));
  });

  it('composes rotations down the chain (G_j = G_parent · q_j)', () => {
    // root 90° about z: +y → −x. tip 90° about x locally: its segment (+y) → +z locally → still +z globally.
    const p = fk([1, 0, 0], [[eulerToQuat([90 * DEG], 'Z'), I, eulerToQuat([90 * DEG], 'X')]]);
    const expected = [1, 0, 0, 0, 0, 0, 0, 0, 1];
    p.forEach((v, i) => expect(v).toBeCloseTo(expected[i], 6));
  });

  it('handles several frames and unnormalised quaternions', () => {
    const q2: Quat = [0, 0, 2, 0]; // 180° about z, length 2
    const p = fk([0, 0, 0, 0, 1, 0], [[I, I, I], [I, q2, I]]);
    const expected = [0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 1, 0, 0, 0, 0, 0, -1, 0];
    p.forEach((v, i) => expect(v).toBeCloseTo(expected[i], 6));
  });

  it('rejects mismatched array sizes', () => {
    expect(() => forwardKinematics(skeleton, new Float32Array(3), new Float32Array(8))).toThrow(/rotation values/);
    expect(() => forwardKinematics(skeleton, new Float32Array(4), new Float32Array(12))).toThrow(/multiple of 3/);
  });
});

describe('boneLengths', () => {
  it('measures joint-to-parent distances at a frame', () => {
    const motion = {
      fps: 30, frames: 2, joints: skeleton.joints, parents: skeleton.parents,
      positions: new Float32Array([0, 0, 0, 0, 1, 0, 0, 1, 2, 0, 0, 0, 3, 0, 4, 3, 0, 5]),
    };
    expect(Array.from(boneLengths(motion))).toEqual([0, 1, 2]);
    expect(Array.from(boneLengths(motion, 1))).toEqual([0, 5, 1]);
  });
});
