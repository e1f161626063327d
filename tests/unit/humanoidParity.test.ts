// Parity of the humanoid skeleton mapper: web/motion/humanoid.ts mapHumanoid = training/mocap/humanoid.py
// map_humanoid. tests/fixtures/humanoid_map.json (python -m training.fixtures.humanoid_map) holds made-up skeletons
// of many naming schemes (CMU BVH and ASF, Mixamo in centimetres, Unreal, VRM, Bandai Namco, Daz without toes,
// iClone, a 3ds Max Biped in an A-pose, anonymous names with the sides told by the pose) posed over a few frames,
// and a few that are not humanoids, with Python's answer: the joint at each canonical point, the naming scheme, how
// the sides were told and the facing, or the error message; and the naming schemes' tables, normalised names and
// side votes of name pairs. The positions are stored rounded, so both sides read the same numbers: the joints chosen
// must be the same, the facing within 1e-4.
import { describe, expect, it } from 'vitest';
import { CANONICAL_JOINTS, mapHumanoid, NAME_SCHEMES, normaliseName, sideByNames, SkeletonMapError } from '../../web/motion/humanoid';
import { readRepoFile } from './corpus';

interface Case {
  name: string;
  joints: string[];
  parents: number[];
  frames: number;
  positions: number[];
  source?: string[];
  scheme?: string;
  sides_by?: 'names' | 'pose';
  facing?: [number, number];
  height?: number;
  error?: string;
}

interface Fixture {
  canonical_joints: string[];
  schemes: Array<{ name: string; points: Record<string, string[]> }>;
  normalised: Array<[string, string]>;
  sides: Array<[string, string, number]>;
  cases: Case[];
}

const fixture = JSON.parse(readRepoFile('tests/fixtures/humanoid_map.json')) as Fixture;

/** What the page answers for a case, in the fixture's terms (joint names, '' where a point is derived). */
function pageAnswer(c: Case): Partial<Case> {
  try {
    const m = mapHumanoid({ joints: c.joints, parents: c.parents, frames: c.frames, positions: c.positions });
    return { source: m.source.map((j) => (j >= 0 ? c.joints[j] : '')), scheme: m.scheme, sides_by: m.sidesBy, facing: m.facing, height: m.height };
  } catch (e) {
    if (!(e instanceof SkeletonMapError)) throw e;
    return { error: e.message };
  }
}

describe('humanoid mapper: web/motion/humanoid.ts = training/mocap/humanoid.py', () => {
  it('covers the naming schemes, sides by the pose and skeletons that are not humanoids', () => {
    expect(fixture.canonical_joints).toEqual([...CANONICAL_JOINTS]);
    const mapped = fixture.cases.filter((c) => !c.error);
    expect(new Set(mapped.map((c) => c.scheme)).size).toBeGreaterThanOrEqual(9);
    expect(mapped.some((c) => c.sides_by === 'pose' && c.frames > 48)).toBe(true);
    expect(new Set(fixture.cases.filter((c) => c.error).map((c) => c.error)).size).toBeGreaterThanOrEqual(4);
  });

  it('has the same naming schemes, normalised names and side words as Python', () => {
    expect(NAME_SCHEMES.map((s) => ({ name: s.name, points: s.points }))).toEqual(fixture.schemes);
    expect(fixture.normalised.filter(([name, n]) => normaliseName(name) !== n)).toEqual([]);
    expect(fixture.sides.filter(([a, b, vote]) => sideByNames(a, b) !== vote)).toEqual([]);
  });

  it('puts every canonical point on the same joint as Python, or refuses with the same message', () => {
    const differing: string[] = [];
    for (const c of fixture.cases) {
      const page = pageAnswer(c);
      if (c.error !== undefined || page.error !== undefined) {
        if (page.error !== c.error) differing.push(`${c.name}: the page says ${page.error ?? 'mapped'}, Python ${c.error ?? 'mapped'}`);
        continue;
      }
      const points = CANONICAL_JOINTS.flatMap((p, k) => (page.source![k] !== c.source![k] ? [`${p} ${page.source![k] || '-'} (Python ${c.source![k] || '-'})`] : []));
      if (points.length) differing.push(`${c.name}: ${points.join(', ')}`);
      if (page.scheme !== c.scheme) differing.push(`${c.name}: scheme ${page.scheme}, Python ${c.scheme}`);
      if (page.sides_by !== c.sides_by) differing.push(`${c.name}: sides by ${page.sides_by}, Python ${c.sides_by}`);
      const turn = Math.hypot(page.facing![0] - c.facing![0], page.facing![1] - c.facing![1]);
      if (!(turn <= 1e-4)) differing.push(`${c.name}: facing ${page.facing}, Python ${c.facing}`);
      if (!(Math.abs(page.height! - c.height!) <= 1e-5 * c.height!)) differing.push(`${c.name}: height ${page.height}, Python ${c.height}`);
    }
    expect(differing).toEqual([]);
  });
});
