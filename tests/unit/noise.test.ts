import { describe, expect, it } from 'vitest';
import { addNoise, checkNoiseOptions, DRIFT_PERIOD, DRIFT_RAMP, OUTLIER_DISTANCE } from '../../web/motion/noise';
import type { Motion } from '../../web/motion/types';

// A small CMU-BVH-named skeleton (findFootJoints finds LeftFoot/LeftToeBase and RightFoot/RightToeBase).
const JOINTS = ['Hips', 'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'LeftToeBase', 'RightUpLeg', 'RightLeg', 'RightFoot', 'RightToeBase', 'Spine', 'Head'];
const PARENTS = [-1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9];
const REST: [number, number, number][] = [
  [0, 0.95, 0], [0.1, 0.9, 0], [0.1, 0.5, 0], [0.1, 0.08, 0], [0.1, 0.02, 0.12],
  [-0.1, 0.9, 0], [-0.1, 0.5, 0], [-0.1, 0.08, 0], [-0.1, 0.02, 0.12], [0, 1.2, 0], [0, 1.6, 0],
];
const FOOT_CHAINS = new Set([3, 4, 7, 8]);

/** A clip walking slowly along +z with a gentle bob, `frames` long at 30 fps, with contacts. */
function clip(frames = 180): Motion {
  const J = JOINTS.length;
  const positions = new Float32Array(frames * J * 3);
  for (let f = 0; f < frames; f++) {
    REST.forEach(([x, y, z], j) => {
      const i = (f * J + j) * 3;
      positions[i] = x;
      positions[i + 1] = y + 0.02 * Math.sin(f / 4);
      positions[i + 2] = z + 0.01 * f;
    });
  }
  return { fps: 30, frames, joints: [...JOINTS], parents: [...PARENTS], positions, contacts: new Uint8Array(frames * 2).fill(1) };
}

/** Per frame and joint, the noisy position minus the clean one. */
function deltas(clean: Motion, noisy: Motion): [number, number, number][][] {
  const J = clean.joints.length;
  return Array.from({ length: clean.frames }, (_, f) =>
    Array.from({ length: J }, (_, j) => {
      const i = (f * J + j) * 3;
      return [0, 1, 2].map((a) => noisy.positions[i + a] - clean.positions[i + a]) as [number, number, number];
    }),
  );
}

describe('addNoise', () => {
  const all = { jitter: 0.01, outliers: 0.05, drift: 0.3 };

  it('gives the same noise for the same seed and different noise for another', () => {
    const m = clip();
    const a = addNoise(m, { ...all, seed: 7 });
    const b = addNoise(m, { ...all, seed: 7 });
    const c = addNoise(m, { ...all, seed: 8 });
    expect(b.motion.positions).toEqual(a.motion.positions);
    expect(b.outlierFrames).toEqual(a.outlierFrames);
    expect(c.motion.positions).not.toEqual(a.motion.positions);
  });

  it('returns identical positions with no options, a new Motion, and drops contacts', () => {
    const m = clip();
    const { motion, outlierFrames } = addNoise(m, {});
    expect(motion.positions).toEqual(m.positions);
    expect(motion.positions).not.toBe(m.positions);
    expect(outlierFrames).toEqual([]);
    expect(motion.contacts).toBeUndefined();
    expect(motion.joints).toEqual(m.joints);
    expect(motion.parents).toEqual(m.parents);
    expect([motion.fps, motion.frames]).toEqual([m.fps, m.frames]);
  });

  it('jitters with the requested standard deviation and zero mean', () => {
    const m = clip(300);
    const values = deltas(m, addNoise(m, { jitter: 0.02, seed: 3 }).motion).flat(2);
    const mean = values.reduce((s, v) => s + v, 0) / values.length;
    const std = Math.sqrt(values.reduce((s, v) => s + (v - mean) ** 2, 0) / (values.length - 1));
    expect(values.length).toBe(300 * 11 * 3);
    expect(Math.abs(std / 0.02 - 1)).toBeLessThan(0.05);
    expect(Math.abs(mean)).toBeLessThan(0.002);
  });

  it('makes round(share × frames) distinct outlier frames, displaced ≥ 0.15 m there and only there', () => {
    const m = clip(180);
    const jitter = 0.01;
    const { motion, outlierFrames } = addNoise(m, { outliers: 0.1, jitter, seed: 5 });
    expect(outlierFrames.length).toBe(18);
    expect(new Set(outlierFrames).size).toBe(18);
    expect([...outlierFrames].sort((a, b) => a - b)).toEqual(outlierFrames);
    const outlier = new Set(outlierFrames);
    deltas(m, motion).forEach((frame, f) => {
      for (const d of frame) {
        const length = Math.hypot(...d);
        if (outlier.has(f)) expect(length).toBeCloseTo(OUTLIER_DISTANCE + 3 * jitter, 5);
        else expect(length).toBeLessThan(OUTLIER_DISTANCE);
      }
    });
    // Joints of one outlier frame move in different directions: a scrambled pose, not a shifted one.
    const [first] = deltas(m, motion).filter((_, f) => outlier.has(f));
    expect(Math.abs(first[0][0] - first[1][0])).toBeGreaterThan(1e-3);
  });

  it('keeps the outlier frames when only the jitter changes (separate random streams)', () => {
    const m = clip();
    expect(addNoise(m, { outliers: 0.2, seed: 1 }).outlierFrames).toEqual(addNoise(m, { outliers: 0.2, jitter: 0.05, seed: 1 }).outlierFrames);
  });

  it('drifts only the foot chains, only horizontally, rigidly, up to about drift × 2 s', () => {
    const m = clip(360); // 12 s: six drift periods
    const drift = 0.4;
    const d = deltas(m, addNoise(m, { drift, seed: 2 }).motion);
    let largest = 0;
    d.forEach((frame, f) => {
      frame.forEach(([dx, dy, dz], j) => {
        expect(dy).toBe(0);
        if (!FOOT_CHAINS.has(j)) expect([dx, dz]).toEqual([0, 0]);
        largest = Math.max(largest, Math.hypot(dx, dz));
      });
      // Ankle and toe of a side slide together.
      expect(frame[4][0]).toBeCloseTo(frame[3][0], 5);
      expect(frame[8][2]).toBeCloseTo(frame[7][2], 5);
      if (f === 0) expect(Math.hypot(frame[3][0], frame[3][2])).toBe(0);
    });
    expect(largest).toBeGreaterThan(0.9 * drift * DRIFT_PERIOD);
    expect(largest).toBeLessThan(1.05 * drift * DRIFT_PERIOD);
    // No snap at the resets: a step is at most the smoothstep's steepest slope (1.5 / ramp) on the
    // largest offset, plus one frame of drift; a snap would move the whole offset (0.8 m) in one frame.
    const limit = (1.5 * drift * DRIFT_PERIOD) / (DRIFT_RAMP * m.fps) + drift / m.fps + 1e-6;
    let steepest = 0;
    for (let f = 1; f < d.length; f++) {
      steepest = Math.max(steepest, Math.hypot(d[f][3][0] - d[f - 1][3][0], d[f][3][2] - d[f - 1][3][2]));
    }
    expect(steepest).toBeLessThan(limit);
    expect(limit).toBeLessThan(0.25 * drift * DRIFT_PERIOD);
  });

  it('needs feet for drift, but not without it', () => {
    const m = { ...clip(10), joints: JOINTS.map((_, j) => `joint${j}`) };
    expect(() => addNoise(m, { drift: 0.1 })).toThrow(/drift needs the feet/);
    expect(() => addNoise(m, { jitter: 0.01 })).not.toThrow();
  });

  it('leaves the input motion untouched', () => {
    const m = clip();
    const before = { positions: m.positions.slice(), contacts: m.contacts!.slice(), joints: [...m.joints], parents: [...m.parents] };
    addNoise(m, { ...all, seed: 4 });
    expect(m.positions).toEqual(before.positions);
    expect(m.contacts).toEqual(before.contacts);
    expect(m.joints).toEqual(before.joints);
    expect(m.parents).toEqual(before.parents);
  });
});

describe('checkNoiseOptions', () => {
  it('fills in defaults', () => {
    expect(checkNoiseOptions({})).toEqual({ jitter: 0, outliers: 0, drift: 0, seed: 0 });
    expect(checkNoiseOptions({ jitter: 0.5, outliers: 0.5, drift: 5, seed: 12 })).toEqual({ jitter: 0.5, outliers: 0.5, drift: 5, seed: 12 });
    expect(checkNoiseOptions({ jitter: undefined }).jitter).toBe(0);
  });

  it('names the bad option and its value', () => {
    const bad: [unknown, RegExp][] = [
      [null, /options must be an object, got null/],
      [[1], /options must be an object/],
      ['x', /options must be an object, got "x"/],
      [{ jiter: 1 }, /unknown option "jiter"/],
      [{ jitter: 'abc' }, /^noise: jitter must be a number of metres from 0 to 0\.5, got "abc"$/],
      [{ jitter: NaN }, /jitter .* got NaN/],
      [{ jitter: -0.1 }, /jitter .* got -0\.1/],
      [{ jitter: 0.6 }, /jitter .* got 0\.6/],
      [{ outliers: 0.7 }, /outliers must be a share of frames from 0 to 0\.5, got 0\.7/],
      [{ outliers: Infinity }, /outliers .* got Infinity/],
      [{ drift: 6 }, /drift must be a speed in m\/s from 0 to 5, got 6/],
      [{ drift: -1 }, /drift .* got -1/],
      [{ seed: 1.5 }, /seed must be a whole number .* got 1\.5/],
      [{ seed: -2 }, /seed .* got -2/],
      [{ seed: '3' }, /seed .* got "3"/],
      [{ seed: { a: 1 } }, /seed .* got \{"a":1\}/],
    ];
    for (const [options, message] of bad) expect(() => checkNoiseOptions(options), String(message)).toThrow(message);
  });

  it('is what addNoise checks with', () => {
    expect(() => addNoise(clip(10), { jitter: 1 })).toThrow(/noise: jitter/);
  });
});
