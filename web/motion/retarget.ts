// Retargeting a humanoid motion onto a character's own skeleton (issue 40, "Bring your own character"), by rotations.
//
//   1. The source (any humanoid Motion: a model's canonical output or an import) becomes the canonical points in
//      metres (humanoid.ts maps it, skeletonMap.toCanonical places the points it lacks), stood on y = 0 if an import's
//      floor is clearly elsewhere.
//   2. The rig's rest pose is mapped the same way (mapRig): its rest canonical points and each bone's rest world
//      rotation.
//   3. Per frame, each mapped bone's world rotation = R × its rest world rotation, where R takes the bone's rest
//      segment (its canonical point to the next one along the chain) and a twist reference to the source's current
//      ones: the hip line for the hips, the shoulder line for the chest and neck; for thighs, shins, upper arms and
//      forearms the way the knee or elbow points out of the line through the limb's ends (its hinge plane), blended
//      into the foot's or the chest's forward as the limb straightens; the shin for the foot. Hands, toes and the
//      head turn with their parent plus the least swing. Rest-pose differences (T or A pose, a rig facing −z, bone
//      axes that do not follow the bones) cancel: R is measured from the rig's own rest directions. The foot and the
//      toes are also turned down by the difference between the rig's rest slope and the source's flat-foot slope,
//      so that a flat foot stays flat. Unmapped bones (fingers, twist bones, clavicles, a root at the floor) keep
//      their rest rotation under their parent. Local rotation = inverse(parent world) × world.
//   4. The legs' hip joints go where the source's go, scaled by leg length (character leg / source leg), the height
//      shifted by the difference in ankle heights so that planted feet land on the floor (y = 0).
//   5. Where the source's feet are planted (its contacts, else labelled from height and speed, contactLabels.ts),
//      the character's foot stands on its lowest point (heel, ball or a toe-tip bone, each against its height in
//      the rest pose, so a mesh sole stands on the floor), held horizontally where it was when the contact began;
//      thigh and shin turn by two-bone IK (footLock.ts) to reach, the foot keeps its world rotation. A push-off out
//      of reach turns the foot about the pinned ball or tip; where even that does not reach, the hips come down.
//      Swinging feet clear the floor at least as far as the source's. Corrections fade in and out over
//      RELEASE_SECONDS.
// The numbers measured on the source for 4 and 5 (RetargetCalibration) can be given, so that the windows of a live
// stream are retargeted alike; the work on the rig is done once per rig object.
import { labelContacts } from './contactLabels';
import { twoBoneIK, smoothstep } from './footLock';
import { CANONICAL_JOINTS, mapHumanoid, SkeletonMapError, type CanonicalJoint, type HumanoidMap } from './humanoid';
import { cross, dot, length, normalize, quatConjugate, quatFromAxisAngle, quatIdentity, quatMultiply, quatNormalize, quatRotate, rotationFromTwoVectors, sub, swingRotation, type Quat, type Vec3 } from './math';
import { mapSkeleton, toCanonical } from './skeletonMap';
import type { Motion } from './types';

/** A character's skeleton as the file gives it: bones in parent-before-child order. Units: the file's (any). */
export interface CharacterRig {
  bones: string[];
  parents: number[];
  /** Rest (bind) pose: each bone's local rotation (x, y, z, w) and translation relative to its parent; the root's
   *  relative to the scene (the armature's own transform folded in). */
  restRotations: Quat[];
  restTranslations: Vec3[];
  /** Optional: a humanoid map given by the file itself (VRM), canonical point -> bone index; else found by mapHumanoid. */
  humanoid?: HumanoidMap;
}

export interface RetargetOptions {
  /** keep planted feet planted with two-bone IK on the character's legs (default true) */
  footIK?: boolean;
  /**
   * The numbers a retarget measured on a source (RetargetResult.calibration), to use instead of measuring them
   * on this motion: for a live stream retargeted window by window, so that the scale, the hips' height and the feet's
   * slope do not change from one window to the next.
   */
  calibration?: RetargetCalibration;
}

/** What retarget measures on the source to set the retargeting (all from its canonical points, metres). */
export interface RetargetCalibration {
  /** Character leg length / source leg length. */
  scale: number;
  /** The source's ankle height when planted (the character's ankles stand as high as theirs at rest then). */
  sourceAnkle: number;
  /** The height of the source's lowest foot point when planted: its feet's floor. */
  sourceSole: number;
  /** Radians the left foot, left toes, right foot and right toes are turned down (the rig's rest slope against the source's flat foot). */
  footSlopes: number[];
}

export interface RetargetResult {
  /** The motion on the character's skeleton: its bone names and parents, world positions per frame (metres). */
  motion: Motion;
  /** frames × bones × 4: each bone's LOCAL rotation per frame (x, y, z, w), to drive a THREE.SkinnedMesh's bones. */
  rotations: Float32Array;
  /** frames × 3: the root bone's local translation per frame (in the rig's units). */
  rootTranslations: Float32Array;
  /** The bone `rootTranslations` moves: the root the hips hang from (bone 0 in most rigs); other roots keep their rest. */
  rootBone: number;
  /** The rig's humanoid map used (canonical point -> bone), and what canonical points the rig lacks (derived). */
  mapping: HumanoidMap;
  /** Character leg length / source leg length: how proportions were scaled. */
  scale: number;
  /** Units of the rig per metre (e.g. 100 for a centimetre rig, 1 for metres), as detected from its height. */
  unitsPerMetre: number;
  /** The rig's rest pose as canonical points (25 × 3, metres, CANONICAL_JOINTS order; derived points placed). */
  restCanonical: Float32Array;
  /** The source's foot contacts used for the foot IK (frames × 2, left, right; 1 = planted). */
  contacts: Uint8Array;
  /** The numbers measured on the source (or given in options.calibration) that set this retargeting. */
  calibration: RetargetCalibration;
}

