// Test support for retarget.ts (tests/unit/retarget.test.ts, tests/eval/retarget.eval.ts): character rigs of five
// namings built as data (as a glTF loader would give them), the source motions (a CMU walk and run, an acLSTM dance,
// a model-like canonical walk with contacts) and the measures of the "Done when".
import { parseBVH } from '../../web/motion/bvh';
import { labelContacts } from '../../web/motion/contactLabels';
import { CANONICAL_JOINTS, type CanonicalJoint, type HumanoidMap } from '../../web/motion/humanoid';
import { quatConjugate, quatFromAxisAngle, quatMultiply, quatNormalize, quatRotate, rotationFromTwoVectors, sub, type Quat, type Vec3 } from '../../web/motion/math';
import { lowFootSliding } from '../../web/motion/footSkating';
import { atRate, canonicalView, floorHeight } from '../../web/motion/motionStats';
import type { CharacterRig, RetargetResult } from '../../web/motion/retarget';
import type { Motion } from '../../web/motion/types';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { readCorpus } from './corpus';

/** Body proportions (metres) of a test figure standing facing +z, its left at +x. */
interface Body {
  ankle: number; thigh: number; shin: number; foot: number; torso: number; neck: number; head: number;
  shoulder: number; hipWidth: number; upperArm: number; foreArm: number; hand: number;
  /** Arms' angle below the horizontal: 0 for a T-pose, about 45° for an A-pose (degrees). */
  armDrop: number;
}

/** The generic bones a test rig may have, parent first. */
const GENERIC: Array<[string, string | null]> = [
  ['root', null], ['hips', 'root'], ['spine0', 'hips'], ['spine1', 'spine0'], ['spine2', 'spine1'], ['neck', 'spine2'],
  ['head', 'neck'], ['headEnd', 'head'],
  ...(['L', 'R'] as const).flatMap((s): Array<[string, string]> => [
    [`clav${s}`, 'spine2'], [`upperArm${s}`, `clav${s}`], [`upperTwist${s}`, `upperArm${s}`], [`foreArm${s}`, `upperArm${s}`],
    [`hand${s}`, `foreArm${s}`], [`finger${s}`, `hand${s}`], [`fingerEnd${s}`, `finger${s}`],
    [`thigh${s}`, 'hips'], [`thighTwist${s}`, `thigh${s}`], [`shin${s}`, `thigh${s}`], [`foot${s}`, `shin${s}`], [`toe${s}`, `foot${s}`], [`toeEnd${s}`, `toe${s}`],
  ]),
];

function layout(b: Body): Map<string, Vec3> {
  const p = new Map<string, Vec3>();
  const hipY = b.ankle + b.thigh + b.shin;
  p.set('root', [0, 0, 0]);
  p.set('hips', [0, hipY, 0]);
  p.set('spine0', [0, hipY + 0.1 * b.torso, -0.01]);
  p.set('spine1', [0, hipY + 0.4 * b.torso, -0.02]);
  p.set('spine2', [0, hipY + 0.7 * b.torso, -0.01]);
  p.set('neck', [0, hipY + b.torso, 0]);
  p.set('head', [0, hipY + b.torso + b.neck, 0.02]);
  p.set('headEnd', [0, hipY + b.torso + b.neck + b.head, 0.02]);
  const drop = (b.armDrop * Math.PI) / 180;
  for (const [s, x] of [['L', 1], ['R', -1]] as const) {
    const shoulderY = hipY + 0.92 * b.torso;
    const arm: Vec3 = [x * Math.cos(drop), -Math.sin(drop), 0];
    const along = (from: Vec3, d: number): Vec3 => [from[0] + arm[0] * d, from[1] + arm[1] * d, from[2] + arm[2] * d];
    p.set(`clav${s}`, [x * 0.03, shoulderY - 0.02, 0.01]);
    const upper: Vec3 = [x * b.shoulder, shoulderY, 0];
    p.set(`upperArm${s}`, upper);
    p.set(`upperTwist${s}`, along(upper, b.upperArm / 2));
    p.set(`foreArm${s}`, along(upper, b.upperArm));
    p.set(`hand${s}`, along(upper, b.upperArm + b.foreArm));
    p.set(`finger${s}`, along(upper, b.upperArm + b.foreArm + b.hand * 0.5));
    p.set(`fingerEnd${s}`, along(upper, b.upperArm + b.foreArm + b.hand));
    const hx = x * b.hipWidth;
    p.set(`thigh${s}`, [hx, hipY - 0.03, 0]);
    p.set(`thighTwist${s}`, [hx, hipY - 0.03 - b.thigh / 2, 0.005]);
    p.set(`shin${s}`, [hx, b.ankle + b.shin, 0.015]);
    p.set(`foot${s}`, [hx, b.ankle, 0]);
    p.set(`toe${s}`, [hx, 0.025, 0.7 * b.foot]);
    p.set(`toeEnd${s}`, [hx, 0.01, b.foot]);
  }
  return p;
}

