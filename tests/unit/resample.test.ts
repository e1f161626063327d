// Moving per-frame values between frame rates (web/motion/resample.ts), as the clean-up does.
import { expect, it } from 'vitest';
import { resampledFrames, resampleLinear, resampleNearest, resampleQuaternions, resampleRobust } from '../../web/motion/resample';

it('counts frames over the same duration and interpolates linearly', () => {
  expect(resampledFrames(121, 120, 30)).toBe(31);
  expect(resampledFrames(1, 120, 30)).toBe(1);
  const ramp = Float32Array.from({ length: 121 }, (_, i) => i / 120); // one value per frame: time in seconds
  const down = resampleLinear(ramp, 1, 120, 30, 31);
  down.forEach((v, f) => expect(v).toBeCloseTo(f / 30, 6));
  const up = resampleLinear(down, 1, 30, 120, 121);
  up.forEach((v, f) => expect(v).toBeCloseTo(f / 120, 6));
});

it('brings frames down with a robust mean: jitter averaged, a one-frame glitch ignored', () => {
  const frames = 121;
  const values = new Float32Array(frames);
  for (let f = 0; f < frames; f++) values[f] = 1 + (f % 2 ? 0.01 : -0.01); // alternating jitter
  values[40] = 5; // a glitch at an output frame's own sample
  const { values: down, window } = resampleRobust(values, 1, 120, 30, 31);
  expect(window).toBe(5);
  expect(Math.abs(down[10] - 1)).toBeLessThan(0.01); // frame 10 is at input frame 40
  for (const v of down) expect(Math.abs(v - 1)).toBeLessThan(0.01);
});

it('interpolates quaternions on the shorter arc, normalised, and bits by the nearest frame', () => {
  const a = [0, 0, 0, 1], b = [0, -Math.sin(0.5), 0, -Math.cos(0.5)]; // b is the same turn as +1 rad about y, sign flipped
  const q = resampleQuaternions(Float32Array.from([...a, ...b]), 1, 1, 2, 3);
  const mid = Array.from(q.subarray(4, 8));
  expect(Math.hypot(...mid)).toBeCloseTo(1, 6);
  expect(Math.abs(mid[1])).toBeCloseTo(Math.sin(0.25), 3); // half way: a quarter radian about y, not through the long way
  expect(Array.from(resampleNearest(Uint8Array.from([0, 1, 1, 0]), 2, 1, 2, 3))).toEqual([0, 1, 1, 0, 1, 0]);
});
