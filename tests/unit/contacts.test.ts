import { describe, expect, it } from 'vitest';
import { CONTACT_THRESHOLDS, detectContacts, findFootJoints, footJointsOf, percentile } from '../../web/motion/contacts';
import { parseAMC } from '../../web/motion/asfamc';
import { parseBVH } from '../../web/motion/bvh';
import type { Motion } from '../../web/motion/types';
import { readCorpus } from './corpus';

/** Fraction of frames in contact and number of touch-downs per foot. */
function summary(m: Motion, contacts: Uint8Array) {
  return [0, 1].map((side) => {
    let on = 0, touchDowns = 0;
    for (let f = 0; f < m.frames; f++) {
      const c = contacts[f * 2 + side];
      on += c;
      if (c && (f === 0 || !contacts[(f - 1) * 2 + side])) touchDowns++;
    }
    return { fraction: on / m.frames, touchDowns };
  });
}

function expectWalkingContacts(m: Motion, minSteps: number, maxNeither: number) {
  const contacts = detectContacts(m)!;
  expect(contacts).toBeInstanceOf(Uint8Array);
  expect(contacts.length).toBe(m.frames * 2);
  for (const { fraction, touchDowns } of summary(m, contacts)) {
    expect(fraction).toBeGreaterThan(0.3);
    expect(fraction).toBeLessThan(0.8);
    expect(touchDowns).toBeGreaterThanOrEqual(minSteps);
  }
  // Walking alternates: mostly at least one foot is down, and each foot is often the only one down.
  let none = 0, leftOnly = 0, rightOnly = 0;
  for (let f = 0; f < m.frames; f++) {
    const l = contacts[f * 2], r = contacts[f * 2 + 1];
    if (!l && !r) none++;
    if (l && !r) leftOnly++;
    if (r && !l) rightOnly++;
  }
  expect(none / m.frames).toBeLessThan(maxNeither);
  expect(leftOnly / m.frames).toBeGreaterThan(0.15);
  expect(rightOnly / m.frames).toBeGreaterThan(0.15);
}