/** How a rig's rest rotations are set: identity (BVH, VRM), each bone's y axis along the bone with a roll (Blender's
 * and Mixamo's exports), or a seeded random orientation per bone. */
type Orientation = 'identity' | 'alongBone' | 'random';

interface RigSpec {
  label: string;
  /** Generic bone → the rig's name; generic bones not named are left out (their children hang from the nearest kept ancestor). */
  names: Record<string, string>;
  body: Body;
  /** Rig units per metre (Mixamo: centimetres). */
  units: number;
  facingMinusZ: boolean;
  orientation: Orientation;
  seed: number;
  /** Give the rig the humanoid map a VRM file carries (bone names looked up) instead of letting mapRig find one. */
  vrmMap?: boolean;
}

function random(seed: number): () => number {
  let s = seed >>> 0 || 1;
  return () => {
    s ^= s << 13; s >>>= 0;
    s ^= s >>> 17;
    s ^= s << 5; s >>>= 0;
    return s / 2 ** 32;
  };
}

/** A CharacterRig from a spec: rest world positions from `layout`, rest world rotations by `orientation`, as locals. */
export function buildRig(spec: RigSpec): CharacterRig {
  const positions = layout(spec.body);
  const kept = GENERIC.filter(([g]) => g in spec.names);
  const parentOf = (g: string): string | null => {
    let p = GENERIC.find(([x]) => x === g)![1];
    while (p && !(p in spec.names)) p = GENERIC.find(([x]) => x === p)![1];
    return p;
  };
  const turn: Quat = spec.facingMinusZ ? [0, 1, 0, 0] : [0, 0, 0, 1];
  const rand = random(spec.seed);
  const world = new Map<string, Quat>();
  const worldPos = new Map<string, Vec3>();
  for (const [g] of kept) {
    worldPos.set(g, quatRotate(turn, positions.get(g)!).map((v) => v * spec.units) as Vec3);
    const child = kept.find(([c]) => parentOf(c) === g)?.[0];
    let q: Quat = [0, 0, 0, 1];
    if (spec.orientation === 'random') {
      q = quatNormalize([rand() - 0.5, rand() - 0.5, rand() - 0.5, rand() - 0.5]);
    } else if (spec.orientation === 'alongBone' && child) {
      const along = sub(quatRotate(turn, positions.get(child)!), quatRotate(turn, positions.get(g)!));
      const roll = quatFromAxisAngle(along, (rand() - 0.5) * Math.PI);
      q = quatMultiply(roll, rotationFromTwoVectors([0, 1, 0], [0, 0, 1], along, [along[1], -along[0] + 0.3, along[2] + 0.7]) ?? [0, 0, 0, 1]);
    }
    world.set(g, quatNormalize(q));
  }
  const bones = kept.map(([g]) => spec.names[g]);
  const parents = kept.map(([g]) => {
    const p = parentOf(g);
    return p ? kept.findIndex(([x]) => x === p) : -1;
  });
  const restRotations: Quat[] = [];
  const restTranslations: Vec3[] = [];
  kept.forEach(([g], i) => {
    const p = parents[i] >= 0 ? kept[parents[i]][0] : null;
    const parentWorld = p ? world.get(p)! : ([0, 0, 0, 1] as Quat);
    const inverse = quatConjugate(parentWorld);
    restRotations.push(quatNormalize(quatMultiply(inverse, world.get(g)!)));
    restTranslations.push(p ? quatRotate(inverse, sub(worldPos.get(g)!, worldPos.get(p)!)) : worldPos.get(g)!);
  });
  const rig: CharacterRig = { bones, parents, restRotations, restTranslations };
  if (spec.vrmMap) rig.humanoid = vrmHumanoid(rig, spec.facingMinusZ ? [0, -1] : [0, 1]);
  return rig;
}