/** A human's height (m), to tell a rig's units: units per metre is the power of ten nearest height / this. */
const TYPICAL_HEIGHT = 1.7;
/** Foot corrections fade in before a contact and out after it over this long (s). */
const RELEASE_SECONDS = 0.15;
/** A rig whose lowest rest foot point is within this height above y = 0 (m) stands on y = 0; else on that point. */
const REST_FLOOR_SLACK = 0.15;
/** A source whose feet's lowest point (this quantile over the frames) is more than OFF_FLOOR (m) off y = 0 is stood on y = 0. */
const SOURCE_FLOOR_QUANTILE = 0.05;
const OFF_FLOOR = 0.05;
/** How far ahead of the knee (a share of the leg's length) the IK's bend is aimed: enough to bend a straight leg forward. */
const KNEE_POLE = 0.05;
/** The longest a leg may stretch in the foot IK, as a share of thigh + shin. */
const REACH = 0.9999;
/** The share of a foot's planted frames, lowest ankle first, taken as the foot standing flat. */
const FLAT_SHARE = 0.25;
/** The most a planted foot is kept above the floor (m) where the source's is higher (a contact's first and last frames). */
const PLANTED_LIFT = 0.02;
/** Below this sine of the angle between a segment and its twist reference, the reference is not trusted. */
const PARALLEL_SINE = 0.08;
/** A knee or elbow bent less than BEND_FROM twists the limb by the fallback forward, more than BEND_FULL by its bend (radians). */
const BEND_FROM = (5 * Math.PI) / 180;
const BEND_FULL = (25 * Math.PI) / 180;

const K = CANONICAL_JOINTS.length;
const CANONICAL_INDEX = new Map<string, number>(CANONICAL_JOINTS.map((name, k) => [name, k]));
const at = (name: CanonicalJoint): number => CANONICAL_INDEX.get(name)!;

type Points = (k: number) => Vec3;
type Twist = (p: Points) => Vec3;

/** How each canonical point's bone turns: towards the first point of `to` (far enough away), twisted by `twist`
 *  (undefined: with its canonical parent, plus the least swing). */
interface SegmentRule {
  to: number[];
  twist?: Twist;
  parent: number;
}

const hipLine: Twist = (p) => sub(p(at('LeftUpLeg')), p(at('RightUpLeg')));
const shoulderLine: Twist = (p) => sub(p(at('LeftArm')), p(at('RightArm')));
/** Where the chest faces: left (right → left shoulder) × up (chest → neck base). */
const chestForward = (p: Points): Vec3 => normalize(cross(shoulderLine(p), sub(p(at('Neck')), p(at('Spine1')))));

/**
 * A limb's twist reference: the way its middle joint points out of the line through its ends (the knee forward, the
 * elbow back), which is the hinge's own plane, where the limb is bent; `straight` (the foot's or the chest's forward)
 * where it is straight, blended between BEND_FROM and BEND_FULL of bend, so the twist does not jump.
 */
function bendTwist(root: Vec3, middle: Vec3, end: Vec3, straight: Vec3, sign: number): Vec3 {
  const upper = sub(middle, root), lower = sub(end, middle);
  const bend = Math.acos(Math.max(-1, Math.min(1, dot(upper, lower) / ((length(upper) * length(lower)) || 1))));
  const w = smoothstep((bend - BEND_FROM) / (BEND_FULL - BEND_FROM));
  const line = sub(end, root);
  const along = dot(upper, line) / (dot(line, line) || 1);
  const out = normalize([upper[0] - line[0] * along, upper[1] - line[1] * along, upper[2] - line[2] * along]);
  const fallback = normalize(straight);
  return [(1 - w) * fallback[0] + w * sign * out[0], (1 - w) * fallback[1] + w * sign * out[1], (1 - w) * fallback[2] + w * sign * out[2]];
}

/** The knee's forward: where it points when bent, else where the foot points. */
function kneeTwist(side: 'Left' | 'Right'): Twist {
  const [hip, knee, ankle, toe] = ['UpLeg', 'Leg', 'Foot', 'ToeBase'].map((n) => at(`${side}${n}` as CanonicalJoint));
  return (p) => bendTwist(p(hip), p(knee), p(ankle), sub(p(toe), p(ankle)), 1);
}

/** The elbow's front: against where it points when bent, else the chest's forward. */
function elbowTwist(side: 'Left' | 'Right'): Twist {
  const [shoulder, elbow, wrist] = ['Arm', 'ForeArm', 'Hand'].map((n) => at(`${side}${n}` as CanonicalJoint));
  return (p) => bendTwist(p(shoulder), p(elbow), p(wrist), chestForward(p), -1);
}

function segmentRules(): SegmentRule[] {
  const rules: SegmentRule[] = CANONICAL_JOINTS.map(() => ({ to: [], parent: -1 }));
  const rule = (name: CanonicalJoint, to: CanonicalJoint[], parent: CanonicalJoint | '', twist?: Twist) =>
    (rules[at(name)] = { to: to.map(at), twist, parent: parent ? at(parent) : -1 });
  rule('Hips', ['Neck'], '', hipLine);
  rule('Spine', ['Spine1', 'Neck'], 'Hips', (p) => {
    const a = normalize(hipLine(p)), b = normalize(shoulderLine(p));
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  });
  rule('Spine1', ['Neck'], 'Spine', shoulderLine);
  rule('Neck', ['Neck1', 'Head'], 'Spine1', shoulderLine);
  rule('Neck1', ['Head'], 'Neck', shoulderLine);
  rule('Head', ['Head_end'], 'Neck1');
  rule('Head_end', [], 'Head');
  for (const side of ['Left', 'Right'] as const) {
    const n = (s: string) => `${side}${s}` as CanonicalJoint;
    rule(n('UpLeg'), [n('Leg')], 'Hips', kneeTwist(side));
    rule(n('Leg'), [n('Foot')], n('UpLeg'), kneeTwist(side));
    rule(n('Foot'), [n('ToeBase'), n('ToeBase_end')], n('Leg'), (p) => sub(p(at(n('Leg'))), p(at(n('Foot')))));
    rule(n('ToeBase'), [n('ToeBase_end')], n('Foot'));
    rule(n('ToeBase_end'), [], n('ToeBase'));
    rule(n('Arm'), [n('ForeArm')], 'Spine1', elbowTwist(side));
    rule(n('ForeArm'), [n('Hand')], n('Arm'), elbowTwist(side));
    rule(n('Hand'), [n('Hand_end')], n('ForeArm'));
    rule(n('Hand_end'), [], n('Hand'));
  }
  return rules;
}
const RULES = segmentRules();

