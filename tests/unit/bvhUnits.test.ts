// Unit detection on the Bandai Namco BVH files (issue 39): centimetres, a rest pose lying flat (spine and legs along
// x, the hips 93 cm above a root joint on the floor), so the rest figure's height says nothing of the unit. Read as
// inches they made a 3.5–4 m figure; the detection measures the posed figure too. CMU BVH (CMU units), the acLSTM
// set (centimetres, standing rest) and metre/centimetre exports must still read as before.
import { readdirSync } from 'node:fs';
import { describe, expect, it } from 'vitest';
import { parseBVH, exportBVH } from '../../web/motion/bvh';
import type { Motion } from '../../web/motion/types';
import { CORPUS_ROOT, readCorpus } from './corpus';
import { jointHeights, jointIndex, maxHeight, position } from './motionStats';

/** The figure's standing height: the median over frames of its joints' vertical extent (m). */
function standingHeight(m: Motion): number {
  const heights = jointHeights(m).sort((a, b) => a - b);
  return heights[heights.length >> 1];
}

describe('BVH unit detection on the Bandai Namco set', () => {
  const files = readdirSync(CORPUS_ROOT + 'bandai/bvh').sort();
  // One file of each content, over several styles.
  const picked = ['walk_normal_001', 'walk-turn-left_elderly_003', 'walk-turn-right_feminine_010', 'run_exhausted_005', 'run_youthful_020']
    .map((key) => files.find((f) => f.includes(`dataset-2_${key}`))!);

  // The joints span floor to skull base (Head's End Site has a zero offset: no head top), about 1.35 m of a figure
  // some 1.6 m tall; read as inches the same joints spanned 3.4 m.
  it.each(picked)('reads %s as centimetres: joints spanning 1.3–1.9 m, hips at about 0.9 m', (file) => {
    const m = parseBVH(readCorpus(`bandai/bvh/${file}`));
    const h = standingHeight(m);
    expect(h).toBeGreaterThan(1.3);
    expect(h).toBeLessThan(1.9);
    expect(maxHeight(m)).toBeLessThan(2.1);
    const hips = jointIndex(m, 'Hips');
    const hipHeight = position(m, 0, hips)[1];
    expect(hipHeight).toBeGreaterThan(0.7);
    expect(hipHeight).toBeLessThan(1.1);
    // The same as the explicit centimetre reading.
    const cm = parseBVH(readCorpus(`bandai/bvh/${file}`), { unitScale: 0.01 });
    expect(m.positions[hips * 3 + 1]).toBeCloseTo(cm.positions[hips * 3 + 1], 6);
  });
});

describe('BVH unit detection elsewhere, unchanged', () => {
  it('reads CMU BVH in CMU units (0.0254 / 0.45 m): a 1.3–1.9 m figure', () => {
    for (const file of ['07_04', '07_12', '08_05', '09_01']) {
      const text = readCorpus(`cmu/bvh/${file}.bvh.gz`);
      const m = parseBVH(text);
      expect(standingHeight(m)).toBeGreaterThan(1.3);
      expect(standingHeight(m)).toBeLessThan(1.9);
      const cmu = parseBVH(text, { unitScale: 0.0254 / 0.45 });
      expect(m.positions[1]).toBeCloseTo(cmu.positions[1], 6);
    }
  });

  it('reads the acLSTM standard skeleton as centimetres', () => {
    const m = parseBVH(readCorpus('aclstm/standard.bvh.gz'));
    expect(m.positions[1]).toBeCloseTo(0.851887, 5);
  });

  it('reads a 1.7 m figure exported in centimetres back as centimetres, whatever its first frame', () => {
    // A first frame lying down, then standing: the posed height is the median over sampled frames.
    const joints = ['hips', 'head', 'foot'];
    const standing = [0, 0.9, 0, 0, 1.7, 0, 0, 0, 0];
    const lying = [0, 0.1, 0, 0.8, 0.1, 0, -0.9, 0.1, 0];
    const frames = [lying, ...Array.from({ length: 9 }, () => standing)];
    const m: Motion = { fps: 30, frames: frames.length, joints, parents: [-1, 0, 0], positions: new Float32Array(frames.flat()) };
    const back = parseBVH(exportBVH(m));
    expect(back.positions[3 * 3 * 5 + 3 + 1]).toBeCloseTo(1.7, 4);
  });
});
