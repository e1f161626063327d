// web/motion/motionStats.ts, the Clean up panel's numbers: jerk of a known cubic, measuring at 30 fps, bone-length
// change, joint error, bend angles of a known knee, and on a real CMU clip sliding and jerk that noise raises and a
// skeleton whose knees are renamed refused.
import { describe, expect, it } from 'vitest';
import { parseAMC } from '../../web/motion/asfamc';
import {
  atRate, bendAngles, bendJoints, boneLengthChange, canonicalView, cleanupNumbers, footSliding, jerk, meanJointError,
} from '../../web/motion/motionStats';
import { addNoise } from '../../web/motion/noise';
import type { Motion } from '../../web/motion/types';
import { readCorpus } from './corpus';

/** A 3-joint chain hip → knee → ankle: the thigh hangs down 0.4 m, the shin at `bend(f)` radians from straight. */
function leg(frames: number, fps: number, bend: (f: number) => number, shin = 0.4): Motion {
  const positions = new Float32Array(frames * 9);
  for (let f = 0; f < frames; f++) {
    const a = bend(f);
    positions.set([0, 1, 0, 0, 0.6, 0, 0, 0.6 - shin * Math.cos(a), shin * Math.sin(a)], f * 9);
  }
  return { fps, frames, joints: ['hip', 'knee', 'ankle'], parents: [-1, 0, 1], positions };
}

const clip = parseAMC(readCorpus('cmu/amc/35_13.amc.gz'), readCorpus('cmu/asf/35.asf'), { fps: 120 });

describe('motionStats', () => {
  it('jerk is the mean third difference × fps³: 6 m/s³ for x = t³, 0 for a straight line', () => {
    const fps = 30, frames = 40;
    const cubic: Motion = { fps, frames, joints: ['a'], parents: [-1], positions: new Float32Array(frames * 3) };
    const line: Motion = { ...cubic, positions: new Float32Array(frames * 3) };
    for (let f = 0; f < frames; f++) {
      cubic.positions[f * 3] = (f / fps) ** 3;
      line.positions[f * 3 + 2] = 0.05 * f;
    }
    expect(jerk(cubic)).toBeCloseTo(6, 2);
    expect(jerk(line)).toBeLessThan(0.05); // float32 rounding × fps³
    expect(jerk({ ...cubic, frames: 3, positions: cubic.positions.slice(0, 9) })).toBeNaN();
  });

  it('atRate keeps every step-th frame (120 → 30 fps) and leaves a 30 fps motion as it is', () => {
    const m = leg(121, 120, (f) => f / 100);
    const m30 = atRate(m);
    expect(m30.fps).toBe(30);
    expect(m30.frames).toBe(31);
    expect(Array.from(m30.positions.subarray(9, 18))).toEqual(Array.from(m.positions.subarray(36, 45)));
    const same = leg(10, 30, () => 0);
    expect(atRate(same)).toBe(same);
  });

  it('bone-length change is 0 for a rigid motion and the mean stretch from the median otherwise', () => {
    const rigid = leg(10, 30, (f) => f / 10);
    expect(boneLengthChange(rigid)).toBeCloseTo(0, 6);
    // Shin 0.4 m in 6 frames, 0.5 m in 4: median 0.4, so the mean change over 2 bones × 10 frames is 4 × 0.1 / 20.
    const stretched = leg(10, 30, () => 0.3);
    const longer = leg(10, 30, () => 0.3, 0.5);
    stretched.positions.set(longer.positions.subarray(0, 4 * 9));
    expect(boneLengthChange(stretched)).toBeCloseTo(0.02, 5);
    // Against another motion's lengths: the rigid 0.4 m shin against 0.5 m.
    expect(boneLengthChange(rigid, leg(10, 30, () => 0, 0.5))).toBeCloseTo(0.05, 5);
  });

  it('mean joint error is the mean distance per joint and frame', () => {
    const a = leg(5, 30, () => 0);
    const b: Motion = { ...a, positions: a.positions.slice() };
    for (let f = 0; f < 5; f++) b.positions[f * 9 + 6] += 0.03; // the ankle 3 cm off: 1 joint in 3
    expect(meanJointError(a, b)).toBeCloseTo(0.01, 6);
    expect(() => meanJointError(a, leg(4, 30, () => 0))).toThrow(/5 frames × 3 joints against 4 × 3/);
  });

  it('bend angles are the angle between the bone in and the bone out, in degrees', () => {
    const m = leg(3, 30, (f) => [0, Math.PI / 2, Math.PI / 4][f]);
    expect(bendJoints(m.parents)).toEqual([{ joint: 1, child: 2 }]);
    const angles = Array.from(bendAngles(m, 1));
    expect(angles[0]).toBeCloseTo(0, 3);
    expect(angles[1]).toBeCloseTo(90, 3);
    expect(angles[2]).toBeCloseTo(45, 3);
    expect(() => bendAngles(m, 2)).toThrow(/ankle has no bone into it and out of it/);
  });

  it('on a CMU clip: noise raises jerk, sliding and bone change; the clean original gives the joint error', () => {
    const noisy = addNoise(clip, { jitter: 0.03, outliers: 0.01, seed: 1 }).motion;
    const clean = cleanupNumbers(clip);
    const dirty = cleanupNumbers(noisy, { original: clip });
    expect(Number.isFinite(clean.sliding)).toBe(true);
    expect(dirty.jerk).toBeGreaterThan(3 * clean.jerk);
    expect(dirty.sliding).toBeGreaterThan(clean.sliding);
    expect(dirty.boneChange).toBeGreaterThan(clean.boneChange + 0.01);
    expect(dirty.error).toBeGreaterThan(0.03); // about √3 × 3 cm × √(2/π)·… for 3D jitter
    expect(dirty.error).toBeLessThan(0.08);
    expect(clean.error).toBeNaN();
    // The same floor for both: sliding of the noisy clip above the clean clip's floor.
    expect(footSliding(noisy, -10)).toBeNaN(); // no foot within 4 cm of a floor 10 m down
  });

  it('a skeleton that is not a humanoid (every joint on one chain) has no canonical view, and no sliding number', () => {
    const renamed: Motion = { ...clip, parents: clip.parents.map((_, j) => j - 1) };
    expect(() => canonicalView(renamed)).toThrow(/not a humanoid the playground can map/);
    const numbers = cleanupNumbers(renamed);
    expect(numbers.sliding).toBeNaN();
    expect(Number.isFinite(numbers.jerk)).toBe(true);
  });
});
