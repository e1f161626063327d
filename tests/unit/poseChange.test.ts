// Per-second pose change (web/motion/poseChange.ts), the measure of the Dance mode plot: joint speed
// relative to the root only, whole seconds only, the same whether frames come at once or in chunks.
import { describe, expect, it } from 'vitest';
import { PoseChangeMeter, poseChangePerSecond } from '../../web/motion/poseChange';

/** Two joints: a root travelling and turning up and down, and a joint moving away from it along x at `speed` m/s. */
function travelling(frames: number, fps: number, speed: number): Float32Array {
  const p = new Float32Array(frames * 2 * 3);
  for (let f = 0; f < frames; f++) {
    const t = f / fps;
    const root = [3 * t, 0.9 + 0.1 * Math.sin(5 * t), -2 * t];
    p.set(root, f * 6);
    p.set([root[0] + 0.2 + speed * t, root[1] + 0.5, root[2]], f * 6 + 3);
  }
  return p;
}

describe('poseChangePerSecond', () => {
  it('measures joint speed relative to the root, averaged over all joints (the root counts as 0)', () => {
    const values = poseChangePerSecond(travelling(181, 60, 0.6), 2, 60);
    expect(values).toHaveLength(3); // 180 transitions = 3 whole seconds
    for (const v of values) expect(v).toBeCloseTo(0.3, 4);
  });

  it('is 0 for a rigid pose carried around by the root', () => {
    const values = poseChangePerSecond(travelling(121, 60, 0), 2, 60);
    expect(values).toHaveLength(2);
    for (const v of values) expect(v).toBeLessThan(1e-5);
  });

  it('reports only whole seconds', () => {
    expect(poseChangePerSecond(travelling(60, 60, 1), 2, 60)).toHaveLength(0); // 59 transitions
    expect(poseChangePerSecond(travelling(61, 60, 1), 2, 60)).toHaveLength(1);
  });
});

describe('PoseChangeMeter', () => {
  it('gives the same seconds for chunked frames as for the whole motion, each when it completes', () => {
    const positions = travelling(400, 60, 0.8).map((v, i) => v + Math.sin(i * 0.37) * 0.01);
    const whole = poseChangePerSecond(positions, 2, 60);
    const meter = new PoseChangeMeter(2, 60);
    const got: number[] = [];
    const completedAt: number[] = [];
    for (let f = 0; f < 400; f += 37) {
      const done = meter.push(positions.subarray(f * 6, Math.min(400, f + 37) * 6));
      for (const v of done) completedAt.push(f);
      got.push(...done);
    }
    expect(got).toHaveLength(whole.length);
    got.forEach((v, i) => expect(v).toBeCloseTo(whole[i], 10));
    expect(completedAt[0]).toBe(37); // second 0 needs frame 60, in the chunk starting at 37
    meter.reset();
    expect(meter.push(positions.subarray(0, 61 * 6))).toHaveLength(1);
  });

  it('rejects frames of the wrong size', () => {
    expect(() => new PoseChangeMeter(2, 60).push(new Float32Array(7))).toThrow(/not a whole number of 2-joint frames/);
  });
});