/** VRM humanoid bone names at the canonical points (a VRM file's own map names these; the rest are derived). */
const VRM_POINTS: Partial<Record<CanonicalJoint, string>> = {
  Hips: 'hips', Spine: 'spine', Spine1: 'chest', Neck: 'neck', Head: 'head',
  ...Object.fromEntries((['Left', 'Right'] as const).flatMap((side) => {
    const s = side.toLowerCase();
    return [['UpLeg', 'UpperLeg'], ['Leg', 'LowerLeg'], ['Foot', 'Foot'], ['ToeBase', 'Toes'], ['Arm', 'UpperArm'], ['ForeArm', 'LowerArm'], ['Hand', 'Hand']]
      .map(([point, bone]) => [`${side}${point}`, `${s}${bone}`]);
  })),
};

/** The humanoid map a VRM loader gives: its bone names looked up, nothing inferred from the pose. */
function vrmHumanoid(rig: CharacterRig, facing: [number, number]): HumanoidMap {
  const source = CANONICAL_JOINTS.map((point) => (VRM_POINTS[point] ? rig.bones.indexOf(VRM_POINTS[point]!) : -1));
  return { source, scheme: 'VRM file', facing, sidesBy: 'names', height: NaN };
}

const sided = (left: Record<string, string>): Record<string, string> => {
  const out: Record<string, string> = {};
  for (const [g, n] of Object.entries(left)) {
    out[`${g}L`] = n.replace('{}', 'Left').replace('{s}', 'l').replace('{S}', 'L').replace('{c}', 'left');
    out[`${g}R`] = n.replace('{}', 'Right').replace('{s}', 'r').replace('{S}', 'R').replace('{c}', 'right');
  }
  return out;
};

const AVERAGE: Body = { ankle: 0.08, thigh: 0.43, shin: 0.42, foot: 0.2, torso: 0.5, neck: 0.1, head: 0.22, shoulder: 0.18, hipWidth: 0.09, upperArm: 0.29, foreArm: 0.25, hand: 0.18, armDrop: 0 };

