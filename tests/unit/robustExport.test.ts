// Issue 43 #10: a skeleton whose bones have zero length (every joint at one point) round-trips through BVH.
import { describe, expect, it } from 'vitest';
import { exportBVH } from '../../web/motion/bvh';
import { importMotion } from '../../web/motion/io';
import type { Motion } from '../../web/motion/types';

function worstJointError(a: Motion, b: Motion): number {
  let worst = 0;
  for (let i = 0; i < a.positions.length; i++) worst = Math.max(worst, Math.abs(a.positions[i] - b.positions[i]));
  return worst;
}

function degenerate(frames: number, move: (f: number) => [number, number, number]): Motion {
  const joints = ['Hips', 'Spine', 'Head', 'LeftUpLeg', 'LeftLeg', 'RightUpLeg'];
  const parents = [-1, 0, 1, 0, 3, 0];
  const positions = new Float32Array(frames * joints.length * 3);
  for (let f = 0; f < frames; f++) for (let j = 0; j < joints.length; j++) positions.set(move(f), (f * joints.length + j) * 3);
  return { fps: 30, frames, joints, parents, positions };
}

describe('zero-length bones round-trip through BVH', () => {
  it.each([
    ['still at the origin', (_f: number): [number, number, number] => [0, 0, 0]],
    ['still off the origin', (_f: number): [number, number, number] => [1.5, 0.9, -2]],
    ['moving', (f: number): [number, number, number] => [0.1 * f, 0.9, 0.05 * f]],
  ])('every joint at one point, %s: within 1 mm', (_name, move) => {
    const m = degenerate(5, move);
    const back = importMotion(exportBVH(m), 'bvh');
    expect(back.joints).toEqual(m.joints);
    expect(worstJointError(m, back)).toBeLessThan(1e-3);
  });

  it('some bones of zero length in a figure of normal height', () => {
    const m = degenerate(4, () => [0, 1, 0]);
    const J = m.joints.length;
    for (let f = 0; f < m.frames; f++) {
      m.positions.set([0, 1.7, 0], (f * J + 2) * 3); // the head 70 cm above the hips and the spine (zero length)
      m.positions.set([0.5 * Math.sin(0.3 * f), 1 - 0.5 * Math.cos(0.3 * f), 0], (f * J + 4) * 3); // the left knee swinging on a rigid 50 cm thigh from its hip at the root
    }
    const back = importMotion(exportBVH(m), 'bvh');
    expect(worstJointError(m, back)).toBeLessThan(1e-3);
  });
});
