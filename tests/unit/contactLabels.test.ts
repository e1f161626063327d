// Contact labels on the shown motion (web/motion/contactLabels.ts) and what every locomotion mode does with
// them (footLock.ts plantFeet: labels, then the lock), against training/contact_labels.py and footlock.py on
// generator motion (tests/fixtures/footlock_reference.json, python -m training.fixtures.footlock), and the
// independent sliding measure (footSkating.ts lowFootSliding = training/metrics.py low_foot_speeds).
import { describe, expect, it } from 'vitest';
import { ContactLabeller, LABEL_THRESHOLDS, labelContacts } from '../../web/motion/contactLabels';
import { plantFeet } from '../../web/motion/footLock';
import { lowFootSample, lowFootSliding, NEAR_FLOOR } from '../../web/motion/footSkating';
import { footFixture, type FootStream } from './footFixture';

type Stream = FootStream;
const fixture = footFixture;
const { joints, parents, offsets, fps } = fixture;
const J = joints.length;
const motion = (positions: ArrayLike<number>, frames: number) => ({ fps, frames, joints, parents, positions: positions as Float32Array });

describe('contact labels: web/motion/contactLabels.ts = training/contact_labels.py', () => {
  it('uses the same thresholds', () => {
    const t = fixture.label_thresholds;
    expect(LABEL_THRESHOLDS).toEqual({ near: t.near, slow: t.slow, stayNear: t.stay_near, staySlow: t.stay_slow, bitNear: t.bit_near });
    expect(NEAR_FLOOR).toBe(fixture.near_floor);
  });

  for (const s of fixture.streams) {
    it(`${s.seed_name} at τ ${s.temperature}: every frame's labels agree, and plantFeet locks the same legs`, () => {
      expect(s.label_margin).toBeGreaterThan(1e-9); // no height or speed sits on a threshold
      const labels = labelContacts(s.positions, s.contacts, joints, fps);
      const mismatched: string[] = [];
      for (let i = 0; i < s.frames * 2; i++) if (labels[i] !== s.labels[i]) mismatched.push(`frame ${i >> 1} ${i & 1 ? 'right' : 'left'}`);
      expect(mismatched).toEqual([]);
      // The labels are not the bits (the comparison is not vacuous) and plant feet the bits left free.
      expect(labels.some((v, i) => v !== s.contacts[i])).toBe(true);
      const planted = plantFeet(Float64Array.from(s.positions), s.contacts, joints, offsets, fps);
      expect(Array.from(planted.contacts)).toEqual(s.labels);
      const legs = fixture.legs.map((n) => joints.indexOf(n));
      let worst = 0;
      for (let f = 0; f < s.frames; f++) {
        legs.forEach((j, k) => {
          for (let d = 0; d < 3; d++) worst = Math.max(worst, Math.abs(planted.positions[(f * J + j) * 3 + d] - s.planted_legs[(f * legs.length + k) * 3 + d]));
        });
      }
      expect(worst).toBeLessThan(1e-5); // float32 output and the fixture's 1e-6 rounding
    });

    it(`${s.seed_name} at τ ${s.temperature}: the low-foot sliding measure agrees (${s.low_foot.pairs} pairs)`, () => {
      const m = motion(Float64Array.from(s.positions), s.frames);
      expect(lowFootSample(m).count).toBe(s.low_foot.pairs);
      expect(s.low_foot.pairs).toBeGreaterThan(50);
      expect(Math.abs(lowFootSliding(m) - s.low_foot.mean!)).toBeLessThan(1e-9);
    });

    it(`${s.seed_name} at τ ${s.temperature}: planted feet slide less by the independent measure`, () => {
      const raw = lowFootSliding(motion(Float64Array.from(s.positions), s.frames));
      const planted = plantFeet(Float64Array.from(s.positions), s.contacts, joints, offsets, fps);
      expect(lowFootSliding(motion(planted.positions, s.frames))).toBeLessThan(0.5 * raw);
    });
  }
});

describe('contact labels: the rule', () => {
  // One generator pose, its feet put at given heights and moved at given speeds: the lowest foot point decides.
  const pose0 = Float64Array.from(fixture.streams[0].positions.slice(0, J * 3));
  const FEET = [['LeftFoot', 'LeftToeBase', 'LeftToeBase_end'], ['RightFoot', 'RightToeBase', 'RightToeBase_end']].map((g) => g.map((n) => joints.indexOf(n)));
  /** pose0 with the left foot's lowest point at `height` and moved `dx` along x; the right foot high. */
  function pose(height: number, dx: number): Float64Array {
    const p = pose0.slice();
    const low = Math.min(...FEET[0].map((j) => p[j * 3 + 1]));
    for (const j of FEET[0]) {
      p[j * 3] += dx;
      p[j * 3 + 1] += height - low;
    }
    for (const j of FEET[1]) p[j * 3 + 1] += 0.5;
    return p;
  }
  const run = (frames: { h: number; v: number; bit: number }[]) => {
    const labeller = new ContactLabeller(joints, fps);
    let x = 0;
    return frames.map(({ h, v, bit }) => {
      x += v / fps;
      return labeller.step(pose(h, x), [bit, 0])[0];
    });
  };

  it('plants a foot resting on the floor whose bit is off, and only while it is slow', () => {
    expect(run([{ h: 0.01, v: 0, bit: 0 }, { h: 0.01, v: 0.5, bit: 0 }])).toEqual([1, 1]);
    expect(run([{ h: 0.01, v: 0, bit: 0 }, { h: 0.01, v: 2.5, bit: 0 }])).toEqual([1, 0]);
    expect(run([{ h: 0.2, v: 3, bit: 0 }, { h: 0.03, v: 3, bit: 0 }, { h: 0.03, v: 3, bit: 0 }])).toEqual([0, 0, 0]); // a swing skimming the floor
  });

  it('keeps a planted foot through the hysteresis band and drops it above', () => {
    const T = LABEL_THRESHOLDS;
    const between = (T.near + T.stayNear) / 2, slowish = (T.slow + T.staySlow) / 2;
    expect(run([{ h: 0.01, v: 0, bit: 0 }, { h: between, v: 0, bit: 0 }, { h: 0.01, v: slowish, bit: 0 }, { h: T.stayNear + 0.01, v: 0, bit: 0 }])).toEqual([1, 1, 1, 0]);
    expect(run([{ h: between, v: 0, bit: 0 }])).toEqual([0]); // the band does not plant a free foot
  });

  it('trusts the bit near the floor but not in the air', () => {
    expect(run([{ h: 0.08, v: 3, bit: 1 }])).toEqual([1]);
    expect(run([{ h: 0.2, v: 0, bit: 1 }])).toEqual([0]);
  });

  it('names missing joints and refuses bad sizes', () => {
    expect(() => new ContactLabeller(['Hips', 'LeftFoot'], 30)).toThrow(/^contact labels needs the leg joints .*; missing LeftUpLeg, LeftLeg, LeftToeBase, LeftToeBase_end, RightUpLeg/);
    expect(() => labelContacts(new Float64Array(J * 3 * 2), new Uint8Array(3), joints, fps)).toThrow(/3 contact values for 2 frames/);
  });
});