describe('detectContacts on real walks', () => {
  it('finds alternating steps in the ASF/AMC walk 16_11', () => {
    expectWalkingContacts(parseAMC(readCorpus('cmu/amc/16_11.amc.gz'), readCorpus('cmu/asf/16.asf')), 2, 0.1);
  });

  it('finds alternating steps in the CMU BVH walk 07_04', () => {
    // This clip's floor is not level (the stance toe height drifts from about 1 cm to 6 cm), so the
    // fixed thresholds miss part of the right foot's later stances: neither foot is down in ~17% of frames.
    expectWalkingContacts(parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz')), 2, 0.25);
  });
});

describe('findFootJoints', () => {
  it('uses ASF bone-end names: ankle = ltibia, toe = lfoot', () => {
    const joints = ['root', 'lfemur', 'ltibia', 'lfoot', 'ltoes', 'rfemur', 'rtibia', 'rfoot', 'rtoes'];
    expect(findFootJoints(joints, 'left')).toEqual({ ankle: 2, toe: 3 });
    expect(findFootJoints(joints, 'right')).toEqual({ ankle: 6, toe: 7 });
  });

  it('uses CMU BVH / canonical names and acLSTM names', () => {
    const cmu = ['Hips', 'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'LeftToeBase', 'LeftToeBase_end'];
    expect(findFootJoints(cmu, 'left')).toEqual({ ankle: 3, toe: 4 });
    expect(findFootJoints(['hip', 'rThigh', 'rShin', 'rFoot', 'rFoot_end'], 'right')).toEqual({ ankle: 3, toe: 4 });
    expect(findFootJoints(['mixamorig:Hips', 'mixamorig:RightFoot', 'mixamorig:RightToeBase'], 'right')).toEqual({ ankle: 1, toe: 2 });
  });

  it('gives up on unknown names', () => {
    expect(findFootJoints(['a', 'b', 'c'], 'left')).toBeUndefined();
    const m: Motion = { fps: 30, frames: 1, joints: ['a', 'b'], parents: [-1, 0], positions: new Float32Array(6) };
    expect(detectContacts(m)).toBeUndefined();
  });
});

describe('detectContacts rules', () => {
  const FPS = 100;
  type Path = (t: number) => [number, number, number];
  /** Synthetic feet: ankle and toe paths for each side as functions of time (s). */
  function feet(frames: number, leftAnkle: Path, leftToe: Path, rightAnkle: Path, rightToe: Path): Motion {
    const joints = ['Hips', 'LeftFoot', 'LeftToeBase', 'RightFoot', 'RightToeBase'];
    const positions = new Float32Array(frames * joints.length * 3);
    for (let f = 0; f < frames; f++) {
      const t = f / FPS;
      positions.set([0, 1, 0, ...leftAnkle(t), ...leftToe(t), ...rightAnkle(t), ...rightToe(t)], f * joints.length * 3);
    }
    return { fps: FPS, frames, joints, parents: [-1, 0, 1, 0, 3], positions };
  }
  const still = (x: number, y: number, z: number): Path => () => [x, y, z];

  it('marks a planted foot, and not a foot sliding fast along the ground', () => {
    // The left foot slides along the floor at 2 m/s; the right one stands still.
    const m = feet(200, (t) => [0.1, 0.08, 2 * t - 0.15], (t) => [0.1, 0, 2 * t], still(-0.1, 0.08, -0.15), still(-0.1, 0, 0));
    const c = detectContacts(m)!;
    for (let f = 0; f < m.frames; f++) {
      expect(c[f * 2]).toBe(0);
      expect(c[f * 2 + 1]).toBe(1);
    }
  });

  it('has hysteresis: the toe turns on below 4 cm and off only at 6 cm', () => {
    // Toe height follows straight ramps (0.25 m/s at most, so speed never matters) through these knots,
    // 20 frames apart. The ankle moves sideways at 1 m/s, so the ankle rule never holds.
    const knots = [0, 0, 0.05, 0.055, 0.03, 0.08, 0.05, 0.035, 0, 0];
    const toeY = (t: number) => {
      const k = Math.min(t * FPS / 20, knots.length - 1);
      const i = Math.min(Math.floor(k), knots.length - 2);
      return knots[i] + (knots[i + 1] - knots[i]) * (k - i);
    };
    const frames = (knots.length - 1) * 20 + 1;
    const m = feet(frames, (t) => [t, 0.1, 0], (t) => [0, toeY(t), 0], still(-0.1, 0.08, -0.15), still(-0.1, 0, 0));
    const c = detectContacts(m)!;
    // The 5th-percentile floor of the toe is 0 (it rests at 0 at both ends).
    expect(knots.map((_, k) => c[k * 20 * 2])).toEqual([1, 1, 1, 1, 1, 0, 0, 1, 1, 1]);
  });

  it('exports its thresholds', () => {
    expect(CONTACT_THRESHOLDS).toMatchObject({ ankleOnHeight: 0.05, toeOnHeight: 0.04, onSpeed: 0.5, ankleOffHeight: 0.07, toeOffHeight: 0.06, offSpeed: 0.75 });
  });
});

describe('percentile', () => {
  it('interpolates linearly like numpy', () => {
    expect(percentile([4, 1, 3, 2], 5)).toBeCloseTo(1.15, 12);
    expect(percentile([5], 5)).toBe(5);
    expect(percentile([0, 10], 50)).toBe(5);
  });
});

describe('footJointsOf', () => {
  it('finds the feet of a skeleton whose names no rule knows by the humanoid mapper, with the same contacts', () => {
    const named = parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz'));
    const nameless = { ...named, joints: named.joints.map((_, j) => `bone${j}`) };
    expect(findFootJoints(nameless.joints, 'left')).toBeUndefined();
    expect(footJointsOf(nameless)).toEqual(footJointsOf(named));
    expect(detectContacts(nameless)).toEqual(detectContacts(named));
  });

  it('gives a Bandai Namco walk (Foot_L, Toes_L) contacts on both feet', () => {
    const m = parseBVH(readCorpus('bandai/bvh/dataset-2_walk_normal_001.bvh.gz'), { unitScale: 0.01 });
    const [left, right] = footJointsOf(m)!;
    expect([m.joints[left.ankle], m.joints[left.toe], m.joints[right.ankle], m.joints[right.toe]]).toEqual(['Foot_L', 'Toes_L', 'Foot_R', 'Toes_R']);
    const contacts = detectContacts(m)!;
    for (const { fraction, touchDowns } of summary(m, contacts)) {
      expect(fraction).toBeGreaterThan(0.2);
      expect(touchDowns).toBeGreaterThanOrEqual(3);
    }
  });

  it('is undefined for a skeleton that is not a humanoid', () => {
    const m = parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz'));
    expect(footJointsOf({ ...m, joints: m.joints.map((_, j) => `bone${j}`), parents: m.parents.map((_, j) => j - 1) })).toBeUndefined();
  });
});
