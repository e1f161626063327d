// Skeleton mapping (web/motion/skeletonMap.ts): joint-name normalisation, picking the naming scheme (CMU BVH,
// CMU ASF, Mixamo, 3ds Max Biped) with its leg-length scale, short errors naming what is missing, the canonical
// points (mapped and derived), and carrying canonical changes back (identity, and a rigid turn + shift).
import { describe, expect, it } from 'vitest';
import {
  CANONICAL_JOINTS,
  SkeletonMapError,
  boneOwners,
  fromCanonical,
  mapSkeleton,
  normaliseName,
  toCanonical,
  type CanonicalJoint,
} from '../../web/motion/skeletonMap';
import type { Motion } from '../../web/motion/types';
import { canonicalRotations } from '../../web/model/featureEncode';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { readRepoFile } from './corpus';

type V = [number, number, number];
const FRAMES = 5;
const K = CANONICAL_JOINTS.length;
const CANONICAL_LEG = 0.85;
const ci = (name: CanonicalJoint) => CANONICAL_JOINTS.indexOf(name);

const rotX = (t: number, v: V): V => [v[0], v[1] * Math.cos(t) - v[2] * Math.sin(t), v[1] * Math.sin(t) + v[2] * Math.cos(t)];
const add = (a: V, b: V): V => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a: V, b: V): V => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];

/**
 * A walking-like pose at frame f (metres, y up, facing +z, left = +x): the body moves forward, the left leg swings
 * and its knee bends, the arms swing, all with rigid bones. `stretch` also moves the left knee and wrists off their
 * bones (lengths then change from frame to frame, as in noisy capture).
 */
function anatomy(f: number, stretch = false): Record<string, V> {
  const rest: Record<string, V> = {
    com: [0, 0.97, 0],
    hips: [0, 0.95, 0],
    spine: [0, 1.05, 0], spine1: [0, 1.2, 0], spine2: [0, 1.32, 0],
    neck: [0, 1.45, 0], neck1: [0, 1.52, 0], head: [0, 1.6, 0], headtop: [0, 1.75, 0],
  };
  for (const [s, x] of [['l', 1], ['r', -1]] as const) {
    rest[`${s}hip`] = [0.1 * x, 0.9, 0];
    rest[`${s}knee`] = [0.1 * x, 0.5, 0.01];
    rest[`${s}ankle`] = [0.1 * x, 0.08, 0];
    rest[`${s}toe`] = [0.1 * x, 0.02, 0.12];
    rest[`${s}toeend`] = [0.1 * x, 0.02, 0.2];
    rest[`${s}clav`] = [0.05 * x, 1.42, 0];
    rest[`${s}shoulder`] = [0.18 * x, 1.42, 0];
    rest[`${s}elbow`] = [0.2 * x, 1.15, 0];
    rest[`${s}wrist`] = [0.21 * x, 0.9, 0];
    rest[`${s}handend`] = [0.21 * x, 0.82, 0];
    rest[`${s}fing2`] = [0.21 * x, 0.79, 0];
    rest[`${s}fing3`] = [0.21 * x, 0.77, 0];
    rest[`${s}thumb`] = [0.19 * x, 0.86, 0.02];
  }
  const P: Record<string, V> = { ...rest };
  // Left leg: the thigh swings about the hip, the shin bends further at the knee.
  const thigh = 0.12 * f, shin = thigh - 0.2 * f;
  P.lknee = add(rest.lhip, rotX(thigh, sub(rest.lknee, rest.lhip)));
  for (const k of ['lankle', 'ltoe', 'ltoeend']) P[k] = add(P.lknee, rotX(shin, sub(rest[k], rest.lknee)));
  // Arms swing in opposite directions, the forearms bend.
  for (const [s, sign] of [['l', -1], ['r', 1]] as const) {
    const upper = sign * 0.1 * f, fore = upper - 0.15 * f;
    P[`${s}elbow`] = add(rest[`${s}shoulder`], rotX(upper, sub(rest[`${s}elbow`], rest[`${s}shoulder`])));
    for (const k of ['wrist', 'handend', 'fing2', 'fing3', 'thumb']) P[`${s}${k}`] = add(P[`${s}elbow`], rotX(fore, sub(rest[`${s}${k}`], rest[`${s}elbow`])));
  }
  if (stretch) {
    P.lknee = add(P.lknee, [0, 0.01 * f * (f % 2 ? 1 : -1), 0.004 * f]);
    P.lwrist = add(P.lwrist, [0, 0, 0.006 * f]);
    P.rwrist = add(P.rwrist, [0.003 * (f % 3), 0, 0]);
  }
  for (const k of Object.keys(P)) P[k] = add(P[k], [0, 0, 0.05 * f]);
  return P;
}