export const RIGS: RigSpec[] = [
  {
    label: 'CMU (BVH names, metres, T-pose, identity rest rotations)',
    names: {
      hips: 'Hips', spine0: 'LowerBack', spine1: 'Spine', spine2: 'Spine1', neck: 'Neck', head: 'Head', headEnd: 'Head_end',
      ...sided({ clav: '{}Shoulder', upperArm: '{}Arm', foreArm: '{}ForeArm', hand: '{}Hand', finger: '{}FingerBase', thigh: '{}UpLeg', shin: '{}Leg', foot: '{}Foot', toe: '{}ToeBase', toeEnd: '{}ToeBase_end' }),
    },
    body: { ...AVERAGE, thigh: 0.41, shin: 0.4 },
    units: 1, facingMinusZ: false, orientation: 'identity', seed: 1,
  },
  {
    label: 'Mixamo (mixamorig: prefix, centimetres, T-pose, bone-along-y rest rotations)',
    names: {
      hips: 'mixamorig:Hips', spine0: 'mixamorig:Spine', spine1: 'mixamorig:Spine1', spine2: 'mixamorig:Spine2', neck: 'mixamorig:Neck', head: 'mixamorig:Head', headEnd: 'mixamorig:HeadTop_End',
      ...sided({ clav: 'mixamorig:{}Shoulder', upperArm: 'mixamorig:{}Arm', foreArm: 'mixamorig:{}ForeArm', hand: 'mixamorig:{}Hand', finger: 'mixamorig:{}HandMiddle1', fingerEnd: 'mixamorig:{}HandMiddle4',
        thigh: 'mixamorig:{}UpLeg', shin: 'mixamorig:{}Leg', foot: 'mixamorig:{}Foot', toe: 'mixamorig:{}ToeBase', toeEnd: 'mixamorig:{}Toe_End' }),
    },
    body: { ...AVERAGE, thigh: 0.46, shin: 0.44, torso: 0.55, upperArm: 0.3, foreArm: 0.27 },
    units: 100, facingMinusZ: false, orientation: 'alongBone', seed: 2,
  },
  {
    label: 'Unreal-style (root at the floor, twist bones, metres, A-pose, random rest rotations)',
    names: {
      root: 'root', hips: 'pelvis', spine0: 'spine_01', spine1: 'spine_02', spine2: 'spine_03', neck: 'neck_01', head: 'head',
      ...sided({ clav: 'clavicle_{s}', upperArm: 'upperarm_{s}', upperTwist: 'upperarm_twist_01_{s}', foreArm: 'lowerarm_{s}', hand: 'hand_{s}', finger: 'middle_01_{s}',
        thigh: 'thigh_{s}', thighTwist: 'thigh_twist_01_{s}', shin: 'calf_{s}', foot: 'foot_{s}', toe: 'ball_{s}' }),
    },
    body: { ...AVERAGE, thigh: 0.47, shin: 0.47, ankle: 0.09, torso: 0.52, armDrop: 45 },
    units: 1, facingMinusZ: false, orientation: 'random', seed: 3,
  },
  {
    label: 'VRM (VRM humanoid names and the file\'s own humanoid map, metres, T-pose, facing −z, identity rest rotations)',
    names: {
      hips: 'hips', spine0: 'spine', spine1: 'chest', spine2: 'upperChest', neck: 'neck', head: 'head',
      ...sided({ clav: '{c}Shoulder', upperArm: '{c}UpperArm', foreArm: '{c}LowerArm', hand: '{c}Hand', finger: '{c}MiddleProximal', fingerEnd: '{c}MiddleIntermediate',
        thigh: '{c}UpperLeg', shin: '{c}LowerLeg', foot: '{c}Foot', toe: '{c}Toes' }),
    },
    body: { ...AVERAGE, thigh: 0.4, shin: 0.42, torso: 0.42, head: 0.26, upperArm: 0.24, foreArm: 0.21, shoulder: 0.15, hipWidth: 0.08 },
    units: 1, facingMinusZ: true, orientation: 'identity', seed: 4, vrmMap: true,
  },
  {
    label: 'Bandai-style (UpperLeg_L …, metres, A-pose, bone-along-y rest rotations, short legs)',
    names: {
      hips: 'Hips', spine0: 'Spine', spine2: 'Chest', neck: 'Neck', head: 'Head',
      ...sided({ clav: 'Shoulder_{S}', upperArm: 'UpperArm_{S}', foreArm: 'LowerArm_{S}', hand: 'Hand_{S}', finger: 'Finger_{S}', thigh: 'UpperLeg_{S}', shin: 'LowerLeg_{S}', foot: 'Foot_{S}', toe: 'Toes_{S}' }),
    },
    body: { ...AVERAGE, thigh: 0.36, shin: 0.35, torso: 0.55, upperArm: 0.28, armDrop: 40 },
    units: 1, facingMinusZ: false, orientation: 'alongBone', seed: 5,
  },
];

