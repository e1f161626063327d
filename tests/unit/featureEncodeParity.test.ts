// Parity of the generator's feature encoding: web/model/featureEncode.ts = training/data/features.py FeatureCodec.encode.
// tests/fixtures/feature_encoding.json (python -m training.fixtures.feature_encoding) holds a few real frames of a
// walk, a run and a pirouette (heading across ±π) as the Python loader gives them: canonical positions, world segment
// rotations, contacts, and the feature rows Python makes of them with generator.json's references. Row t describes
// frame t relative to frame t − 1, so Python has rows for frames 1.. only; the page's made-up row 0 is not compared.
//
// Two checks:
// - encodeFeatures on Python's world rotations is the same rule: every column must agree to float32 rounding
//   (ENCODE_TOLERANCE, metres or radians; the page holds rotations and rows in float32);
// - the page's inverse kinematics from positions alone (canonicalRotations) must point every segment where Python's
//   rotations point it (SEGMENT_TOLERANCE rad). Positions do not show a segment's twist about itself, which the IK
//   picks as the likeliest, so its rotation vectors may differ from Python's (by up to 0.86 rad, a forearm's twist, on
//   these frames) and are not compared; the pelvis's heading follows its children's best fit, so the root channels
//   get the bounds measured here (0.024 rad heading change and 4.7 mm step on the pirouette, 1.5e-3 rad and 0.3 mm
//   on the walk) with about 1.5x room: ROOT_STEP_TOLERANCE, HEADING_TOLERANCE; the root height is a position.
import { describe, expect, it } from 'vitest';
import { canonicalRotations, encodeFeatures } from '../../web/model/featureEncode';
import { quatRotate, type Quat, type Vec3 } from '../../web/motion/math';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { readRepoFile } from './corpus';

const ENCODE_TOLERANCE = 1e-6; // measured: 1.1e-7
const SEGMENT_TOLERANCE = 1e-5; // rad; measured: 8.8e-7
const ROOT_STEP_TOLERANCE = 0.007; // m
const HEADING_TOLERANCE = 0.035; // rad
const HEIGHT_TOLERANCE = 1e-6; // m

interface Case {
  name: string;
  source: string;
  frames: number;
  positions: number[];
  world_rotations: number[];
  contacts: number[];
  features: number[];
}
interface Fixture {
  joints: string[];
  dim: number;
  feature_names: string[];
  cases: Case[];
}

const fixture = JSON.parse(readRepoFile('tests/fixtures/feature_encoding.json')) as Fixture;
const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');
const D = fixture.dim;

/** The page's rows for frames 1.. of a case, given world rotations (frames × joints × 4). */
function pageRows(c: Case, world: Float32Array): Float32Array {
  return encodeFeatures(info, Float32Array.from(c.positions), world, Uint8Array.from(c.contacts)).features.subarray(D);
}

/** The largest angle (rad) between where two sets of world rotations point each modelled segment (its rest offset turned). */
function worstSegmentAngle(a: ArrayLike<number>, b: ArrayLike<number>, frames: number): { angle: number; where: string } {
  const { offsets, joints } = info.skeleton;
  const fixed = new Set(info.features.fixed_joints);
  const J = joints.length;
  let worst = { angle: 0, where: '' };
  for (let f = 0; f < frames; f++) {
    for (let j = 1; j < J; j++) {
      if (fixed.has(j)) continue;
      const offset: Vec3 = [offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]];
      const q = (w: ArrayLike<number>): Quat => [0, 1, 2, 3].map((i) => w[(f * J + j) * 4 + i]) as Quat;
      const u = quatRotate(q(a), offset), v = quatRotate(q(b), offset);
      const cos = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (Math.hypot(...u) * Math.hypot(...v));
      const angle = Math.acos(Math.min(1, cos));
      if (angle > worst.angle) worst = { angle, where: `frame ${f} ${joints[j]}` };
    }
  }
  return worst;
}

/** Per feature column, the largest |page − Python| over the case's rows. */
function worstByColumn(c: Case, rows: Float32Array): number[] {
  const worst = new Array<number>(D).fill(0);
  for (let i = 0; i < c.features.length; i++) worst[i % D] = Math.max(worst[i % D], Math.abs(rows[i] - c.features[i]));
  return worst;
}

function above(worst: number[], limit: (column: number) => number): string[] {
  return worst.flatMap((w, k) => (w > limit(k) ? [`${fixture.feature_names[k]}: ${w.toExponential(2)}`] : []));
}

describe('generator feature encoding: web/model/featureEncode.ts = training/data/features.py', () => {
  it('has the fixture\'s layout', () => {
    expect(info.onnx.dim).toBe(D);
    expect(info.features.names).toEqual(fixture.feature_names);
    expect(info.skeleton.joints).toEqual(fixture.joints);
  });

  for (const c of fixture.cases) {
    it(`encodes Python's world rotations to Python's rows: ${c.name}`, () => {
      expect(c.features.length).toBe((c.frames - 1) * D);
      const rows = pageRows(c, Float32Array.from(c.world_rotations));
      expect(above(worstByColumn(c, rows), () => ENCODE_TOLERANCE)).toEqual([]);
    });

    it(`points every segment as Python does from positions alone (the page's IK): ${c.name}`, () => {
      const world = canonicalRotations(info, Float32Array.from(c.positions));
      const segment = worstSegmentAngle(world, c.world_rotations, c.frames);
      expect(segment.angle, segment.where).toBeLessThan(SEGMENT_TOLERANCE);
      const worst = worstByColumn(c, pageRows(c, world));
      const limits = [ROOT_STEP_TOLERANCE, ROOT_STEP_TOLERANCE, HEADING_TOLERANCE, HEIGHT_TOLERANCE];
      expect(above(worst.slice(0, 4), (k) => limits[k])).toEqual([]);
    });
  }
});