function describeRigError(message: string): never {
  throw new SkeletonMapError(`character rig: ${message}`);
}

function checkRig(rig: CharacterRig): void {
  const n = rig.bones?.length ?? 0;
  if (n < 3) describeRigError(`it has ${n} bone${n === 1 ? '' : 's'}, not a humanoid skeleton`);
  for (const [what, list] of [['parents', rig.parents], ['restRotations', rig.restRotations], ['restTranslations', rig.restTranslations]] as const) {
    if (!list || list.length !== n) describeRigError(`${list?.length ?? 0} ${what} for ${n} bones`);
  }
  for (let b = 0; b < n; b++) {
    const p = rig.parents[b];
    if (!(Number.isInteger(p) && p >= -1 && p < b)) describeRigError(`bone ${b} (${rig.bones[b]}) has parent ${p}; parents must come before children`);
    if (!rig.restRotations[b].every(Number.isFinite) || !rig.restTranslations[b].every(Number.isFinite)) {
      describeRigError(`bone ${b} (${rig.bones[b]}) has a rest rotation or translation that is not a finite number`);
    }
  }
}

/** Rest world rotations and positions (rig units) of every bone: FK of the rest pose (three.js semantics). */
function restWorld(rig: CharacterRig): { rotations: Quat[]; positions: Vec3[] } {
  const rotations: Quat[] = [];
  const positions: Vec3[] = [];
  rig.parents.forEach((p, b) => {
    const q = quatNormalize(rig.restRotations[b]);
    const t = rig.restTranslations[b];
    if (p < 0) {
      rotations[b] = q;
      positions[b] = [t[0], t[1], t[2]];
    } else {
      rotations[b] = quatNormalize(quatMultiply(rotations[p], q));
      const o = quatRotate(rotations[p], t);
      positions[b] = [positions[p][0] + o[0], positions[p][1] + o[1], positions[p][2] + o[2]];
    }
  });
  return { rotations, positions };
}

/** World rest positions (bones × 3) of a rig: FK of its rest pose. */
export function restPositions(rig: CharacterRig): Float32Array {
  checkRig(rig);
  return Float32Array.from(restWorld(rig).positions.flat());
}