/** [joint name, parent name or null, anatomy key]; `L`/`l` placeholders expand to both sides. */
type Spec = [string, string | null, string][];

/** Expands a left-side spec line into both sides: `{S}` → side word, `{s}` → anatomy side letter. */
function sides(lines: Spec, words: [string, string]): Spec {
  const out: Spec = [];
  for (const [w, s] of [[words[0], 'l'], [words[1], 'r']] as const) {
    for (const [n, p, k] of lines) out.push([n.replace('{S}', w), p === null ? null : p.replace('{S}', w), k.replace('{s}', s)]);
  }
  return out;
}

function build(spec: Spec, unit = 1, stretch = false): Motion {
  const joints = spec.map((l) => l[0]);
  const parents = spec.map(([, p]) => {
    if (p === null) return -1;
    const i = joints.indexOf(p);
    if (i < 0) throw new Error(`bad spec parent ${p}`);
    return i;
  });
  parents.forEach((p, j) => expect(p).toBeLessThan(j));
  const positions = new Float32Array(FRAMES * joints.length * 3);
  for (let f = 0; f < FRAMES; f++) {
    const P = anatomy(f, stretch);
    spec.forEach(([, , key], j) => {
      const v = P[key];
      if (!v) throw new Error(`bad anatomy key ${key}`);
      for (let a = 0; a < 3; a++) positions[(f * joints.length + j) * 3 + a] = v[a] * unit;
    });
  }
  return { fps: 30, frames: FRAMES, joints, parents, positions };
}

const cmuBvh = (stretch = false): Motion =>
  build([
    ['Hips', null, 'hips'],
    ...sides([
      ['{S}UpLeg', 'Hips', '{s}hip'], ['{S}Leg', '{S}UpLeg', '{s}knee'], ['{S}Foot', '{S}Leg', '{s}ankle'],
      ['{S}ToeBase', '{S}Foot', '{s}toe'], ['{S}ToeBase_end', '{S}ToeBase', '{s}toeend'],
    ], ['Left', 'Right']),
    ['Spine', 'Hips', 'spine'], ['Spine1', 'Spine', 'spine1'], ['Neck', 'Spine1', 'neck'], ['Neck1', 'Neck', 'neck1'],
    ['Head', 'Neck1', 'head'], ['Head_end', 'Head', 'headtop'],
    ...sides([
      ['{S}Shoulder', 'Spine1', '{s}clav'], ['{S}Arm', '{S}Shoulder', '{s}shoulder'], ['{S}ForeArm', '{S}Arm', '{s}elbow'],
      ['{S}Hand', '{S}ForeArm', '{s}wrist'], ['{S}FingerBase', '{S}Hand', '{s}handend'], ['{S}HandIndex1', '{S}FingerBase', '{s}fing2'],
    ], ['Left', 'Right']),
  ], 1, stretch);

const cmuAsf = (stretch = false): Motion =>
  build([
    ['root', null, 'hips'],
    ...sides([
      ['{S}hipjoint', 'root', '{s}hip'], ['{S}femur', '{S}hipjoint', '{s}knee'], ['{S}tibia', '{S}femur', '{s}ankle'],
      ['{S}foot', '{S}tibia', '{s}toe'], ['{S}toes', '{S}foot', '{s}toeend'],
    ], ['l', 'r']),
    ['lowerback', 'root', 'spine'], ['upperback', 'lowerback', 'spine1'], ['thorax', 'upperback', 'neck'],
    ['lowerneck', 'thorax', 'neck1'], ['upperneck', 'lowerneck', 'head'], ['head', 'upperneck', 'headtop'],
    ...sides([
      ['{S}clavicle', 'thorax', '{s}shoulder'], ['{S}humerus', '{S}clavicle', '{s}elbow'], ['{S}radius', '{S}humerus', '{s}wrist'],
      ['{S}wrist', '{S}radius', '{s}handend'], ['{S}hand', '{S}wrist', '{s}fing2'], ['{S}fingers', '{S}hand', '{s}fing3'],
      ['{S}thumb', '{S}hand', '{s}thumb'],
    ], ['l', 'r']),
  ], 1, stretch);