/**
 * A CharacterRig from a GLB file's first skin, as a glTF loader gives it: the skin's joints in parent-first order,
 * each one's node rotation and translation; the root's with its ancestors' transforms (the armature) folded in.
 */
export function rigFromGlb(bytes: Uint8Array): CharacterRig {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const jsonLength = view.getUint32(12, true);
  const gltf = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength))) as {
    nodes: Array<{ name?: string; children?: number[]; rotation?: Quat; translation?: Vec3 }>;
    skins: Array<{ joints: number[] }>;
  };
  const parentOf = new Map<number, number>();
  gltf.nodes.forEach((n, i) => n.children?.forEach((c) => parentOf.set(c, i)));
  const joints = new Set(gltf.skins[0].joints);
  const depth = (i: number): number => (parentOf.has(i) ? 1 + depth(parentOf.get(i)!) : 0);
  const order = [...joints].sort((a, b) => depth(a) - depth(b));
  const index = new Map(order.map((node, i) => [node, i]));
  const rotation = (i: number): Quat => gltf.nodes[i].rotation ?? [0, 0, 0, 1];
  const translation = (i: number): Vec3 => gltf.nodes[i].translation ?? [0, 0, 0];
  const restRotations: Quat[] = [];
  const restTranslations: Vec3[] = [];
  const parents = order.map((node) => {
    let p = parentOf.get(node);
    let q = rotation(node), t = translation(node);
    // Fold the transforms of non-joint ancestors (the armature) into the bone.
    while (p !== undefined && !joints.has(p)) {
      t = (([a, b, c], [x, y, z]) => [a + x, b + y, c + z] as Vec3)(translation(p), quatRotate(rotation(p), t));
      q = quatMultiply(rotation(p), q);
      p = parentOf.get(p);
    }
    restRotations.push(q);
    restTranslations.push(t);
    return p === undefined ? -1 : index.get(p)!;
  });
  return { bones: order.map((i) => gltf.nodes[i].name ?? `node ${i}`), parents, restRotations, restTranslations };
}

/** The project's CC0 test character (Unreal-style names, its root turned from z up). */
export function quaterniusRig(): CharacterRig {
  return rigFromGlb(readFileSync(fileURLToPath(new URL('../../../shared/characters/quaternius-human-male.glb', import.meta.url))));
}

/** The source motions: CMU walk and run (BVH), an acLSTM salsa, and a model-like canonical walk with contacts. */
export interface Source { label: string; motion: Motion }

/** Stands a motion on the floor: its canonical lowest foot point's 5th percentile at TOE_HEIGHT (as model outputs are). */
const TOE_HEIGHT = 0;
function onFloor(motion: Motion): Motion {
  const floor = floorHeight(canonicalView(motion)) - TOE_HEIGHT;
  const positions = Float32Array.from(motion.positions);
  for (let i = 1; i < positions.length; i += 3) positions[i] -= floor;
  return { ...motion, positions };
}

function firstFrames(motion: Motion, frames: number): Motion {
  const n = Math.min(frames, motion.frames);
  return { ...motion, frames: n, positions: motion.positions.slice(0, n * motion.joints.length * 3) };
}

export function loadSources(): Source[] {
  const walk = onFloor(atRate(parseBVH(readCorpus('cmu/bvh/07_04.bvh.gz')), 60));
  const run = onFloor(atRate(parseBVH(readCorpus('cmu/bvh/09_01.bvh.gz')), 60));
  const dance = onFloor(firstFrames(parseBVH(readCorpus('aclstm/salsa/01.bvh.gz')), 450));
  const view = canonicalView(atRate(walk, 30));
  const model: Motion = { ...view, contacts: labelContacts(view.positions, new Uint8Array(view.frames * 2), CANONICAL_JOINTS, view.fps) };
  return [
    { label: 'CMU 07_04 walk', motion: walk },
    { label: 'CMU 09_01 run', motion: run },
    { label: 'acLSTM salsa 01', motion: dance },
    { label: 'canonical walk with contacts', motion: model },
  ];
}