/** The rig's humanoid map (its own VRM map when given, else mapHumanoid on the rest pose); throws SkeletonMapError naming what is missing. */
export function mapRig(rig: CharacterRig): HumanoidMap {
  const positions = restPositions(rig);
  if (rig.humanoid) {
    const { source } = rig.humanoid;
    if (source.length !== K || source.some((j) => !Number.isInteger(j) || j < -1 || j >= rig.bones.length)) {
      describeRigError(`its humanoid map has ${source.length} points (expected ${K}) or names a bone that is not there`);
    }
    for (const need of ['Hips', 'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'RightUpLeg', 'RightLeg', 'RightFoot', 'Neck', 'Head', 'LeftArm', 'LeftForeArm', 'LeftHand', 'RightArm', 'RightForeArm', 'RightHand'] as const) {
      if (source[at(need)] < 0) describeRigError(`its humanoid map has no bone for ${need}`);
    }
    return rig.humanoid;
  }
  return mapHumanoid({ joints: rig.bones, parents: rig.parents, frames: 1, positions });
}

/** The source motion's canonical points (frames × 25 × 3, metres). */
function sourceCanonical(source: Motion): Float32Array {
  const canonical = source.joints.length === K && source.joints.every((name, j) => name === CANONICAL_JOINTS[j]);
  const points = canonical ? source.positions : toCanonical(source, { ...mapSkeleton(source, 1), scale: 1 });
  // A motion is on the floor y = 0 (types.ts); an import that is not (a capture whose floor sits lower or higher) is
  // stood on it: its feet's lowest point, 5th percentile over the frames, at y = 0.
  const F = source.frames;
  const lows = new Float64Array(F);
  const feet = (['Left', 'Right'] as const).flatMap(footPointsOf);
  for (let f = 0; f < F; f++) lows[f] = Math.min(...feet.map((k) => points[(f * K + k) * 3 + 1]));
  lows.sort();
  const floor = lows[Math.floor(F * SOURCE_FLOOR_QUANTILE)];
  if (Math.abs(floor) <= OFF_FLOOR) return points;
  const stood = Float32Array.from(points);
  for (let i = 1; i < stood.length; i += 3) stood[i] -= floor;
  return stood;
}

function legLength(points: ArrayLike<number>, frames: number): number {
  let total = 0;
  const p = (f: number, k: number): Vec3 => [points[(f * K + k) * 3], points[(f * K + k) * 3 + 1], points[(f * K + k) * 3 + 2]];
  for (let f = 0; f < frames; f++) {
    for (const side of ['Left', 'Right']) {
      const [h, k, a] = ['UpLeg', 'Leg', 'Foot'].map((n) => p(f, at(`${side}${n}` as CanonicalJoint)));
      total += length(sub(k, h)) + length(sub(a, k));
    }
  }
  return total / (2 * frames);
}

/** A direction's slope: its angle above the ground (radians, negative below). */
const pitchOf = (d: Vec3): number => Math.atan2(d[1], Math.hypot(d[0], d[2]));

/** `d` turned down by `angle` (radians) in its vertical plane; unchanged where it is (nearly) vertical. */
function pitchDown(d: Vec3, angle: number): Vec3 {
  const axis = cross([0, 1, 0], d);
  if (length(axis) < 1e-6 * length(d) || angle === 0) return d;
  return quatRotate(quatFromAxisAngle(axis, angle), d);
}

const midpoint = (a: Vec3, b: Vec3): Vec3 => [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2];

function median(values: number[]): number {
  if (!values.length) return NaN;
  const s = [...values].sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
}

/** R taking (from, its twist reference) to (to, its reference); undefined where a reference lies along its segment. */
function alignFrames(fromDir: Vec3, fromRef: Vec3, toDir: Vec3, toRef: Vec3): Quat | undefined {
  const sine = (a: Vec3, b: Vec3) => length(cross(a, b)) / ((length(a) * length(b)) || 1);
  if (sine(fromDir, fromRef) < PARALLEL_SINE || sine(toDir, toRef) < PARALLEL_SINE) return undefined;
  return rotationFromTwoVectors(fromDir, fromRef, toDir, toRef);
}

interface LegBones {
  thigh: number;
  knee: number;
  ankle: number;
  /** The toe bone and the toe-tip bone, -1 where the rig has none. */
  toe: number;
  tip: number;
  /** The way the knee points (the body's forward in the rest pose) in the thigh bone's frame: where the IK bends a straight leg. */
  kneeForward: Vec3;
  /** Foot points (ankle, toe, toe end) as offsets in the ankle bone's frame (rig units), and each one's rest height above the floor (m). */
  offsets: Vec3[];
  clearance: number[];
}

/** What a rig gives every retargeting onto it: read once per rig object (see prepared). */
interface PreparedRig {
  rest: { rotations: Quat[]; positions: Vec3[] };
  restLocal: Quat[];
  mapping: HumanoidMap;
  unitsPerMetre: number;
  restCanonical: Float32Array;
  restAt: (k: number) => Vec3;
  characterLeg: number;
  /** Per canonical point the rig bone there (-1: derived), and per bone its canonical point (-1: none). */
  boneOf: number[];
  pointOfBone: number[];
  mapped: boolean[];
  restRef: Vec3[];
  restFloor: number;
  characterAnkle: number;
  /** The rest offset (m) from the hips point to the legs' hip joints' midpoint. */
  restHipJoints: Vec3;
  rootBone: number;
  hipsFromRoot: Vec3;
  legs: LegBones[];
}

/** The per-rig work, kept per rig object: a rig changed in place after a retarget is not read again (pass a new object). */
const preparedRigs = new WeakMap<CharacterRig, PreparedRig>();

const footPointsOf = (side: 'Left' | 'Right') => ['Foot', 'ToeBase', 'ToeBase_end'].map((n) => at(`${side}${n}` as CanonicalJoint));

function prepared(rig: CharacterRig): PreparedRig {
  const known = preparedRigs.get(rig);
  if (known) return known;
  checkRig(rig);
  const rest = restWorld(rig);
  const found = mapRig(rig);
  // The rest pose's height (its vertical extent), not the map's: a map the file gives may not carry one.
  const restYs = rest.positions.map((p) => p[1]);
  const restHeight = Math.max(...restYs) - Math.min(...restYs);
  if (!(restHeight > 0)) describeRigError('its rest pose has no height (every bone at one level)');
  const mapping: HumanoidMap = found.height > 0 ? found : { ...found, height: restHeight };
  const unitsPerMetre = 10 ** Math.round(Math.log10(restHeight / TYPICAL_HEIGHT));
  const restCanonical = toCanonical(
    { fps: 30, frames: 1, joints: rig.bones, parents: rig.parents, positions: Float32Array.from(rest.positions.flat()) },
    { scheme: mapping.scheme, source: mapping.source, scale: 1 / unitsPerMetre },
  );
  const restAt = (k: number): Vec3 => [restCanonical[k * 3], restCanonical[k * 3 + 1], restCanonical[k * 3 + 2]];
  const characterLeg = legLength(restCanonical, 1);
  if (!(characterLeg > 1e-4)) throw new SkeletonMapError("retarget: the character's legs have no length");
  const boneOf = mapping.source;
  const pointOfBone = new Array<number>(rig.bones.length).fill(-1);
  boneOf.forEach((b, k) => b >= 0 && pointOfBone[b] < 0 && (pointOfBone[b] = k));

  // Heights: the rig's rest floor and its ankles' height above it.
  const restLowest = Math.min(...(['Left', 'Right'] as const).flatMap(footPointsOf).map((k) => restAt(k)[1]));
  const restFloor = restLowest >= 0 && restLowest <= REST_FLOOR_SLACK ? 0 : restLowest;
  const characterAnkle = (restAt(at('LeftFoot'))[1] + restAt(at('RightFoot'))[1]) / 2 - restFloor;

  const hipsBone = boneOf[at('Hips')];
  let rootBone = hipsBone;
  while (rig.parents[rootBone] >= 0) rootBone = rig.parents[rootBone];

  // The points a foot stands on: the ankle (heel), the toe base (ball) and the toe tip where the rig has a bone there
  // (skeletonMap.ts derives one along the foot where it has none: a guess the foot does not stand on).
  const restForward = normalize(cross(sub(restAt(at('LeftUpLeg')), restAt(at('RightUpLeg'))), [0, 1, 0]));
  const legs: LegBones[] = (['Left', 'Right'] as const).map((side) => {
    const ankle = boneOf[at(`${side}Foot`)];
    const thigh = boneOf[at(`${side}UpLeg`)];
    const inverseAnkle = quatConjugate(rest.rotations[ankle]);
    return {
      thigh,
      knee: boneOf[at(`${side}Leg`)],
      kneeForward: quatRotate(quatConjugate(rest.rotations[thigh]), restForward),
      ankle,
      toe: boneOf[at(`${side}ToeBase`)],
      tip: boneOf[at(`${side}ToeBase_end`)],
      offsets: footPointsOf(side).map((k) => quatRotate(inverseAnkle, sub(restAt(k), restAt(at(`${side}Foot`))).map((v) => v * unitsPerMetre) as Vec3)),
      clearance: footPointsOf(side).map((k) => restAt(k)[1] - restFloor),
    };
  });
  const rig1: PreparedRig = {
    rest, restLocal: rig.restRotations.map(quatNormalize), mapping, unitsPerMetre, restCanonical, restAt, characterLeg,
    boneOf, pointOfBone, mapped: pointOfBone.map((k) => k >= 0),
    restRef: RULES.map((rule) => (rule.twist ? rule.twist(restAt) : ([0, 0, 0] as Vec3))),
    restFloor, characterAnkle,
    restHipJoints: sub(midpoint(restAt(at('LeftUpLeg')), restAt(at('RightUpLeg'))), restAt(at('Hips'))),
    // The root's rest offset from the hips: the bones between keep their rest rotations, so it is constant.
    rootBone, hipsFromRoot: sub(rest.positions[hipsBone], rest.positions[rootBone]),
    legs,
  };
  preparedRigs.set(rig, rig1);
  return rig1;
}

/**
 * The numbers measured on the source that set how it is retargeted (see RetargetOptions.calibration). They are
 * measured on the motion given unless given.
 */
function calibrate(src: Float32Array, F: number, contacts: Uint8Array, rig: PreparedRig): RetargetCalibration {
  const srcAt = (f: number, k: number): Vec3 => [src[(f * K + k) * 3], src[(f * K + k) * 3 + 1], src[(f * K + k) * 3 + 2]];
  const sourceLeg = legLength(src, F);
  if (!(sourceLeg > 1e-4)) throw new SkeletonMapError("retarget: the motion's legs have no length");
  // Feet: the rig's flat foot (its rest) may slope more or less than the source's flat foot (its median slope over
  // the planted frames where its ankle is lowest: flat on the floor, not landing on the heel or the ball); the foot
  // and toes are turned down by the difference, so that a flat foot of the source is flat on the character too (toes
  // neither floating nor sunk when the heel is down).
  const slopes = [0, 0, 0, 0];
  (['Left', 'Right'] as const).forEach((side, s) => {
    const [ankle, toe, tip] = footPointsOf(side);
    const flatFrames: number[] = [];
    for (let f = 0; f < F; f++) if (contacts[f * 2 + s]) flatFrames.push(f);
    flatFrames.sort((f, g) => srcAt(f, ankle)[1] - srcAt(g, ankle)[1]);
    flatFrames.length = Math.min(flatFrames.length, Math.ceil(flatFrames.length * FLAT_SHARE));
    if (!flatFrames.length) return;
    // The foot (ankle → toe base) and the toes (toe base → tip) each by their own slopes.
    [[ankle, toe], [toe, tip]].forEach(([from, to], i) => {
      const sourceFlat = median(flatFrames.map((f) => pitchOf(sub(srcAt(f, to), srcAt(f, from)))));
      slopes[s * 2 + i] = sourceFlat - pitchOf(sub(rig.restAt(to), rig.restAt(from)));
    });
  });
  // The source's ankles' height when planted (else their lowest), and the height of its feet's lowest point then.
  const plantedAnkles: number[] = [];
  const plantedLows: number[] = [];
  for (let f = 0; f < F; f++) {
    (['Left', 'Right'] as const).forEach((side, s) => {
      if (!contacts[f * 2 + s]) return;
      plantedAnkles.push(srcAt(f, at(`${side}Foot`))[1]);
      plantedLows.push(Math.min(...footPointsOf(side).map((k) => srcAt(f, k)[1])));
    });
  }
  let sourceAnkle = median(plantedAnkles);
  if (!Number.isFinite(sourceAnkle)) {
    const lows: number[] = [];
    for (let f = 0; f < F; f++) lows.push(Math.min(srcAt(f, at('LeftFoot'))[1], srcAt(f, at('RightFoot'))[1]));
    sourceAnkle = median(lows);
  }
  const sourceSole = Number.isFinite(median(plantedLows)) ? median(plantedLows) : 0;
  return { scale: rig.characterLeg / sourceLeg, sourceAnkle, sourceSole, footSlopes: slopes };
}

function checkCalibration(c: RetargetCalibration): RetargetCalibration {
  const ok = c && c.scale > 0 && Number.isFinite(c.sourceAnkle) && Number.isFinite(c.sourceSole) && c.footSlopes?.length === 4 && c.footSlopes.every(Number.isFinite);
  if (!ok) throw new Error('retarget: options.calibration is not one a retarget returned (scale, sourceAnkle, sourceSole, four footSlopes)');
  return c;
}

/** Retargets `source` (any humanoid Motion: every model's canonical output or an import) onto `rig`. */
export function retarget(source: Motion, rig: CharacterRig, options: RetargetOptions = {}): RetargetResult {
  const prep = prepared(rig);
  const F = source.frames;
  if (!(F >= 1) || !(source.fps > 0)) throw new Error(`retarget: the motion needs frames and a positive fps (got ${F} frames at ${source.fps} fps)`);
  const B = rig.bones.length;
  const footIK = options.footIK ?? true;
  const { rest, restLocal, mapping, unitsPerMetre, restCanonical, restAt, characterLeg, pointOfBone, restRef, characterAnkle, restHipJoints, rootBone, hipsFromRoot, legs, mapped } = prep;

  // The source's canonical points and contacts.
  const src = sourceCanonical(source);
  const srcAt = (f: number, k: number): Vec3 => [src[(f * K + k) * 3], src[(f * K + k) * 3 + 1], src[(f * K + k) * 3 + 2]];
  const contacts = source.contacts && source.contacts.length === F * 2
    ? Uint8Array.from(source.contacts)
    : labelContacts(src, new Uint8Array(F * 2), CANONICAL_JOINTS, source.fps);
  const calibration = options.calibration ? checkCalibration(options.calibration) : calibrate(src, F, contacts, prep);
  const { scale, sourceAnkle, sourceSole } = calibration;
  const slopeOffset = new Float64Array(K);
  [at('LeftFoot'), at('LeftToeBase'), at('RightFoot'), at('RightToeBase')].forEach((k, i) => (slopeOffset[k] = calibration.footSlopes[i]));

  // Where each segment points: the first target point far enough from the bone's point in the rest and the source.
  const minSegment = 0.01 * characterLeg;
  const segmentEnd = RULES.map((rule, k) => rule.to.find((e) =>
    length(sub(restAt(e), restAt(k))) > minSegment && length(sub(srcAt(0, e), srcAt(0, k))) > minSegment / scale) ?? -1);
  const restDir = segmentEnd.map((e, k) => (e >= 0 ? sub(restAt(e), restAt(k)) : ([0, 0, 0] as Vec3)));

  // Each source foot's height above the floor per frame (its lowest point less where that lies when planted), scaled
  // up for a taller character but not down for a shorter one (toe clearance in the swing is a few centimetres
  // whatever one's size): a swinging foot of the character clears the floor at least as far, so it does not scuff it.
  const sourceFootPoints = (['Left', 'Right'] as const).map(footPointsOf);
  const lowestOf = (f: number, s: number) => Math.min(...sourceFootPoints[s].map((k) => src[(f * K + k) * 3 + 1]));
  const swingClearance = [0, 1].map((s) => Float64Array.from({ length: F }, (_, f) => Math.max(0, lowestOf(f, s) - sourceSole) * Math.max(1, scale)));

  const rotations = new Float32Array(F * B * 4);
  const rootTranslations = new Float32Array(F * 3);
  const positions = new Float32Array(F * B * 3);
  const worlds: Quat[][] = [];

  // Pass 1: the pose from the source's rotations; per bone its world rotation (mapped bones: R × rest world).
  for (let f = 0; f < F; f++) {
    const points: Vec3[] = [];
    for (let k = 0; k < K; k++) points.push(srcAt(f, k));
    const p: Points = (k) => points[k];
    const delta: Quat[] = new Array(K);
    for (let k = 0; k < K; k++) {
      const rule = RULES[k];
      const parentDelta = rule.parent >= 0 ? delta[rule.parent] : quatIdentity();
      const e = segmentEnd[k];
      if (e < 0) {
        delta[k] = parentDelta;
        continue;
      }
      let dir = sub(p(e), p(k));
      if (slopeOffset[k] !== 0) dir = pitchDown(dir, slopeOffset[k]);
      const aligned = rule.twist ? alignFrames(restDir[k], restRef[k], dir, rule.twist(p)) : undefined;
      delta[k] = aligned ?? quatNormalize(quatMultiply(swingRotation(quatRotate(parentDelta, restDir[k]), dir), parentDelta));
    }
    const world: Quat[] = new Array(B);
    for (let b = 0; b < B; b++) {
      const k = pointOfBone[b];
      const parent = rig.parents[b];
      world[b] = k >= 0 ? quatNormalize(quatMultiply(delta[k], rest.rotations[b])) : parent >= 0 ? quatMultiply(world[parent], restLocal[b]) : restLocal[b];
    }
    worlds.push(world);
    // The legs' hip joints (their midpoint) go where the source's go, scaled; the character stands on y = 0
    // (whatever floor its rest pose stood on), its ankles as high above it as the source's are, scaled.
    const mid = midpoint(p(at('LeftUpLeg')), p(at('RightUpLeg')));
    const hipJoints: Vec3 = [mid[0] * scale, (mid[1] - sourceAnkle) * scale + characterAnkle, mid[2] * scale];
    const hips = sub(hipJoints, quatRotate(delta[at('Hips')], restHipJoints));
    const root = sub(hips.map((v) => v * unitsPerMetre) as Vec3, hipsFromRoot);
    rootTranslations.set(root, f * 3);
    poseFrame(rig, world, rootBone, root, rotations, positions, f);
  }

  if (footIK) plantFeet(rig, legs, worlds, mapped, contacts, swingClearance, source.fps, unitsPerMetre, rootBone, rootTranslations, restLocal, rotations, positions);

  for (let i = 0; i < positions.length; i++) positions[i] /= unitsPerMetre;
  const motion: Motion = { fps: source.fps, frames: F, joints: [...rig.bones], parents: [...rig.parents], positions, contacts };
  return { motion, rotations, rootTranslations, rootBone, mapping, scale, unitsPerMetre, restCanonical, contacts, calibration };
}

/**
 * One frame from its world rotations: writes the local rotations and the positions (rig units; FK with three.js
 * semantics: a bone's position is its parent's plus the parent's world rotation applied to the bone's rest
 * translation; `rootBone` stands at `root`, other roots at their rest).
 */
function poseFrame(rig: CharacterRig, world: Quat[], rootBone: number, root: Vec3, rotations: Float32Array, positions: Float32Array, f: number): void {
  const B = rig.bones.length;
  for (let b = 0; b < B; b++) {
    const parent = rig.parents[b];
    let local: Quat;
    if (parent < 0) {
      local = world[b];
      const t = b === rootBone ? root : rig.restTranslations[b];
      positions.set(t, (f * B + b) * 3);
    } else {
      local = quatNormalize(quatMultiply(quatConjugate(world[parent]), world[b]));
      const o = quatRotate(world[parent], rig.restTranslations[b]);
      const pp = (f * B + parent) * 3;
      const at3 = (f * B + b) * 3;
      positions[at3] = positions[pp] + o[0];
      positions[at3 + 1] = positions[pp + 1] + o[1];
      positions[at3 + 2] = positions[pp + 2] + o[2];
    }
    // Keep w ≥ 0 so that consecutive frames interpolate the short way.
    if (local[3] < 0) local = [-local[0], -local[1], -local[2], -local[3]];
    rotations.set(local, (f * B + b) * 4);
  }
}

/** The world rotations of a frame with unmapped bones re-derived from their (possibly turned) parents. */
function refreshUnmapped(rig: CharacterRig, world: Quat[], mapped: boolean[], restLocal: Quat[]): void {
  for (let b = 0; b < rig.bones.length; b++) {
    const parent = rig.parents[b];
    if (!mapped[b] && parent >= 0) world[b] = quatMultiply(world[parent], restLocal[b]);
  }
}

/**
 * Holds the character's planted feet still on the floor (see the header, step 5), in place: turns the thighs and
 * shins of `worlds` and rewrites `rotations` and `positions`.
 */
function plantFeet(
  rig: CharacterRig, legs: LegBones[], worlds: Quat[][], mapped: boolean[], contacts: Uint8Array, swingClearance: Float64Array[], fps: number, unitsPerMetre: number,
  rootBone: number, rootTranslations: Float32Array, restLocal: Quat[], rotations: Float32Array, positions: Float32Array,
): void {
  const B = rig.bones.length;
  const F = worlds.length;
  const pos = (f: number, b: number): Vec3 => [positions[(f * B + b) * 3], positions[(f * B + b) * 3 + 1], positions[(f * B + b) * 3 + 2]];
  // A foot's points: rigid with the foot bone, but a toe-tip bone, which the toes' own rotation carries.
  const footPoints = (f: number, leg: LegBones): Vec3[] => {
    const a = pos(f, leg.ankle);
    return leg.offsets.map((o, i) => {
      if (i === 2 && leg.tip >= 0) return pos(f, leg.tip);
      const d = quatRotate(worlds[f][leg.ankle], o);
      return [a[0] + d[0], a[1] + d[1], a[2] + d[2]] as Vec3;
    });
  };
  // Height of a foot above the floor: its lowest point relative to that point's rest height (rig units); a derived
  // toe tip does not count.
  const lowest = (points: Vec3[], leg: LegBones): { i: number; height: number } => {
    let i = 0, height = Infinity;
    points.forEach((p, n) => {
      if (n === 2 && leg.tip < 0) return;
      const h = p[1] - leg.clearance[n] * unitsPerMetre;
      if (h < height) [i, height] = [n, h];
    });
    return { i, height };
  };
  const blend = Math.max(1, Math.round(RELEASE_SECONDS * fps));
  const shifts: Vec3[][] = legs.map(() => new Array<Vec3>(F));
  // Per leg and planted frame, the pinned foot point (0 ankle, 1 toe base, 2 toe tip); -1 in free frames.
  const pinned: Int8Array[] = legs.map(() => new Int8Array(F).fill(-1));
  legs.forEach((leg, s) => {
    // Planted frames: pin the lowest point where it was (corrected) the frame before, at floor height.
    let previous: Vec3[] | null = null;
    const planted: boolean[] = [];
    for (let f = 0; f < F; f++) {
      planted[f] = contacts[f * 2 + s] > 0;
      if (!planted[f]) {
        previous = null;
        continue;
      }
      const points = footPoints(f, leg);
      const low = lowest(points, leg);
      const anchor = previous ? previous[low.i] : points[low.i];
      // As high as the source's foot above its floor (scaled), up to PLANTED_LIFT: a labelled contact begins and ends
      // with the source's foot still a few centimetres up (contactLabels.ts), and pulling it down there drags the
      // character's foot along the floor.
      const lift = Math.min(swingClearance[s][f], PLANTED_LIFT) * unitsPerMetre;
      const shift: Vec3 = [anchor[0] - points[low.i][0], lift - low.height, anchor[2] - points[low.i][2]];
      shifts[s][f] = shift;
      pinned[s][f] = low.i;
      previous = points.map((p) => [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]] as Vec3);
    }
  });
  lowerHips(rig, legs, shifts, pinned, pos, footPoints, blend, rootBone, rootTranslations, positions);
  legs.forEach((leg, s) => {
    const planted = Array.from({ length: F }, (_, f) => contacts[f * 2 + s] > 0);
    // Free frames: the neighbouring contacts' corrections fading out (after) and in (before); the foot at least as
    // high above the floor as the source's (scaled).
    for (let f = 0; f < F; f++) {
      if (planted[f]) continue;
      const shift: Vec3 = [0, 0, 0];
      for (let d = 1; d <= blend; d++) {
        const w = 1 - smoothstep(d / (blend + 1));
        const fade = (g: number) => {
          if (g < 0 || g >= F || !planted[g]) return false;
          for (let a = 0; a < 3; a++) shift[a] += w * shifts[s][g][a];
          return true;
        };
        if (fade(f - d)) break;
      }
      for (let d = 1; d <= blend; d++) {
        const w = 1 - smoothstep(d / (blend + 1));
        const g = f + d;
        if (g < F && planted[g]) {
          for (let a = 0; a < 3; a++) shift[a] += w * shifts[s][g][a];
          break;
        }
      }
      const height = lowest(footPoints(f, leg).map((p) => [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]] as Vec3), leg).height;
      const clearance = swingClearance[s][f] * unitsPerMetre;
      if (height < clearance) shift[1] += clearance - height;
      shifts[s][f] = shift;
    }
  });

  // Per leg, the mapped bones the IK turns: from the thigh down to the knee (exclusive), and from the knee down to the
  // foot (exclusive); the foot and what hangs from it keep their world rotations.
  const turned = legs.map((leg) => {
    const between = rig.bones.flatMap((_, b) => (mapped[b] && isBelow(rig.parents, b, leg.thigh) && !isBelow(rig.parents, b, leg.ankle) ? [b] : []));
    return { thigh: between.filter((b) => !isBelow(rig.parents, b, leg.knee)), shin: between.filter((b) => isBelow(rig.parents, b, leg.knee)) };
  });
  for (let f = 0; f < F; f++) {
    const world = worlds[f];
    let changed = false;
    legs.forEach((leg, s) => {
      const shift = shifts[s][f];
      if (Math.hypot(...shift) < 1e-9) return;
      const hip = pos(f, leg.thigh), knee = pos(f, leg.knee), ankle = pos(f, leg.ankle);
      let target: Vec3 = [ankle[0] + shift[0], ankle[1] + shift[1], ankle[2] + shift[2]];
      const l1 = length(sub(knee, hip)), l2 = length(sub(ankle, knee));
      const reach = REACH * (l1 + l2);
      if (pinned[s][f] > 0 && length(sub(target, hip)) > reach) {
        // Out of reach with the ball or the toe tip pinned (a push-off): the heel rises, the foot turning about it.
        const ball = footPoints(f, leg)[pinned[s][f]];
        const pivot: Vec3 = [ball[0] + shift[0], ball[1] + shift[1], ball[2] + shift[2]];
        const lifted = pivotAbout(hip, target, pivot, reach);
        if (lifted) {
          const turn = swingRotation(sub(target, pivot), sub(lifted, pivot));
          world[leg.ankle] = quatNormalize(quatMultiply(turn, world[leg.ankle]));
          // Turning about the toe tip, the toes turn with the foot (about the ball they stay flat on the floor).
          if (pinned[s][f] === 2 && leg.toe >= 0 && mapped[leg.toe]) world[leg.toe] = quatNormalize(quatMultiply(turn, world[leg.toe]));
          target = lifted;
        }
      }
      // The knee bends towards where it points (a leg the source holds straight bends forward, not sideways).
      const [newKnee, newAnkle] = twoBoneIK(hip, knee, target, l1, l2, REACH, quatRotate(world[leg.thigh], leg.kneeForward), KNEE_POLE * (l1 + l2));
      const thighTurn = rotationFromTwoVectors(sub(knee, hip), sub(ankle, hip), sub(newKnee, hip), sub(newAnkle, hip)) ?? swingRotation(sub(knee, hip), sub(newKnee, hip));
      const shinTurn = quatMultiply(swingRotation(quatRotate(thighTurn, sub(ankle, knee)), sub(newAnkle, newKnee)), thighTurn);
      // Every bone from the thigh down to (not including) the foot turns: the thigh by thighTurn, the shin and the
      // bones between it and the foot by shinTurn; the foot keeps its world rotation.
      for (const b of turned[s].thigh) world[b] = quatNormalize(quatMultiply(thighTurn, world[b]));
      for (const b of turned[s].shin) world[b] = quatNormalize(quatMultiply(shinTurn, world[b]));
      changed = true;
    });
    if (!changed) continue;
    refreshUnmapped(rig, world, mapped, restLocal);
    poseFrame(rig, world, rootBone, [rootTranslations[f * 3], rootTranslations[f * 3 + 1], rootTranslations[f * 3 + 2]], rotations, positions, f);
  }
}