function mixamoSpec(knee = 'Leg'): Spec {
  const m = 'mixamorig:';
  return [
    [`${m}Hips`, null, 'hips'],
    [`${m}Spine`, `${m}Hips`, 'spine'], [`${m}Spine1`, `${m}Spine`, 'spine1'], [`${m}Spine2`, `${m}Spine1`, 'spine2'],
    [`${m}Neck`, `${m}Spine2`, 'neck'], [`${m}Head`, `${m}Neck`, 'head'], [`${m}HeadTop_End`, `${m}Head`, 'headtop'],
    ...sides([
      [`${m}{S}Shoulder`, `${m}Spine2`, '{s}clav'], [`${m}{S}Arm`, `${m}{S}Shoulder`, '{s}shoulder'],
      [`${m}{S}ForeArm`, `${m}{S}Arm`, '{s}elbow'], [`${m}{S}Hand`, `${m}{S}ForeArm`, '{s}wrist'],
      [`${m}{S}HandIndex1`, `${m}{S}Hand`, '{s}handend'], [`${m}{S}HandIndex2`, `${m}{S}HandIndex1`, '{s}fing2'],
      [`${m}{S}HandIndex3`, `${m}{S}HandIndex2`, '{s}fing3'],
    ], ['Left', 'Right']),
    ...sides([
      [`${m}{S}UpLeg`, `${m}Hips`, '{s}hip'], [`${m}{S}${knee}`, `${m}{S}UpLeg`, '{s}knee'],
      [`${m}{S}Foot`, `${m}{S}${knee}`, '{s}ankle'], [`${m}{S}ToeBase`, `${m}{S}Foot`, '{s}toe'],
      [`${m}{S}Toe_End`, `${m}{S}ToeBase`, '{s}toeend'],
    ], ['Left', 'Right']),
  ];
}
const mixamo = (unit = 1, stretch = false): Motion => build(mixamoSpec(), unit, stretch);

const biped = (stretch = false): Motion =>
  build([
    ['Bip01', null, 'com'], ['Bip01 Pelvis', 'Bip01', 'hips'],
    ['Bip01 Spine', 'Bip01 Pelvis', 'spine'], ['Bip01 Spine1', 'Bip01 Spine', 'spine1'],
    ['Bip01 Neck', 'Bip01 Spine1', 'neck'], ['Bip01 Head', 'Bip01 Neck', 'head'],
    ...sides([
      ['Bip01 {S} Clavicle', 'Bip01 Neck', '{s}clav'], ['Bip01 {S} UpperArm', 'Bip01 {S} Clavicle', '{s}shoulder'],
      ['Bip01 {S} Forearm', 'Bip01 {S} UpperArm', '{s}elbow'], ['Bip01 {S} Hand', 'Bip01 {S} Forearm', '{s}wrist'],
      ['Bip01 {S} Finger0', 'Bip01 {S} Hand', '{s}thumb'],
      ['Bip01 {S} Thigh', 'Bip01 Pelvis', '{s}hip'], ['Bip01 {S} Calf', 'Bip01 {S} Thigh', '{s}knee'],
      ['Bip01 {S} Foot', 'Bip01 {S} Calf', '{s}ankle'], ['Bip01 {S} Toe0', 'Bip01 {S} Foot', '{s}toe'],
    ], ['L', 'R']),
  ], 1, stretch);

const dist = (a: V, b: V) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
/** The mean hip → knee → ankle length of the anatomy, computed independently of the module. */
function anatomyLegLength(unit = 1, stretch = false): number {
  let total = 0;
  for (let f = 0; f < FRAMES; f++) {
    const P = anatomy(f, stretch);
    for (const s of ['l', 'r']) total += dist(P[`${s}hip`], P[`${s}knee`]) + dist(P[`${s}knee`], P[`${s}ankle`]);
  }
  return (total / (2 * FRAMES)) * unit;
}