/** The limb bones measured (canonical from → to). */
export const MEASURED_BONES: Array<[CanonicalJoint, CanonicalJoint]> = [
  ['LeftUpLeg', 'LeftLeg'], ['LeftLeg', 'LeftFoot'], ['LeftFoot', 'LeftToeBase'], ['RightUpLeg', 'RightLeg'], ['RightLeg', 'RightFoot'], ['RightFoot', 'RightToeBase'],
  ['LeftArm', 'LeftForeArm'], ['LeftForeArm', 'LeftHand'], ['RightArm', 'RightForeArm'], ['RightForeArm', 'RightHand'],
  ['Hips', 'Neck'], ['Neck', 'Head'],
];

export interface Measures {
  /** Mean angle (degrees) between each measured bone of the character and the source's, over frames and bones. */
  angle: number;
  /** The largest of the per-bone mean angles (degrees) and its bone. */
  worstBoneAngle: number;
  worstBone: string;
  /** Lowest-foot sliding (footSkating.ts lowFootSliding at 30 fps, see slidingOf) of the source and the character, m/s. */
  sourceSliding: number;
  sliding: number;
  /** Over the source's planted frames (its contacts, else its labels): the character's foot height above the floor
   *  (the lowest of its heel (ankle), ball (toe base) and, where the rig has a bone there, toe tip, each less its
   *  height in the rig's rest pose): mean, 95th percentile and largest |height|, metres. */
  plantedMean: number;
  planted95: number;
  plantedMax: number;
  /** The share of planted foot-frames within PLANTED_FLOOR of the floor. */
  plantedWithin: number;
}

/** A planted foot is within this of the floor (m): the bar. */
export const PLANTED_FLOOR = 0.03;

const K = CANONICAL_JOINTS.length;
const idx = (n: CanonicalJoint) => CANONICAL_JOINTS.indexOf(n);

/** Median over the planted frames (contacts frames × 2) of the lowest of `points` (per side) of a canonical motion, m. */
function plantedLow(view: Motion, contacts: Uint8Array, points: number[][]): number {
  const lows: number[] = [];
  points.forEach((side, s) => {
    for (let f = 0; f < view.frames; f++) {
      if (contacts[f * 2 + s]) lows.push(Math.min(...side.map((k) => view.positions[(f * K + k) * 3 + 1])));
    }
  });
  lows.sort((a, b) => a - b);
  return lows.length ? lows[Math.floor(lows.length / 2)] : 0;
}

/**
 * The reports' lowest-foot sliding (footSkating.ts lowFootSliding: the lowest foot point's horizontal speed while
 * within 4 cm of the floor) at 30 fps on a canonical motion's feet, the floor at `floor`. With `withTips` false the
 * feet are the ankle and toe base only (the dance set's leg names, which lowFootSliding reads as feet without tips).
 */
function slidingOf(view: Motion, floor: number, withTips: boolean): number {
  const legs = ['Left', 'Right'].map((side) => ['UpLeg', 'Leg', 'Foot', 'ToeBase', ...(withTips ? ['ToeBase_end'] : [])].map((n) => idx(`${side}${n}` as CanonicalJoint)));
  const names = withTips ? legs.flat().map((k) => CANONICAL_JOINTS[k]) : ['lThigh', 'lShin', 'lFoot', 'lFoot_end', 'rThigh', 'rShin', 'rFoot', 'rFoot_end'];
  const slow = atRate(view, 30);
  const J = names.length;
  const positions = new Float32Array(slow.frames * J * 3);
  for (let f = 0; f < slow.frames; f++) {
    legs.flat().forEach((k, j) => {
      for (let c = 0; c < 3; c++) positions[(f * J + j) * 3 + c] = slow.positions[(f * K + k) * 3 + c] - (c === 1 ? floor : 0);
    });
  }
  return lowFootSliding({ fps: slow.fps, frames: slow.frames, joints: names, parents: names.map(() => -1), positions });
}

