// The foot lock (web/motion/footLock.ts) against training/footlock.py on generator motion
// (tests/fixtures/footlock_reference.json, written by python -m training.fixtures.footlock), and what it
// must do on its own: planted toes stay put and on the ground, bones keep their lengths, no popping.
import { describe, expect, it } from 'vitest';
import { FLAT_PITCH, FOOT_LOCK_DEFAULTS, FootLock, footLock, RELEASE_LIFT, STEEP_PITCH, twoBoneIK } from '../../web/motion/footLock';
import { readRepoFile } from './corpus';
import { footFixture, type FootStream } from './footFixture';

type Stream = FootStream;
const fixture = footFixture;
const refiner = JSON.parse(readRepoFile('public/models/refiner.json')) as { footlock: Record<string, number> };
const { joints, parents, offsets } = fixture;
const J = joints.length;
const TOES = ['LeftToeBase', 'RightToeBase'].map((n) => joints.indexOf(n));

/** Runs the streaming lock over a fixture stream in double precision. */
function lockStream(s: Stream, settings = {}): Float64Array {
  const lock = new FootLock(joints, offsets, settings);
  const out = new Float64Array(s.positions.length);
  const n = J * 3;
  for (let f = 0; f < s.frames; f++) {
    const pose = s.positions.slice(f * n, (f + 1) * n);
    out.set(lock.step(pose, s.contacts.slice(f * 2, f * 2 + 2)), f * n);
  }
  return out;
}

/** Horizontal toe movement (m per frame) between consecutive frames, per foot, for frame pairs that pass `keep`. */
function toeSteps(P: ArrayLike<number>, frames: number, keep: (f: number, side: number) => boolean): number[] {
  const steps: number[] = [];
  for (let f = 1; f < frames; f++) {
    for (let side = 0; side < 2; side++) {
      if (!keep(f, side)) continue;
      const a = ((f - 1) * J + TOES[side]) * 3, b = (f * J + TOES[side]) * 3;
      steps.push(Math.hypot(P[b] - P[a], P[b + 2] - P[a + 2]));
    }
  }
  return steps;
}

const percentile = (values: number[], p: number) => [...values].sort((a, b) => a - b)[Math.min(values.length - 1, Math.floor((p / 100) * values.length))];
const mean = (values: number[]) => values.reduce((a, b) => a + b, 0) / values.length;

describe('foot lock parity with training/footlock.py', () => {
  it('uses the same constants as refiner.json and footlock.py', () => {
    const s = fixture.settings;
    expect(FOOT_LOCK_DEFAULTS).toEqual({
      groundHeight: s.toe_ground_height,
      blendIn: s.blend_in_frames,
      blendOut: s.blend_out_frames,
      reach: s.reach,
      poleBias: s.pole_bias,
    });
    expect([FLAT_PITCH, STEEP_PITCH, RELEASE_LIFT]).toEqual([s.flat_pitch, s.steep_pitch, s.release_lift]);
    expect(refiner.footlock.toe_ground_height).toBe(s.toe_ground_height);
    expect(refiner.footlock.blend_in_frames).toBe(s.blend_in_frames);
    expect(refiner.footlock.blend_out_frames).toBe(s.blend_out_frames);
    expect(refiner.footlock.reach).toBe(s.reach);
  });

  for (const s of fixture.streams) {
    it(`matches within 1 mm on ${s.seed_name} at τ ${s.temperature} (${s.frames} frames)`, () => {
      const out = lockStream(s);
      const legs = fixture.legs.map((n) => joints.indexOf(n));
      let worst = 0;
      for (let f = 0; f < s.frames; f++) {
        legs.forEach((j, k) => {
          for (let d = 0; d < 3; d++) worst = Math.max(worst, Math.abs(out[(f * J + j) * 3 + d] - s.locked_legs[(f * legs.length + k) * 3 + d]));
        });
      }
      expect(worst).toBeLessThan(1e-3);
      expect(worst).toBeLessThan(1e-5); // in fact only the fixture's rounding (1e-6) apart
      // Everything but the legs is untouched.
      for (let f = 0; f < s.frames; f++) {
        for (let j = 0; j < J; j++) {
          if (legs.includes(j)) continue;
          for (let d = 0; d < 3; d++) expect(out[(f * J + j) * 3 + d]).toBe(s.positions[(f * J + j) * 3 + d]);
        }
      }
      // The lock really changed the motion (the comparison is not vacuous).
      expect(Math.max(...s.locked_legs.map((v, i) => Math.abs(v - s.positions[(Math.floor(i / 3 / legs.length) * J + legs[Math.floor(i / 3) % legs.length]) * 3 + (i % 3)])))).toBeGreaterThan(0.05);
    });
  }

  it('footLock over a whole motion equals the per-frame steps (as float32)', () => {
    const s = fixture.streams[1];
    const whole = footLock(Float64Array.from(s.positions), s.contacts, joints, offsets);
    const streamed = Float32Array.from(lockStream(s));
    expect(whole).toEqual(streamed);
    // reset() starts over: the same input gives the same output again.
    const lock = new FootLock(joints, offsets);
    const n = J * 3;
    const first = Array.from(lock.step(s.positions.slice(0, n), [1, 1]));
    lock.step(s.positions.slice(n, 2 * n), [1, 1]);
    lock.reset();
    expect(Array.from(lock.step(s.positions.slice(0, n), [1, 1]))).toEqual(first);
  });
});

