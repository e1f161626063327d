// Toe swing per second (web/motion/toeSwing.ts), the measure of running that lasts: real Bandai Namco runs swing
// their toes several times as fast as walks of the same set, a motion made to glide (every frame's pose frozen while
// the root keeps moving) swings nothing, and an anonymous skeleton is measured as its named twin.
import { describe, expect, it } from 'vitest';
import { parseBVH } from '../../web/motion/bvh';
import { toeSwingPerSecond } from '../../web/motion/toeSwing';
import type { Motion } from '../../web/motion/types';
import { readCorpus } from './corpus';

const mean = (v: number[]) => v.reduce((a, b) => a + b, 0) / v.length;
const bandai = (key: string) => parseBVH(readCorpus(`bandai/bvh/dataset-2_${key}.bvh.gz`));

/** The first frame's pose carried along the clip's own root track: the root moves, nothing swings. */
function glide(m: Motion): Motion {
  const J = m.joints.length;
  const positions = new Float32Array(m.positions.length);
  for (let f = 0; f < m.frames; f++) {
    for (let j = 0; j < J; j++) {
      for (let a = 0; a < 3; a++) positions[(f * J + j) * 3 + a] = m.positions[j * 3 + a] + (m.positions[f * J * 3 + a] - m.positions[a]);
    }
  }
  return { ...m, positions };
}

describe('toeSwingPerSecond', () => {
  it('tells running from walking, and a glide from either', () => {
    const run = bandai('run_normal_001');
    const walk = bandai('walk_normal_001');
    const runSwing = toeSwingPerSecond(run);
    const walkSwing = toeSwingPerSecond(walk);
    expect(runSwing.length).toBe(Math.floor((run.frames - 1) / Math.round(run.fps)));
    expect(mean(runSwing)).toBeGreaterThan(1.6 * mean(walkSwing));
    expect(mean(walkSwing)).toBeGreaterThan(0.5);
    expect(Math.max(...toeSwingPerSecond(glide(run)))).toBeLessThan(1e-4);
  });

  it('finds the toes of an anonymous skeleton by its shape', () => {
    const run = bandai('run_normal_001');
    const anonymous = { ...run, joints: run.joints.map((_, i) => `j${i}`) };
    const named = toeSwingPerSecond(run);
    toeSwingPerSecond(anonymous).forEach((v, k) => expect(v).toBeCloseTo(named[k], 6));
  });
});