const pos = (m: Motion, f: number, j: number): V => {
  const o = (f * m.joints.length + j) * 3;
  return [m.positions[o], m.positions[o + 1], m.positions[o + 2]];
};
const point = (pts: Float32Array, f: number, k: number): V => [pts[(f * K + k) * 3], pts[(f * K + k) * 3 + 1], pts[(f * K + k) * 3 + 2]];
const expectVec = (a: V, b: V, tol = 1e-5) => {
  for (let i = 0; i < 3; i++) expect(Math.abs(a[i] - b[i])).toBeLessThan(tol);
};

const generatorInfo = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'generator.json');
/** The canonical segments' world rotations of canonical points (the clean-up's IK: unmapped bones ride on them). */
const rotationsOf = (points: Float32Array): Float32Array => canonicalRotations(generatorInfo, points);

/** Rotates v by the unit quaternion q = [x, y, z, w] (written out here, not taken from the module). */
function rotate(q: number[], v: V): V {
  const [x, y, z, w] = q;
  const m = [
    [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
    [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
    [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
  ];
  return [0, 1, 2].map((i) => m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2]) as V;
}

describe('normaliseName', () => {
  it('drops namespaces, the Biped prefix, case and separators', () => {
    expect(normaliseName('mixamorig:LeftUpLeg')).toBe('leftupleg');
    expect(normaliseName('Bip01 L Thigh')).toBe('lthigh');
    expect(normaliseName('Bip01')).toBe('');
    expect(normaliseName('LeftToe_End')).toBe('lefttoeend');
  });
});

describe('mapSkeleton', () => {
  const cases: { label: string; motion: () => Motion; scheme: string; knee: string; leftHip: string; hips: string }[] = [
    // Stretched motions: the leg length then differs from frame to frame, and the scale uses its mean.
    { label: 'CMU BVH', motion: () => cmuBvh(true), scheme: 'CMU BVH', knee: 'LeftLeg', leftHip: 'LeftUpLeg', hips: 'Hips' },
    { label: 'CMU ASF', motion: () => cmuAsf(true), scheme: 'CMU ASF', knee: 'lfemur', leftHip: 'lhipjoint', hips: 'root' },
    { label: 'Mixamo', motion: () => mixamo(1, true), scheme: 'Mixamo', knee: 'mixamorig:LeftLeg', leftHip: 'mixamorig:LeftUpLeg', hips: 'mixamorig:Hips' },
    { label: '3ds Max Biped', motion: () => biped(true), scheme: '3ds Max Biped', knee: 'Bip01 L Calf', leftHip: 'Bip01 L Thigh', hips: 'Bip01 Pelvis' },
  ];
  for (const c of cases) {
    it(`picks ${c.scheme} for ${c.label} names, maps the knee and scales by the leg length`, () => {
      const m = c.motion();
      const mapping = mapSkeleton(m, CANONICAL_LEG);
      expect(mapping.scheme).toBe(c.scheme);
      expect(mapping.source).toHaveLength(K);
      expect(mapping.source[ci('LeftLeg')]).toBe(m.joints.indexOf(c.knee));
      expect(mapping.source[ci('LeftUpLeg')]).toBe(m.joints.indexOf(c.leftHip));
      expect(mapping.source[ci('Hips')]).toBe(m.joints.indexOf(c.hips));
      expect(mapping.source[ci('RightLeg')]).toBe(m.joints.indexOf(c.knee.replace(/Left|\bL\b|^l/, (s) => ({ Left: 'Right', L: 'R', l: 'r' })[s]!)));
      expect(mapping.scale).toBeCloseTo(CANONICAL_LEG / anatomyLegLength(1, true), 5);
      expect(Math.abs(mapping.scale - CANONICAL_LEG / anatomyLegLength())).toBeGreaterThan(1e-4); // the stretch matters
    });
  }

  it('maps every ASF point to the joint at the end of its bone (the ASF foot is the toe base)', () => {
    const m = cmuAsf();
    const { source } = mapSkeleton(m, CANONICAL_LEG);
    expect(source.every((j) => j >= 0)).toBe(true);
    expect(m.joints[source[ci('LeftFoot')]]).toBe('ltibia');
    expect(m.joints[source[ci('LeftToeBase')]]).toBe('lfoot');
    expect(m.joints[source[ci('Head_end')]]).toBe('head');
    expect(m.joints[source[ci('RightHand')]]).toBe('rradius');
  });

  it('maps the Biped ankle to "L Foot", and the spine to Spine1 with Spine1 derived', () => {
    const m = biped();
    const { source } = mapSkeleton(m, CANONICAL_LEG);
    expect(m.joints[source[ci('LeftFoot')]]).toBe('Bip01 L Foot');
    expect(m.joints[source[ci('LeftToeBase')]]).toBe('Bip01 L Toe0');
    expect(m.joints[source[ci('Spine')]]).toBe('Bip01 Spine1');
    expect(source[ci('Spine1')]).toBe(-1);
    expect(source[ci('LeftToeBase_end')]).toBe(-1);
    expect(source).not.toContain(m.joints.indexOf('Bip01'));
  });

  it('scales a skeleton in centimetres down by 100 more', () => {
    const mapping = mapSkeleton(mixamo(100), CANONICAL_LEG);
    expect(mapping.scheme).toBe('Mixamo');
    expect(mapping.scale / (CANONICAL_LEG / anatomyLegLength(100))).toBeCloseTo(1, 5);
    expect(mapping.scale * 100).toBeCloseTo(CANONICAL_LEG / anatomyLegLength(), 5);
  });

  it('maps knees by the tree and bone lengths when their names match no scheme (names are only hints)', () => {
    const m = build(mixamoSpec('KneeJoint'));
    const { source } = mapSkeleton(m, CANONICAL_LEG);
    expect(m.joints[source[ci('LeftLeg')]]).toBe('mixamorig:LeftKneeJoint');
    expect(m.joints[source[ci('RightLeg')]]).toBe('mixamorig:RightKneeJoint');
  });

  it('throws a short SkeletonMapError naming what is missing for a chain of joints j0…j9', () => {
    const joints = Array.from({ length: 10 }, (_, i) => `j${i}`);
    const positions = new Float32Array(FRAMES * 10 * 3).map((_, i) => (i % 7) * 0.1);
    const m: Motion = { fps: 30, frames: FRAMES, joints, parents: joints.map((_, i) => i - 1), positions };
    expect(() => mapSkeleton(m, CANONICAL_LEG)).toThrow(SkeletonMapError);
    expect(() => mapSkeleton(m, CANONICAL_LEG)).toThrow(/no two legs/);
    try {
      mapSkeleton(m, CANONICAL_LEG);
    } catch (e) {
      expect((e as Error).message.length).toBeLessThan(300);
    }
  });
});

describe('toCanonical', () => {
  it('places mapped points at their joint × scale and Mixamo\'s missing Neck1 halfway from Neck to Head', () => {
    const m = mixamo();
    const mapping = mapSkeleton(m, CANONICAL_LEG);
    const pts = toCanonical(m, mapping);
    expect(pts).toHaveLength(FRAMES * K * 3);
    expect(mapping.source[ci('Neck1')]).toBe(-1);
    // The hand end is the finger joint nearest 0.7 forearm lengths beyond the wrist.
    expect(m.joints[mapping.source[ci('LeftHand_end')]]).toBe('mixamorig:LeftHandIndex3');
    const s = mapping.scale;
    for (let f = 0; f < FRAMES; f++) {
      mapping.source.forEach((j, k) => {
        if (j < 0) return;
        const p = pos(m, f, j);
        expectVec(point(pts, f, k), [p[0] * s, p[1] * s, p[2] * s]);
      });
      const P = anatomy(f);
      const neck1 = [0, 1, 2].map((a) => ((P.neck[a] + P.head[a]) / 2) * s) as V;
      expectVec(point(pts, f, ci('Neck1')), neck1);
    }
  });

  it('derives the Biped Spine1 at 0.66 from Hips to Neck and the toe tips at 1.5 beyond the toe base', () => {
    const m = biped();
    const mapping = mapSkeleton(m, CANONICAL_LEG);
    const pts = toCanonical(m, mapping);
    const s = mapping.scale;
    for (let f = 0; f < FRAMES; f++) {
      const P = anatomy(f);
      expectVec(point(pts, f, ci('Spine1')), [0, 1, 2].map((a) => (P.hips[a] + 0.66 * (P.neck[a] - P.hips[a])) * s) as V);
      expectVec(point(pts, f, ci('RightToeBase_end')), [0, 1, 2].map((a) => (P.rankle[a] + 1.5 * (P.rtoe[a] - P.rankle[a])) * s) as V);
      expectVec(point(pts, f, ci('Hips')), P.hips.map((v) => v * s) as V);
    }
  });
});

describe('fromCanonical', () => {
  // Bones that are not whole canonical segments (shoulders, extra spine joints, fingers) ride on the segment rotations
  // the clean-up's IK reads from the positions (whose twist about the segment is an estimate), at their median offset
  // fused with their own captured point: within 3 mm here (whole segments stay exact, as checked below).
  const RIDING = 3e-3;
  for (const [label, make] of [['Mixamo', () => mixamo()], ['3ds Max Biped', biped]] as const) {
    it(`gives the ${label} positions back unchanged when the canonical motion does not change`, () => {
      const m = make();
      const mapping = mapSkeleton(m, CANONICAL_LEG);
      const state = { points: toCanonical(m, mapping), rotations: rotationsOf(toCanonical(m, mapping)) };
      const out = fromCanonical(m, mapping, state, { points: state.points.slice(), rotations: state.rotations.slice() });
      expect(out.positions).toHaveLength(m.positions.length);
      for (let i = 0; i < m.positions.length; i++) expect(Math.abs(out.positions[i] - m.positions[i])).toBeLessThan(RIDING);
    });
  }

  it('puts a finger that flexes against its hand back where it was captured without jitter, and near its median offset under heavy jitter', () => {
    const m = mixamo();
    const J = m.joints.length;
    const finger = m.joints.indexOf('mixamorig:LeftHandIndex3'), knuckle = m.parents[finger];
    // Flex the last finger bone about its knuckle by up to 0.8 rad over the frames (its length kept).
    for (let f = 0; f < FRAMES; f++) {
      const k = pos(m, f, knuckle), bone = sub(pos(m, f, finger), k);
      m.positions.set(add(k, rotX((0.8 * f) / (FRAMES - 1), bone)), (f * J + finger) * 3);
    }
    const mapping = mapSkeleton(m, CANONICAL_LEG);
    const state = { points: toCanonical(m, mapping), rotations: rotationsOf(toCanonical(m, mapping)) };
    const exact = fromCanonical(m, mapping, state, state, 0);
    const rigid = fromCanonical(m, mapping, state, state, 1);
    let rigidOff = 0;
    for (let f = 0; f < FRAMES; f++) {
      expect(dist(pos(exact, f, finger), pos(m, f, finger))).toBeLessThan(1e-5);
      rigidOff = Math.max(rigidOff, dist(pos(rigid, f, finger), pos(m, f, finger)));
    }
    // Under 1 m of jitter the captured point counts for nearly nothing: the finger keeps one offset, so the flexed frames are off.
    expect(rigidOff).toBeGreaterThan(0.005);
  });

  it('gives every bone of a stretched skeleton its median length over the frames, whole segments near their joints', () => {
    const m = mixamo(1, true);
    const mapping = mapSkeleton(m, CANONICAL_LEG);
    const state = { points: toCanonical(m, mapping), rotations: rotationsOf(toCanonical(m, mapping)) };
    const out = fromCanonical(m, mapping, state, state);
    const { whole } = boneOwners(m.parents, mapping);
    let stretched = 0;
    for (let j = 0; j < m.joints.length; j++) {
      const p = m.parents[j];
      if (p < 0) {
        for (let f = 0; f < FRAMES; f++) expectVec(pos(out, f, j), pos(m, f, j));
        continue;
      }
      const lengths = Array.from({ length: FRAMES }, (_, f) => dist(pos(m, f, j), pos(m, f, p)));
      const median = [...lengths].sort((a, b) => a - b)[(FRAMES - 1) / 2];
      stretched = Math.max(stretched, Math.max(...lengths) - Math.min(...lengths));
      for (let f = 0; f < FRAMES; f++) {
        expect(Math.abs(dist(pos(out, f, j), pos(out, f, p)) - median)).toBeLessThan(1e-5);
        // A whole segment stays near its joint: the frame's stretch against the median is spread along the chain.
        if (whole[j]) expect(dist(pos(out, f, j), pos(m, f, j))).toBeLessThan(0.03);
      }
    }
    expect(stretched).toBeGreaterThan(0.005);
  });

  const angle = 0.3;
  const qy = [0, Math.sin(angle / 2), 0, Math.cos(angle / 2)];
  const shift: V = [0.5, 0, 0.2];
  /** `before` turned about the canonical hips by qy and shifted by `shift`, with the rotations turned by qy. */
  function turned(before: Float32Array, beforeRotations: Float32Array) {
    const points = new Float32Array(before.length);
    const rotations = new Float32Array(FRAMES * K * 4);
    for (let f = 0; f < FRAMES; f++) {
      const h = point(before, f, 0);
      for (let k = 0; k < K; k++) {
        const p = point(before, f, k);
        const r = rotate(qy, [p[0] - h[0], p[1] - h[1], p[2] - h[2]]);
        for (let a = 0; a < 3; a++) points[(f * K + k) * 3 + a] = h[a] + r[a] + shift[a];
        // qy × the segment's rotation.
        const b = Array.from(beforeRotations.subarray((f * K + k) * 4, (f * K + k) * 4 + 4));
        const q = [
          qy[3] * b[0] + qy[0] * b[3] + qy[1] * b[2] - qy[2] * b[1],
          qy[3] * b[1] - qy[0] * b[2] + qy[1] * b[3] + qy[2] * b[0],
          qy[3] * b[2] + qy[0] * b[1] - qy[1] * b[0] + qy[2] * b[3],
          qy[3] * b[3] - qy[0] * b[0] - qy[1] * b[1] - qy[2] * b[2],
        ];
        for (let a = 0; a < 4; a++) rotations[(f * K + k) * 4 + a] = q[a];
      }
    }
    return { points, rotations };
  }

  for (const [label, make] of [['Mixamo', () => mixamo()], ['3ds Max Biped', biped], ['CMU ASF', cmuAsf]] as const) {
    it(`keeps the ${label} joints, parents, frames and every bone length, and moves the root by the hips' shift / scale`, () => {
      const m = make();
      const mapping = mapSkeleton(m, CANONICAL_LEG);
      const before = { points: toCanonical(m, mapping), rotations: rotationsOf(toCanonical(m, mapping)) };
      const out = fromCanonical(m, mapping, before, turned(before.points, before.rotations));
      expect(out.joints).toEqual(m.joints);
      expect(out.parents).toEqual(m.parents);
      expect(out.frames).toBe(m.frames);
      expect(out.positions).toHaveLength(m.positions.length);
      const root = m.parents.indexOf(-1);
      let moved = 0;
      for (let f = 0; f < FRAMES; f++) {
        for (let j = 0; j < m.joints.length; j++) {
          const p = m.parents[j];
          if (p < 0) continue;
          expect(Math.abs(dist(pos(out, f, j), pos(out, f, p)) - dist(pos(m, f, j), pos(m, f, p)))).toBeLessThan(1e-5);
          moved = Math.max(moved, dist(pos(out, f, j), pos(m, f, j)));
        }
        const r = pos(m, f, root);
        expectVec(pos(out, f, root), [r[0] + shift[0] / mapping.scale, r[1] + shift[1] / mapping.scale, r[2] + shift[2] / mapping.scale]);
      }
      expect(moved).toBeGreaterThan(0.1); // it did move things
    });
  }

  it('turns a Mixamo skeleton (root = hips) rigidly about its hips and shifts it', () => {
    const m = mixamo();
    const mapping = mapSkeleton(m, CANONICAL_LEG);
    const before = { points: toCanonical(m, mapping), rotations: rotationsOf(toCanonical(m, mapping)) };
    const out = fromCanonical(m, mapping, before, turned(before.points, before.rotations));
    for (let f = 0; f < FRAMES; f++) {
      const h = pos(m, f, 0);
      for (let j = 0; j < m.joints.length; j++) {
        const p = pos(m, f, j);
        const r = rotate(qy, [p[0] - h[0], p[1] - h[1], p[2] - h[2]]);
        expectVec(pos(out, f, j), [0, 1, 2].map((a) => h[a] + r[a] + shift[a] / mapping.scale) as V, RIDING);
      }
    }
  });
});

describe('boneOwners', () => {
  const m = mixamo();
  const mapping = mapSkeleton(m, CANONICAL_LEG);
  const J = (n: string) => m.joints.indexOf(`mixamorig:${n}`);

  it('gives mapped joints the segment ending at their point, whole when the parent is its canonical parent', () => {
    const { owner, whole } = boneOwners(m.parents, mapping);
    expect(owner[J('LeftLeg')]).toBe(ci('LeftLeg'));
    expect(whole[J('LeftLeg')]).toBe(true);
    expect(owner[J('Neck')]).toBe(ci('Neck')); // parent Spine2 is the canonical Spine1
    expect(whole[J('Neck')]).toBe(true);
    expect(owner[J('LeftArm')]).toBe(ci('LeftArm')); // parent LeftShoulder is unmapped
    expect(whole[J('LeftArm')]).toBe(false);
    expect(owner[J('Spine1')]).toBe(ci('Spine')); // parent Spine is unmapped
    expect(whole[J('Spine1')]).toBe(false);
    expect(whole[J('Hips')]).toBe(false);
  });

  it('gives an unmapped joint with mapped joints below the segment ending at the first of them', () => {
    const { owner, whole } = boneOwners(m.parents, mapping);
    expect(owner[J('LeftShoulder')]).toBe(ci('LeftArm'));
    expect(owner[J('RightShoulder')]).toBe(ci('RightArm'));
    expect(owner[J('Spine')]).toBe(ci('Spine'));
    expect(whole[J('LeftShoulder')]).toBe(false);
  });

  it('gives an unmapped leaf the segment beyond its nearest mapped ancestor, or the ancestor\'s own with several children', () => {
    // Fingers under LeftHand: LeftHand's only canonical child is LeftHand_end.
    const { owner, whole } = boneOwners(m.parents, mapping);
    for (const n of ['LeftHandIndex1', 'LeftHandIndex2', 'LeftHandIndex3']) expect(owner[J(n)]).toBe(ci('LeftHand_end'));
    for (const n of ['RightHandIndex1', 'RightHandIndex3']) expect(owner[J(n)]).toBe(ci('RightHand_end'));
    expect(whole[J('LeftHandIndex1')]).toBe(false);
    // Props: one under the Neck (canonical children Neck1 and both arms) and one under the Hips (legs and spine).
    const parents = [...m.parents, J('Neck'), J('Hips'), J('Spine2')];
    const extra = boneOwners(parents, mapping).owner.slice(m.parents.length);
    expect(extra).toEqual([ci('Neck'), ci('Hips'), ci('Neck')]);
  });
});

describe('the acLSTM dance skeleton (Daz names, a buttock joint above each thigh)', () => {
  it('maps the hip socket to the thigh the scheme names, not the buttock above it', async () => {
    const { parseBVH } = await import('../../web/motion/bvh');
    const { readCorpus } = await import('./corpus');
    const m = parseBVH(readCorpus('aclstm/salsa/01.bvh.gz'));
    expect(m.joints).toContain('lButtock');
    const { source } = mapSkeleton(m, CANONICAL_LEG);
    const at = (p: CanonicalJoint) => m.joints[source[ci(p)]];
    expect([at('LeftUpLeg'), at('LeftLeg'), at('LeftFoot'), at('RightUpLeg')]).toEqual(['lThigh', 'lShin', 'lFoot', 'rThigh']);
    expect([at('LeftArm'), at('LeftForeArm'), at('LeftHand'), at('Neck'), at('Head')]).toEqual(['lShldr', 'lForeArm', 'lHand', 'neck', 'head']);
  });
});