describe('foot lock behaviour on generator motion', () => {
  for (const s of fixture.streams) {
    const out = lockStream(s);
    const bothPlanted = (f: number, side: number) => s.contacts[f * 2 + side] > 0 && s.contacts[(f - 1) * 2 + side] > 0;

    it(`${s.seed_name}: planted toes stay put and sit on the ground`, () => {
      const raw = toeSteps(s.positions, s.frames, bothPlanted);
      const locked = toeSteps(out, s.frames, bothPlanted);
      expect(mean(raw)).toBeGreaterThan(0.01); // the raw motion skates (m per frame)
      expect(percentile(locked, 90)).toBeLessThan(1e-9);
      expect(mean(locked)).toBeLessThan(0.1 * mean(raw));
      // At least blendIn frames into a contact the toe is at the ground height (unless out of reach).
      const heights: number[] = [];
      for (let f = FOOT_LOCK_DEFAULTS.blendIn; f < s.frames; f++) {
        for (let side = 0; side < 2; side++) {
          let settled = true;
          for (let k = 0; k <= FOOT_LOCK_DEFAULTS.blendIn; k++) settled &&= s.contacts[(f - k) * 2 + side] > 0;
          if (settled) heights.push(Math.abs(out[(f * J + TOES[side]) * 3 + 1] - FOOT_LOCK_DEFAULTS.groundHeight));
        }
      }
      expect(heights.length).toBeGreaterThan(100);
      expect(percentile(heights, 90)).toBeLessThan(1e-9);
    });

    it(`${s.seed_name}: every bone keeps its length`, () => {
      let worst = 0;
      for (let f = 0; f < s.frames; f++) {
        for (let j = 1; j < J; j++) {
          const a = (f * J + parents[j]) * 3, b = (f * J + j) * 3;
          const len = Math.hypot(out[b] - out[a], out[b + 1] - out[a + 1], out[b + 2] - out[a + 2]);
          const raw = Math.hypot(s.positions[b] - s.positions[a], s.positions[b + 1] - s.positions[a + 1], s.positions[b + 2] - s.positions[a + 2]);
          worst = Math.max(worst, Math.abs(len - raw));
        }
      }
      expect(worst).toBeLessThan(1e-4); // the input is rounded to 10 µm; the lock itself is exact
    });
  }
});