export function measure(source: Motion, result: RetargetResult): Measures {
  const src = canonicalView(source);
  const character = result.motion;
  const view = canonicalView(character);
  const B = character.joints.length;
  const bone = result.mapping.source;
  const perBone = new Map<string, { sum: number; count: number }>();
  let sum = 0, count = 0;
  for (let f = 0; f < source.frames; f++) {
    for (const [a, b] of MEASURED_BONES) {
      if (bone[idx(a)] < 0 || bone[idx(b)] < 0) continue;
      const s = [0, 1, 2].map((c) => src.positions[(f * K + idx(b)) * 3 + c] - src.positions[(f * K + idx(a)) * 3 + c]);
      const t = [0, 1, 2].map((c) => character.positions[(f * B + bone[idx(b)]) * 3 + c] - character.positions[(f * B + bone[idx(a)]) * 3 + c]);
      const cos = (s[0] * t[0] + s[1] * t[1] + s[2] * t[2]) / (Math.hypot(...s) * Math.hypot(...t));
      const angle = (Math.acos(Math.min(1, Math.max(-1, cos))) * 180) / Math.PI;
      sum += angle;
      count++;
      const key = `${a}→${b}`;
      const entry = perBone.get(key) ?? { sum: 0, count: 0 };
      entry.sum += angle;
      entry.count++;
      perBone.set(key, entry);
    }
  }
  let worstBone = '', worstBoneAngle = 0;
  for (const [key, { sum: s, count: n }] of perBone) if (s / n > worstBoneAngle) [worstBone, worstBoneAngle] = [key, s / n];

  // Sliding: the source on its floor (y = 0); the character on its floor shifted by how much higher its lowest foot
  // point stands when planted than the source's does (foot joints sit at different heights inside different feet).
  // A rig without toe-tip bones has its tips derived along the foot (a guess): both are then measured on ankle and toe base.
  const withTips = bone[idx('LeftToeBase_end')] >= 0 && bone[idx('RightToeBase_end')] >= 0;
  const feet = ['Left', 'Right'].map((side) => ['Foot', 'ToeBase', ...(withTips ? ['ToeBase_end'] : [])].map((n) => idx(`${side}${n}` as CanonicalJoint)));
  const floor = plantedLow(view, result.contacts, feet) - plantedLow(src, result.contacts, feet);

  // Planted heights: heel, ball and toe tip (a bone's, not a derived one), each less its rest height above the rig's rest floor.
  const rest = result.restCanonical;
  const allFoot = ['Left', 'Right'].flatMap((side) => ['Foot', 'ToeBase', 'ToeBase_end'].map((n) => idx(`${side}${n}` as CanonicalJoint)));
  const restLow = Math.min(...allFoot.map((k) => rest[k * 3 + 1]));
  const restFloor = restLow >= 0 && restLow <= 0.15 ? 0 : restLow;
  const heights: number[] = [];
  ['Left', 'Right'].forEach((side, s) => {
    const sole = ['Foot', 'ToeBase', ...(withTips ? ['ToeBase_end'] : [])].map((n) => idx(`${side}${n}` as CanonicalJoint));
    for (let f = 0; f < view.frames; f++) {
      if (result.contacts[f * 2 + s]) heights.push(Math.abs(Math.min(...sole.map((k) => view.positions[(f * K + k) * 3 + 1] - (rest[k * 3 + 1] - restFloor)))));
    }
  });
  heights.sort((x, y) => x - y);
  const n = heights.length;
  return {
    angle: sum / count,
    worstBoneAngle,
    worstBone,
    sourceSliding: slidingOf(src, 0, withTips),
    sliding: slidingOf(view, floor, withTips),
    plantedMean: n ? heights.reduce((x, y) => x + y, 0) / n : NaN,
    planted95: n ? heights[Math.min(n - 1, Math.floor(0.95 * n))] : NaN,
    plantedMax: n ? heights[n - 1] : NaN,
    plantedWithin: n ? heights.filter((h) => h <= PLANTED_FLOOR).length / n : NaN,
  };
}
