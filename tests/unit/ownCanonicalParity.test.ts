// Parity of the canonical points a user's skeleton gives: web/motion/skeletonMap.ts mapSkeleton + toCanonical (the
// page) = training/own/canonical.py map_skeleton + to_canonical (python -m training.own). tests/fixtures/
// own_canonical.json (python -m training.fixtures.own_canonical) holds a few frames of a Bandai Namco walk, the same
// skeleton without toes (toe bases placed ahead of the ankles) and a CMU ASF walk, as the readers give them, with
// Python's mapped joints, leg-length scale and canonical points (the derived ones placed). The page reads positions in
// float32, so points agree to POINT_TOLERANCE (metres) and the scale to SCALE_TOLERANCE (relative).
import { describe, expect, it } from 'vitest';
import { mapSkeleton, toCanonical } from '../../web/motion/skeletonMap';
import type { Motion } from '../../web/motion/types';
import { readRepoFile } from './corpus';

const POINT_TOLERANCE = 1e-5;
const SCALE_TOLERANCE = 1e-6;

interface Case {
  name: string;
  frames: number;
  joints: string[];
  parents: number[];
  positions: number[];
  source: number[];
  scale: number;
  canonical: number[];
}
const fixture = JSON.parse(readRepoFile('tests/fixtures/own_canonical.json')) as { canonical_leg_length: number; cases: Case[] };

describe('canonical points of a user skeleton: web/motion/skeletonMap.ts = training/own/canonical.py', () => {
  it('covers a skeleton without toes and one with every point', () => {
    expect(fixture.cases.some((c) => c.source[4] < 0 && c.source[9] < 0)).toBe(true);
    expect(fixture.cases.some((c) => c.source.every((j) => j >= 0))).toBe(true);
  });

  for (const c of fixture.cases) {
    it(`maps and places the points as Python does: ${c.name}`, () => {
      const motion: Motion = { fps: 30, frames: c.frames, joints: c.joints, parents: c.parents, positions: Float32Array.from(c.positions) };
      const mapping = mapSkeleton(motion, fixture.canonical_leg_length);
      expect(mapping.source).toEqual(c.source);
      expect(Math.abs(mapping.scale / c.scale - 1)).toBeLessThan(SCALE_TOLERANCE);
      const points = toCanonical(motion, mapping);
      let worst = 0;
      points.forEach((v, i) => (worst = Math.max(worst, Math.abs(v - c.canonical[i]))));
      expect(worst).toBeLessThan(POINT_TOLERANCE);
    });
  }
});