/**
 * Lowers the whole character where a planted foot's pinned point is out of the leg's reach even with the foot
 * turned about it (the ankle's distance beyond the ball): by the least drop that brings it within reach, eased in
 * and out over `blend` frames. Planted feet keep their targets (their shifts grow by the drop); `positions` and
 * `rootTranslations` are lowered in place.
 */
function lowerHips(
  rig: CharacterRig, legs: LegBones[], shifts: Vec3[][], pinned: Int8Array[], pos: (f: number, b: number) => Vec3,
  footPoints: (f: number, leg: LegBones) => Vec3[], blend: number, rootBone: number, rootTranslations: Float32Array, positions: Float32Array,
): void {
  const F = rootTranslations.length / 3;
  const moved = rig.bones.flatMap((_, b) => (isBelow(rig.parents, b, rootBone) ? [b] : []));
  const B = rig.bones.length;
  const need = new Float64Array(F);
  for (let f = 0; f < F; f++) {
    legs.forEach((leg, s) => {
      const i = pinned[s][f];
      if (i < 0) return;
      const hip = pos(f, leg.thigh), knee = pos(f, leg.knee), ankle = pos(f, leg.ankle);
      const points = footPoints(f, leg);
      const shift = shifts[s][f];
      const point: Vec3 = [points[i][0] + shift[0], points[i][1] + shift[1], points[i][2] + shift[2]];
      const reach = REACH * (length(sub(knee, hip)) + length(sub(ankle, knee))) + (i > 0 ? 0.95 * length(sub(points[i], ankle)) : 0);
      const v = sub(point, hip);
      const across = v[0] * v[0] + v[2] * v[2];
      if (across >= reach * reach) return;
      need[f] = Math.max(need[f], -v[1] - Math.sqrt(reach * reach - across));
    });
  }
  for (let f = 0; f < F; f++) {
    let drop = 0;
    for (let g = Math.max(0, f - blend); g <= Math.min(F - 1, f + blend); g++) {
      drop = Math.max(drop, need[g] * (1 - smoothstep(Math.abs(f - g) / (blend + 1))));
    }
    if (!(drop > 0)) continue;
    rootTranslations[f * 3 + 1] -= drop;
    for (const b of moved) positions[(f * B + b) * 3 + 1] -= drop;
    legs.forEach((_, s) => pinned[s][f] >= 0 && (shifts[s][f][1] += drop));
  }
}