describe('foot lock on a sliding body', () => {
  // One generator pose sliding +x at 2 cm per frame (0.6 m/s) with alternating contacts: planted feet
  // must stay, and the release after each contact must catch up smoothly rather than pop.
  const FRAMES = 120, STEP = 0.02;
  const pose0 = fixture.streams[0].positions.slice(0, J * 3);
  const positions = new Float64Array(FRAMES * J * 3);
  const contacts = new Uint8Array(FRAMES * 2);
  for (let f = 0; f < FRAMES; f++) {
    for (let j = 0; j < J; j++) for (let d = 0; d < 3; d++) positions[(f * J + j) * 3 + d] = pose0[j * 3 + d] + (d === 0 ? STEP * f : 0);
    contacts[f * 2] = f % 20 < 12 ? 1 : 0;
    contacts[f * 2 + 1] = (f + 10) % 20 < 12 ? 1 : 0;
  }
  const locked = footLock(positions, contacts, joints, offsets);
  const jumps = (P: ArrayLike<number>) => toeSteps(P, FRAMES, () => true);

  it('holds planted toes while the body slides', () => {
    const planted = toeSteps(locked, FRAMES, (f, side) => contacts[f * 2 + side] > 0 && contacts[(f - 1) * 2 + side] > 0);
    expect(Math.min(...toeSteps(positions, FRAMES, () => true))).toBeCloseTo(STEP, 9);
    expect(Math.max(...planted)).toBeLessThan(1e-5); // float32 output
  });

  it('releases without popping: bounded per-frame toe jumps, far below an unblended lock', () => {
    const unblended = footLock(positions, contacts, joints, offsets, { blendIn: 0, blendOut: 1 });
    const worst = Math.max(...jumps(locked));
    // A release catches up with a toe that is at most 12 + 6 frames of sliding away, over 6 frames: at most
    // 1.5 / 6 of that distance per frame (smoothstep's steepest slope) plus the body's own step.
    expect(worst).toBeLessThan(0.25 * (12 + 6) * STEP + STEP);
    expect(Math.max(...jumps(unblended))).toBeGreaterThan(10 * STEP);
    expect(worst).toBeLessThan(0.5 * Math.max(...jumps(unblended)));
  });
});

describe('foot lock pieces', () => {
  it('two-bone IK reaches the target with exact bone lengths and bends the knee the raw way', () => {
    const hip: [number, number, number] = [0, 1, 0], knee: [number, number, number] = [0, 0.6, 0.1];
    for (const target of [[0.1, 0.3, 0.2], [0, -2, 0]] as [number, number, number][]) {
      const [k, a] = twoBoneIK(hip, knee, target, 0.4, 0.43, 0.999, null, 0.05);
      expect(Math.hypot(k[0] - hip[0], k[1] - hip[1], k[2] - hip[2])).toBeCloseTo(0.4, 9);
      expect(Math.hypot(a[0] - k[0], a[1] - k[1], a[2] - k[2])).toBeCloseTo(0.43, 9);
      expect(k[2]).toBeGreaterThan(0);
    }
    const [, a] = twoBoneIK(hip, knee, [0.1, 0.3, 0.2], 0.4, 0.43, 0.999, null, 0.05);
    expect(Math.hypot(a[0] - 0.1, a[1] - 0.3, a[2] - 0.2)).toBeLessThan(1e-9);
  });

  it('leaves free feet alone and names missing joints and bad sizes', () => {
    const s = fixture.streams[0];
    const pose = s.positions.slice(0, J * 3);
    expect(Array.from(new FootLock(joints, offsets).step(pose, [0, 0]))).toEqual(pose);
    expect(() => new FootLock(joints.filter((n) => n !== 'LeftFoot'), offsets.slice(3))).toThrow(/missing LeftFoot/);
    expect(() => new FootLock(joints, offsets.slice(3))).toThrow(/offset values/);
    expect(() => new FootLock(joints, offsets).step(pose.slice(3), [0, 0])).toThrow(/position values/);
    expect(() => footLock(new Float32Array(J * 3 * 2), [0, 0], joints, offsets)).toThrow(/contact values/);
  });
});
