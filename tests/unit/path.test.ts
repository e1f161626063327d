// Ground paths for the path follower (web/optimizer/path.ts): checking user points, resampling,
// smoothing of strokes, projection and headings, against hand-computed geometry.
import { describe, expect, it } from 'vitest';
import { angleDifference, checkPathPoints, GroundPath, MAX_PATH_COORDINATE, moveBack, PATH_SPACING, relativeToStart, type GroundPoint } from '../../web/optimizer/path';
import { readRepoFile } from './corpus';

const BENCHMARK_PATHS: Record<string, GroundPoint[]> = Object.fromEntries(
  Object.entries(JSON.parse(readRepoFile('tests/fixtures/benchmark_paths.json')).paths as Record<string, { points: GroundPoint[] }>).map(([k, v]) => [k, v.points]),
);

describe('checkPathPoints', () => {
  it('accepts [x, z] pairs and names the first bad one', () => {
    expect(checkPathPoints([[0, 0], [1, 2]])).toEqual([[0, 0], [1, 2]]);
    expect(() => checkPathPoints('nope')).toThrow(/array of \[x, z\] pairs/);
    expect(() => checkPathPoints([[0, 0]])).toThrow(/at least 2/);
    expect(() => checkPathPoints([[0, 0], [1, NaN]])).toThrow(/points\[1\] must be a pair of finite numbers/);
    expect(() => checkPathPoints([[0, 0], [1, 2, 3]])).toThrow(/points\[1\]/);
  });

  it('refuses points that float32 positions cannot hold to a millimetre, saying why', () => {
    const edge = MAX_PATH_COORDINATE;
    expect(checkPathPoints([[edge, -edge], [edge - 3, -edge]])).toEqual([[edge, -edge], [edge - 3, -edge]]);
    for (const far of [1e300, 1e15, 1e5, -(edge + 1)]) {
      expect(() => checkPathPoints([[0, 0], [far, 5]])).toThrow(`points[1] [${far}, 5] is too far out: x and z must be within ±10000 m`);
      expect(() => checkPathPoints([[5, far], [0, 0]])).toThrow(/^points\[0\] .* is too far out/);
    }
    // The float32 step at the limit is under a millimetre (at 100 km it is 8 mm).
    expect(Math.fround(edge + 200 + 2 ** -10) - Math.fround(edge + 200)).toBeLessThanOrEqual(0.001);
  });
});

describe('relativeToStart and moveBack', () => {
  it('move a path to the origin and positions back, exactly for exactly representable offsets', () => {
    const { origin, local } = relativeToStart([[9000, -7000], [9000, -6998], [9001.5, -6996.5]]);
    expect(origin).toEqual([9000, -7000]);
    expect(local).toEqual([[0, 0], [0, 2], [1.5, 3.5]]);
    const positions = Float32Array.from([0.25, 1, -0.5, 1.1, 0.9, 3.3]);
    expect(Array.from(moveBack(positions.slice(), origin))).toEqual([9000.25, 1, -7000.5, Math.fround(9000 + Math.fround(1.1)), Math.fround(0.9), Math.fround(-7000 + Math.fround(3.3))]);
  });
});

describe('GroundPath', () => {
  it('resamples a polyline at even arc length and keeps its ends', () => {
    const p = GroundPath.fromPoints([[0, 0], [0, 5], [5, 5]]);
    expect(p.length).toBeCloseTo(10, 6);
    expect(p.spacing).toBeCloseTo(PATH_SPACING, 6);
    expect(p.pointAt(0)).toEqual([0, 0]);
    expect(p.pointAt(p.length)).toEqual([5, 5]);
    const mid = p.pointAt(7.5);
    expect(mid[0]).toBeCloseTo(2.5, 6);
    expect(mid[1]).toBeCloseTo(5, 6);
  });

  it('projects onto the nearest point, within an arc-length window when asked', () => {
    const p = GroundPath.fromPoints(BENCHMARK_PATHS['figure-eight']);
    // The origin is on the path twice: at the start and halfway (where the loops meet).
    const near = p.project(0.1, 0);
    expect(near.distance).toBeLessThan(0.11);
    const late = p.project(0.1, 0, p.length / 2 - 0.5, p.length / 2 + 0.5);
    expect(Math.abs(late.s - p.length / 2)).toBeLessThan(0.2);
    expect(late.distance).toBeLessThan(0.11);
    expect(p.distance(5, 0)).toBeCloseTo(2, 2); // 2 m outside the right loop (which spans x 0…3)
  });

  it('gives the travel heading: 0 along +z, π/2 along +x', () => {
    const p = GroundPath.fromPoints([[0, 0], [0, 5], [5, 5]]);
    expect(p.headingAt(2)).toBeCloseTo(0, 6);
    expect(p.headingAt(8)).toBeCloseTo(Math.PI / 2, 6);
  });

  it('smooths a jittery stroke but keeps where it starts and ends', () => {
    const stroke: [number, number][] = Array.from({ length: 200 }, (_, i) => [((i % 2) - 0.5) * 0.06, i * 0.025]);
    const p = GroundPath.fromStroke(stroke);
    expect(p.pointAt(0)[1]).toBeCloseTo(0, 6);
    expect(p.pointAt(p.length)).toEqual(stroke[stroke.length - 1]);
    const xs = Array.from(p.xs.subarray(5, -5));
    expect(Math.max(...xs.map(Math.abs))).toBeLessThan(0.02); // ±3 cm zig-zag mostly averaged out
  });

  it('refuses paths that are too short or too long', () => {
    expect(() => GroundPath.fromPoints([[0, 0], [0, 0.2]])).toThrow(/at least 0.5 m/);
    expect(() => GroundPath.fromPoints([[0, 0], [0, 500]])).toThrow(/at most 200 m/);
    expect(() => GroundPath.fromPoints([[1, 1], [1, 1]])).toThrow(/at least 0.5 m/);
  });

  it('has the five benchmark paths at their stated sizes', () => {
    const lengths = Object.fromEntries(Object.entries(BENCHMARK_PATHS).map(([k, v]) => [k, GroundPath.fromPoints(v).length]));
    expect(lengths.straight).toBeCloseTo(10, 6);
    expect(lengths.circle).toBeCloseTo(4 * Math.PI, 1);
    expect(lengths.corner).toBeCloseTo(10, 6);
    expect(lengths['figure-eight']).toBeCloseTo(6 * Math.PI, 1);
    expect(lengths['s-curve']).toBeGreaterThan(8);
  });
});

describe('angleDifference', () => {
  it('wraps to (−π, π]', () => {
    expect(angleDifference(0.1, -0.1)).toBeCloseTo(0.2, 12);
    expect(angleDifference(Math.PI - 0.1, -Math.PI + 0.1)).toBeCloseTo(-0.2, 12);
    expect(angleDifference(5 * Math.PI, 0)).toBeCloseTo(Math.PI, 12);
  });
});
