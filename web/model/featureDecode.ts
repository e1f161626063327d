// Generator feature rows (physical units) → root trajectory, local rotations and joint positions.
// A port of training/data/features.py FeatureCodec.decode followed by forward kinematics; keep the two in step.
import { forwardKinematics } from '../motion/skeleton';
import { quatMultiply, quatNormalize, quatRotate, type Quat } from '../motion/math';
import type { Skeleton } from '../motion/types';
import { JOINT_FEATURES_START, type GeneratorInfo } from './generatorInfo';

/** Where the character stands before the first decoded frame (metres, radians; heading 0 faces +z). */
export interface RootStart {
  x: number;
  z: number;
  heading: number;
}

export interface DecodedFeatures {
  /** frames × joints × 3, world metres. */
  positions: Float32Array;
  /** frames × 2 (left, right), 1 = planted. */
  contacts: Uint8Array;
  /** Heading of each frame (radians, unwrapped). */
  rootHeading: Float32Array;
  /** Root state after the last frame, in double precision: pass it as `start` to continue. */
  end: RootStart;
}

/** Rotation by `angle` about +y. */
function yawQuat(angle: number): Quat {
  return [0, Math.sin(angle / 2), 0, Math.cos(angle / 2)];
}

/** exp of a rotation vector: rotation by |v| about v/|v|. */
function rotvecToQuat(x: number, y: number, z: number): Quat {
  const angle = Math.sqrt(x * x + y * y + z * z);
  const s = angle > 1e-9 ? Math.sin(angle / 2) / angle : 0.5;
  return [x * s, y * s, z * s, Math.cos(angle / 2)];
}

export function generatorSkeleton(info: GeneratorInfo): Skeleton {
  return {
    joints: info.skeleton.joints,
    parents: info.skeleton.parents,
    offsets: Float32Array.from(info.skeleton.offsets),
  };
}

/**
 * Moves `root` by one frame's root channels: the step (dtx, dtz), expressed in the previous frame's
 * heading frame, then the heading change dry.
 */
export function integrateRoot(root: RootStart, dtx: number, dtz: number, dry: number): void {
  const c = Math.cos(root.heading), s = Math.sin(root.heading);
  root.x += c * dtx + s * dtz;
  root.z += -s * dtx + c * dtz;
  root.heading += dry;
}

/** `offsets` (joints × 3) replaces the skeleton's rest offsets, e.g. to decode onto a captured clip's own proportions. */
export function decodeFeatures(info: GeneratorInfo, features: Float32Array, start: RootStart = { x: 0, z: 0, heading: 0 }, offsets?: ArrayLike<number>): DecodedFeatures {
  const D = info.onnx.dim;
  const skeleton = offsets ? { ...generatorSkeleton(info), offsets: Float32Array.from(offsets) } : generatorSkeleton(info);
  const J = skeleton.parents.length;
  if (features.length % D !== 0) throw new Error(`decodeFeatures: ${features.length} values is not a whole number of ${D}-value frames`);
  const frames = features.length / D;
  const references = info.features.references.map((q) => quatNormalize(q as Quat));
  const featureJoints = info.features.joints;

  const rootPositions = new Float32Array(frames * 3);
  const rotations = new Float32Array(frames * J * 4);
  const contacts = new Uint8Array(frames * 2);
  const rootHeading = new Float32Array(frames);

  const root = { ...start };
  for (let f = 0; f < frames; f++) {
    const row = f * D;
    integrateRoot(root, features[row], features[row + 1], features[row + 2]);
    rootPositions[f * 3] = root.x;
    rootPositions[f * 3 + 1] = features[row + 3];
    rootPositions[f * 3 + 2] = root.z;
    rootHeading[f] = root.heading;

    const base = f * J * 4;
    for (let j = 0; j < J; j++) rotations.set(references[j], base + j * 4); // fixed joints keep their reference
    const tilt = quatMultiply(references[0], rotvecToQuat(features[row + 4], features[row + 5], features[row + 6]));
    rotations.set(quatMultiply(yawQuat(root.heading), tilt), base);
    for (let k = 0; k < featureJoints.length; k++) {
      const j = featureJoints[k];
      const o = row + JOINT_FEATURES_START + 3 * k;
      rotations.set(quatMultiply(references[j], rotvecToQuat(features[o], features[o + 1], features[o + 2])), base + j * 4);
    }
    contacts[f * 2] = features[row + D - 2] > 0.5 ? 1 : 0;
    contacts[f * 2 + 1] = features[row + D - 1] > 0.5 ? 1 : 0;
  }

  return {
    positions: forwardKinematics(skeleton, rootPositions, rotations),
    contacts,
    rootHeading,
    end: root,
  };
}

/**
 * One physical feature row placed from `root` (the state before it) → world positions (joints × 3) on `offsets`:
 * decodeFeatures for a single frame, into one reused buffer (the clean-up's smoother poses each frame ~140 times).
 */
export function framePoser(info: GeneratorInfo, offsets: ArrayLike<number>): (row: ArrayLike<number>, root: RootStart) => Float32Array {
  const { parents } = info.skeleton;
  const J = parents.length;
  const refs = info.features.references.map((q) => quatNormalize(q as Quat));
  const featureOf = new Array<number>(J).fill(-1);
  info.features.joints.forEach((j, k) => (featureOf[j] = JOINT_FEATURES_START + 3 * k));
  const world: Quat[] = new Array(J);
  const out = new Float32Array(J * 3);
  return (row, root) => {
    const r = { ...root };
    integrateRoot(r, row[0], row[1], row[2]);
    world[0] = quatMultiply(yawQuat(r.heading), quatMultiply(refs[0], rotvecToQuat(row[4], row[5], row[6])));
    out[0] = r.x;
    out[1] = row[3];
    out[2] = r.z;
    for (let j = 1; j < J; j++) {
      const o = featureOf[j];
      const local = o < 0 ? refs[j] : quatMultiply(refs[j], rotvecToQuat(row[o], row[o + 1], row[o + 2]));
      const g = (world[j] = quatMultiply(world[parents[j]], local));
      const v = quatRotate(g, [offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]]);
      const p = parents[j] * 3;
      out[j * 3] = out[p] + v[0];
      out[j * 3 + 1] = out[p + 1] + v[1];
      out[j * 3 + 2] = out[p + 2] + v[2];
    }
    return out;
  };
}
