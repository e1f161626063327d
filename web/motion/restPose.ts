// The rest pose the exporters write (BVH: bvh.ts, glTF: gltf.ts): each joint's offset from its parent when
// every rotation is zero (metres; the root's is zero). Bone lengths are the clip's mean lengths in both rest
// poses; the directions are
//   'clip':  each bone as in the clip's tallest frame (a clip that starts crouched still gets a standing rest,
//            which keeps unit detection on re-import reliable);
//   'tpose': a T-pose facing +z: legs straight down, feet and toes forward (+z), spine, neck and head up, arms
//            straight out sideways (left +x, right −x: CMU's rest pose faces +z with the left side at +x) with the
//            hands and fingers continuing them. Bones between those (pelvis → hips, chest → shoulders) and any the
//            T-pose does not name (props) keep their direction in the tallest frame, turned about y so that the
//            figure faces +z. Which joints are legs, arms and head comes from the humanoid mapper (humanoid.ts).
import { quatAboutAxis, quatRotate, length, normalize, type Vec3 } from './math';
import { boneVector, jointAt, type RigClip } from './jointRotations';
import { CANONICAL_JOINTS, mapHumanoid, type CanonicalJoint } from './humanoid';

export type RestPose = 'clip' | 'tpose';
export const REST_POSES: readonly RestPose[] = ['clip', 'tpose'];

/** Rest length (metres) given to bones of zero length so that importers do not drop their joint. */
const TINY_BONE = 1e-5;

const UP: Vec3 = [0, 1, 0];
const DOWN: Vec3 = [0, -1, 0];
const FORWARD: Vec3 = [0, 0, 1];
const LEFT: Vec3 = [1, 0, 0];
const RIGHT: Vec3 = [-1, 0, 0];

/** The points a T-pose needs named: hip, knee and ankle, shoulder, elbow and wrist of both sides, and the head. */
const TPOSE_POINTS = [
  'LeftUpLeg', 'LeftLeg', 'LeftFoot', 'RightUpLeg', 'RightLeg', 'RightFoot',
  'LeftArm', 'LeftForeArm', 'LeftHand', 'RightArm', 'RightForeArm', 'RightHand', 'Head',
] as const satisfies readonly CanonicalJoint[];
type TposePoint = (typeof TPOSE_POINTS)[number];

/** Each joint's rest offset from its parent (metres; [0, 0, 0] for the root) in the given rest pose. */
export function restOffsets(clip: RigClip, pose: RestPose): Vec3[] {
  const restFrame = tallestFrame(clip);
  const directions = pose === 'tpose' ? tposeDirections(clip, restFrame) : clipDirections(clip, restFrame);
  const rest: Vec3[] = clip.joints.map(() => [0, 0, 0]);
  for (let j = 1; j < clip.joints.length; j++) {
    let mean = 0;
    for (let f = 0; f < clip.frames; f++) mean += length(boneVector(clip, f, j));
    mean /= clip.frames;
    const len = mean > TINY_BONE ? mean : TINY_BONE;
    const dir = directions[j];
    rest[j] = [dir[0] * len, dir[1] * len, dir[2] * len];
  }
  return rest;
}

/** The frame with the largest y extent (the first of equals). */
function tallestFrame(clip: RigClip): number {
  const P = clip.positions;
  const J = clip.joints.length;
  let restFrame = 0;
  let tallest = -Infinity;
  for (let f = 0; f < clip.frames; f++) {
    let lo = Infinity;
    let hi = -Infinity;
    for (let j = 0; j < J; j++) {
      const y = P[(f * J + j) * 3 + 1];
      lo = Math.min(lo, y);
      hi = Math.max(hi, y);
    }
    if (hi - lo > tallest + 1e-9) {
      tallest = hi - lo;
      restFrame = f;
    }
  }
  return restFrame;
}

/** Unit direction of each bone in the rest frame (else the first frame where it has length; else up). */
function clipDirections(clip: RigClip, restFrame: number): Vec3[] {
  const dirs: Vec3[] = clip.joints.map(() => [0, 0, 0]);
  for (let j = 1; j < clip.joints.length; j++) {
    let dir = normalize(boneVector(clip, restFrame, j));
    for (let f = 0; length(dir) === 0 && f < clip.frames; f++) dir = normalize(boneVector(clip, f, j));
    if (length(dir) === 0) dir = [0, 1, 0];
    dirs[j] = dir;
  }
  return dirs;
}

/**
 * The T-pose points of a skeleton, by the humanoid mapper (humanoid.ts); throws an Error naming what is missing
 * ("T-pose rest needs a humanoid skeleton: …").
 */
function tposePoints(clip: RigClip): Record<TposePoint, number> {
  let source: number[];
  try {
    source = mapHumanoid(clip).source;
  } catch (e) {
    throw new Error(`T-pose rest needs a humanoid skeleton: ${(e as Error).message.replace(/^this skeleton is not a humanoid the playground can map: /, '')}`);
  }
  return Object.fromEntries(TPOSE_POINTS.map((point) => [point, source[CANONICAL_JOINTS.indexOf(point)]])) as Record<TposePoint, number>;
}

/** Unit direction of each bone in the T-pose (see the header); throws when the skeleton's limbs cannot be named. */
function tposeDirections(clip: RigClip, restFrame: number): Vec3[] {
  const at = tposePoints(clip);
  const { parents } = clip;
  /** Whether joint j lies strictly below joint a. */
  const below = (j: number, a: number) => {
    for (let k = parents[j]; k >= 0; k = parents[k]) if (k === a) return true;
    return false;
  };
  const onHeadChain = (j: number) => j === at.Head || below(at.Head, j) || below(j, at.Head);
  const facing = facingTurn(clip, restFrame, at);
  const clipDirs = clipDirections(clip, restFrame);
  return clip.joints.map((_, j): Vec3 => {
    if (parents[j] < 0) return [0, 0, 0];
    if (below(j, at.LeftArm)) return LEFT;
    if (below(j, at.RightArm)) return RIGHT;
    if (below(j, at.LeftFoot) || below(j, at.RightFoot)) return FORWARD;
    if (below(j, at.LeftUpLeg) || below(j, at.RightUpLeg)) return DOWN;
    if (onHeadChain(j)) return UP;
    return normalize(quatRotate(facing, clipDirs[j]));
  });
}

/** The turn about y that makes the figure of the rest frame face +z (its left hip and shoulder towards +x). */
function facingTurn(clip: RigClip, restFrame: number, at: Record<TposePoint, number>) {
  const across = (left: number, right: number) => {
    const l = jointAt(clip, restFrame, left);
    const r = jointAt(clip, restFrame, right);
    return [l[0] - r[0], l[2] - r[2]];
  };
  const hips = across(at.LeftUpLeg, at.RightUpLeg);
  const shoulders = across(at.LeftArm, at.RightArm);
  const x = hips[0] + shoulders[0];
  const z = hips[1] + shoulders[1];
  // quatAboutAxis('y', θ) takes the direction (cos θ, 0, sin θ) of x–z onto +x.
  return quatAboutAxis('y', x === 0 && z === 0 ? 0 : Math.atan2(z, x));
}
