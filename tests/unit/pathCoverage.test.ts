// pathCoverage (web/motion/pathCoverage.ts): the share of a path's length a walk followed within 0.15 m, in
// order, on hand-made walks whose answer is known, and the back-and-forth benchmark path.
import { describe, expect, it } from 'vitest';
import { pathCoverage, rootGroundTrack, type GroundXZ } from '../../web/motion/pathCoverage';
import { readRepoFile } from './corpus';

const BACK_AND_FORTH = (JSON.parse(readRepoFile('tests/fixtures/benchmark_paths.json')).paths['back-and-forth'].points) as GroundXZ[];

/** A walk along a polyline, one point every `step` metres (a 1.1 m/s walk at 30 fps steps 3.7 cm). */
function walkAlong(points: readonly GroundXZ[], step = 0.037): GroundXZ[] {
  const out: GroundXZ[] = [points[0]];
  for (let i = 1; i < points.length; i++) {
    const [ax, az] = points[i - 1], [bx, bz] = points[i];
    const n = Math.max(1, Math.ceil(Math.hypot(bx - ax, bz - az) / step));
    for (let k = 1; k <= n; k++) out.push([ax + ((bx - ax) * k) / n, az + ((bz - az) * k) / n]);
  }
  return out;
}

const offset = (walk: GroundXZ[], dx: number): GroundXZ[] => walk.map(([x, z]) => [x + dx, z]);

describe('pathCoverage', () => {
  const straight: GroundXZ[] = [[0, 0], [0, 10]];

  it('is 1 for a walk on the path, and still for one 0.1 m beside it; 0 for one 0.2 m beside it', () => {
    expect(pathCoverage(straight, walkAlong(straight))).toBeCloseTo(1, 6);
    expect(pathCoverage(straight, offset(walkAlong(straight), 0.1))).toBeCloseTo(1, 6);
    expect(pathCoverage(straight, offset(walkAlong(straight), 0.2))).toBe(0);
    expect(pathCoverage(straight, offset(walkAlong(straight), 0.2), 0.25)).toBeCloseTo(1, 6);
  });

  it('counts the length up to where the walk stopped, plus the tolerance ahead of it', () => {
    expect(pathCoverage(straight, walkAlong([[0, 0], [0, 4]]))).toBeCloseTo(0.415, 2);
    expect(pathCoverage(straight, [[0, 5]])).toBeCloseTo(0.03, 3); // one frame: the 0.3 m around it
  });

  it('does not count a path walked backwards, nor ground covered out of order', () => {
    expect(pathCoverage(straight, walkAlong([[0, 10], [0, 0]]))).toBeCloseTo(0.03, 2);
    // The second half first, then back 1 m aside and the first half: the better of the two halves, not both.
    const twoHalves = walkAlong([[0, 5], [0, 10], [1, 10], [1, 0], [0, 0], [0, 5]]);
    expect(pathCoverage(straight, twoHalves)).toBeLessThan(0.52);
  });

  it('on the back-and-forth path: 1 walked as drawn, the first leg alone a fifth, and a corner cut loses the tip', () => {
    const total = 3 + 2.5 + Math.hypot(0.3, 3) + 2.5 + 3;
    expect(pathCoverage(BACK_AND_FORTH, walkAlong(BACK_AND_FORTH))).toBeCloseTo(1, 6);
    // The first leg; the second runs back over it, but after its tip, so it is not covered but for ~0.3 m: a walk
    // standing 0.15 m before the tip is within 0.15 m of the path from 0.3 m before the tip on the way back.
    const firstLeg = pathCoverage(BACK_AND_FORTH, walkAlong(BACK_AND_FORTH.slice(0, 2)));
    expect(firstLeg).toBeGreaterThan((3 + 0.15) / total);
    expect(firstLeg).toBeLessThan((3 + 0.35) / total);
    // Turning back 0.6 m before the first two upper tips (z 2.4 instead of 3, 2.9 instead of 3.5) skips them.
    const cut: GroundXZ[] = [[0, 0], [0, 2.4], [0, 0.5], [0.3 * 0.8, 2.9], [0.3, 1], [0.3, 4]];
    const cutCoverage = pathCoverage(BACK_AND_FORTH, walkAlong(cut));
    expect(cutCoverage).toBeLessThan(1 - (2 * 2 * 0.45) / total);
    expect(cutCoverage).toBeGreaterThan(0.7);
    // The same walk, and then the skipped tips visited at the end, out of order: no better.
    const lateTips = [...walkAlong(cut), ...walkAlong([[0.3, 4], [0.3, 3.5], [0, 3]])];
    expect(pathCoverage(BACK_AND_FORTH, lateTips)).toBeCloseTo(cutCoverage, 2);
  });

  it('reads the root track from positions and refuses bad input with a short message', () => {
    const positions = Float32Array.from([1, 0.9, 2, 5, 5, 5, 3, 0.9, 4, 6, 6, 6]); // 2 frames × 2 joints
    expect(rootGroundTrack(positions, 2)).toEqual([[1, 2], [3, 4]]);
    expect(() => pathCoverage([[0, 0]], [])).toThrow(/at least 2 points/);
    expect(() => pathCoverage(straight, [], -1)).toThrow(/tolerance must be a positive/);
    expect(pathCoverage(straight, [])).toBe(0);
  });
});