/**
 * The ankle nearest `ankle` that lies `reach` from the hip and as far from `pivot` as `ankle` does: the foot turned
 * about its pinned ball until the leg reaches (footLock.ts pivotFoot); undefined when no turn reaches.
 */
function pivotAbout(hip: Vec3, ankle: Vec3, pivot: Vec3, reach: number): Vec3 | undefined {
  const r = length(sub(ankle, pivot));
  const toPivot = sub(pivot, hip);
  const d = length(toPivot);
  if (d >= reach + r || d <= Math.abs(reach - r) || d < 1e-9) return undefined;
  const u: Vec3 = [toPivot[0] / d, toPivot[1] / d, toPivot[2] / d];
  const a = (reach * reach - r * r + d * d) / (2 * d);
  const rho = Math.sqrt(Math.max(reach * reach - a * a, 0));
  const centre: Vec3 = [hip[0] + u[0] * a, hip[1] + u[1] * a, hip[2] + u[2] * a];
  const rel = sub(ankle, centre);
  const along = rel[0] * u[0] + rel[1] * u[1] + rel[2] * u[2];
  const off: Vec3 = [rel[0] - u[0] * along, rel[1] - u[1] * along, rel[2] - u[2] * along];
  const n = length(off);
  if (n < 1e-9) return undefined;
  return [centre[0] + (off[0] * rho) / n, centre[1] + (off[1] * rho) / n, centre[2] + (off[2] * rho) / n];
}

/** Whether bone `b` is `ancestor` or lies below it. */
function isBelow(parents: readonly number[], b: number, ancestor: number): boolean {
  for (let j = b; j >= 0; j = parents[j]) if (j === ancestor) return true;
  return false;
}
