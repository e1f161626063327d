// Canonical joint positions → the generator's feature rows: the inverse of featureDecode.ts (the encode half of
// training/data/features.py FeatureCodec), with inverse kinematics in front, since imported motion is positions only.
//
// Rotations follow the canonical skeleton's bone-end convention (web/motion/skeleton.ts): the world rotation G_j at
// point j turns the segment that ends at j, p_j = p_parent + G_j · offset_j, G_j = G_parent · q_j.
// Positions fix each segment's direction but not its twist about itself. The twist is read from the segment's
// children: it turns the children's directions, at their reference (mean) local rotations, as close as it can to
// where they are (the knee's plane sets the thigh's twist, the shoulders the chest's). Without children the twist
// stays at the reference. Fixed joints (the pelvis-to-hip and hand segments) stay at their reference, as in training.
import { dot, length, normalize, quatConjugate, quatMultiply, quatNormalize, quatRotate, swingRotation, type Quat, type Vec3 } from '../motion/math';
import { bestRotation } from '../motion/fitSkeleton';
import { JOINT_FEATURES_START, type GeneratorInfo } from './generatorInfo';
import type { RootStart } from './featureDecode';

function quatAboutUnitAxis(axis: Vec3, angle: number): Quat {
  const s = Math.sin(angle / 2);
  return [axis[0] * s, axis[1] * s, axis[2] * s, Math.cos(angle / 2)];
}

/** log of a unit quaternion as a rotation vector, angle in [0, π]. */
function quatToRotvec(q: Quat): Vec3 {
  const sign = q[3] < 0 ? -1 : 1;
  const x = q[0] * sign, y = q[1] * sign, z = q[2] * sign, w = q[3] * sign;
  const s = Math.hypot(x, y, z);
  const angle = 2 * Math.atan2(s, w);
  const k = s > 1e-9 ? angle / s : 2;
  return [x * k, y * k, z * k];
}

const yawQuat = (angle: number): Quat => [0, Math.sin(angle / 2), 0, Math.cos(angle / 2)];

/** Heading (yaw) of a root rotation: where its +z axis points on the ground (heading_of in features.py). */
export function headingOf(root: Quat): number {
  const f = quatRotate(root, [0, 0, 1]);
  return Math.atan2(f[0], f[2]);
}

/** Step of the coarse twist scan (rad); the best is then refined by golden-section search. */
const TWIST_SCAN = Math.PI / 12;
/** σ (rad) of a fixed child's direction error in the twist cost (hips from the pelvis, hand tips from the wrist). */
const FIXED_CHILD_SIGMA = 0.1;

/**
 * Inverse kinematics of canonical positions onto the generator's skeleton, one frame at a time. The twist of each
 * segment about itself (which positions do not show) is the one that makes the joint's own local rotation and its
 * children's most likely under a prior: by default each joint's reference (mean) rotation with the features'
 * normalisation spread (`prior` can give other local rotations).
 */
export class CanonicalIK {
  private readonly parents: number[];
  private readonly offsets: Vec3[];
  private readonly refs: Quat[];
  private readonly fixed: Set<number>;
  private readonly sigma = new Map<number, Vec3>();
  private readonly children: number[][];

  constructor(private readonly info: GeneratorInfo) {
    this.parents = info.skeleton.parents;
    const o = info.skeleton.offsets;
    this.offsets = this.parents.map((_, j) => [o[j * 3], o[j * 3 + 1], o[j * 3 + 2]]);
    this.refs = info.features.references.map((q) => quatNormalize(q as Quat));
    this.fixed = new Set(info.features.fixed_joints);
    info.features.joints.forEach((j, k) => {
      const i = JOINT_FEATURES_START + 3 * k;
      this.sigma.set(j, [info.normalisation.std[i], info.normalisation.std[i + 1], info.normalisation.std[i + 2]]);
    });
    this.children = this.parents.map(() => [] as number[]);
    this.parents.forEach((p, j) => p >= 0 && this.children[p].push(j));
  }

  /**
   * World segment rotations of one frame's points (J × 3, read from `points` at `base`) into `out` (J × 4 at
   * `outBase`). `prior`: per joint, the local rotation the twist should stay nearest (default the references).
   */
  solve(points: ArrayLike<number>, base: number, out: Float32Array, outBase: number, prior: readonly Quat[] = this.refs): void {
    const { parents, offsets, refs, fixed, children, sigma } = this;
    const J = parents.length;
    const from = (a: number, b: number): Vec3 => [
      points[base + b * 3] - points[base + a * 3],
      points[base + b * 3 + 1] - points[base + a * 3 + 1],
      points[base + b * 3 + 2] - points[base + a * 3 + 2],
    ];
    /** Squared z-score of joint j's local rotation against the prior's, in the features' rotation-vector terms. */
    const zscore = (j: number, local: Quat): number => {
      const v = quatToRotvec(quatMultiply(quatConjugate(refs[j]), local));
      const m = quatToRotvec(quatMultiply(quatConjugate(refs[j]), prior[j]));
      const s = sigma.get(j)!;
      return ((v[0] - m[0]) / s[0]) ** 2 + ((v[1] - m[1]) / s[1]) ** 2 + ((v[2] - m[2]) / s[2]) ** 2;
    };
    const cost = (j: number, parentWorld: Quat, g: Quat): number => {
      let total = zscore(j, quatMultiply(quatConjugate(parentWorld), g));
      for (const k of children[j]) {
        const rest = quatMultiply(g, prior[k]);
        const predicted = quatRotate(rest, offsets[k]);
        const observed = from(j, k);
        if (fixed.has(k)) {
          const angle = Math.acos(Math.max(-1, Math.min(1, dot(normalize(predicted), normalize(observed)))));
          total += (angle / FIXED_CHILD_SIGMA) ** 2;
        } else {
          total += zscore(k, quatMultiply(quatConjugate(g), quatMultiply(swingRotation(predicted, observed), rest)));
        }
      }
      return total;
    };
    const G: Quat[] = new Array(J);
    // The pelvis: the rotation that best takes its children's reference directions onto where they are.
    const kids = children[0];
    G[0] = bestRotation(kids.map((c) => normalize(quatRotate(refs[c], offsets[c]))), kids.map((c) => normalize(from(0, c)))) ?? [0, 0, 0, 1];
    for (let j = 1; j < J; j++) {
      const parent = G[parents[j]];
      let g = quatMultiply(parent, fixed.has(j) ? refs[j] : prior[j]);
      if (!fixed.has(j)) {
        const d = from(parents[j], j);
        g = quatMultiply(swingRotation(quatRotate(g, offsets[j]), d), g);
        const axis = normalize(d);
        if (length(axis) > 0) g = this.bestTwist(j, axis, g, (q) => cost(j, parent, q));
      }
      G[j] = quatNormalize(g);
      out.set(G[j], outBase + j * 4);
    }
    out.set(G[0], outBase);
  }

  /** Per joint, the twist the last solved frame chose: frames come in order, so the next one starts near it. */
  private readonly lastTwist = new Map<number, number>();

  /**
   * g turned about `axis` by the angle of least cost: a coarse scan of the whole turn (or, after a first frame, of the
   * last frame's twist and its neighbours: twists change little from frame to frame), then golden-section search.
   */
  private bestTwist(joint: number, axis: Vec3, g: Quat, cost: (q: Quat) => number): Quat {
    const twisted = (theta: number) => quatMultiply(quatAboutUnitAxis(axis, theta), g);
    const at = (theta: number) => cost(twisted(theta));
    let best = 0, bestCost = at(0);
    const last = this.lastTwist.get(joint);
    const candidates: number[] = [];
    if (last === undefined) for (let theta = -Math.PI + TWIST_SCAN; theta < Math.PI; theta += TWIST_SCAN) candidates.push(theta);
    else candidates.push(last, last - TWIST_SCAN, last + TWIST_SCAN);
    for (const theta of candidates) {
      const c = at(theta);
      if (c < bestCost) [best, bestCost] = [theta, c];
    }
    let lo = best - TWIST_SCAN, hi = best + TWIST_SCAN;
    const phi = (Math.sqrt(5) - 1) / 2;
    let a = hi - phi * (hi - lo), b = lo + phi * (hi - lo), ca = at(a), cb = at(b);
    for (let it = 0; it < 16; it++) {
      if (ca < cb) {
        hi = b; b = a; cb = ca; a = hi - phi * (hi - lo); ca = at(a);
      } else {
        lo = a; a = b; ca = cb; b = lo + phi * (hi - lo); cb = at(b);
      }
    }
    const theta = ca < cb ? a : b;
    this.lastTwist.set(joint, theta);
    return twisted(theta);
  }

  /** The joint-angle part of a feature row (tilt, joint rotation vectors) of one frame's world rotations. */
  angles(world: ArrayLike<number>, base: number, heading: number, row: Float32Array): void {
    const g = (j: number): Quat => [world[base + j * 4], world[base + j * 4 + 1], world[base + j * 4 + 2], world[base + j * 4 + 3]];
    row.set(quatToRotvec(quatMultiply(quatConjugate(this.refs[0]), quatMultiply(yawQuat(-heading), g(0)))), 4);
    this.info.features.joints.forEach((j, k) => {
      const local = quatMultiply(quatConjugate(g(this.parents[j])), g(j));
      row.set(quatToRotvec(quatMultiply(quatConjugate(this.refs[j]), local)), JOINT_FEATURES_START + 3 * k);
    });
  }
}

/** World segment rotations (frames × J × 4) of canonical positions (frames × J × 3), twists nearest the references. */
export function canonicalRotations(info: GeneratorInfo, points: ArrayLike<number>): Float32Array {
  const J = info.skeleton.parents.length;
  const frames = points.length / (J * 3);
  const out = new Float32Array(frames * J * 4);
  const ik = new CanonicalIK(info);
  for (let f = 0; f < frames; f++) ik.solve(points, f * J * 3, out, f * J * 4);
  return out;
}

export interface EncodedFeatures {
  /** frames × D physical feature rows; row t describes frame t relative to frame t − 1. */
  features: Float32Array;
  /** The root state before frame 0 (frame 0 stepped back by its first step), for decodeFeatures' `start`. */
  start: RootStart;
}

/**
 * Feature rows of every frame of canonical positions (frames × J × 3) with their world rotations
 * (canonicalRotations). Frame 0 has no predecessor: it is encoded as the step from frame 0 moved back by the
 * 0 → 1 step. Contacts are `contacts` (frames × 2) or 0.
 */
export function encodeFeatures(info: GeneratorInfo, points: ArrayLike<number>, world: Float32Array, contacts?: Uint8Array): EncodedFeatures {
  const { parents } = info.skeleton;
  const J = parents.length;
  const D = info.onnx.dim;
  const frames = points.length / (J * 3);
  const ik = new CanonicalIK(info);
  const g = (f: number, j: number): Quat => {
    const o = (f * J + j) * 4;
    return [world[o], world[o + 1], world[o + 2], world[o + 3]];
  };
  const heading = new Float64Array(frames);
  for (let f = 0; f < frames; f++) heading[f] = headingOf(g(f, 0));
  for (let f = 1; f < frames; f++) heading[f] = heading[f - 1] + wrap(heading[f] - heading[f - 1]); // unwrapped
  const rootX = (f: number) => points[f * J * 3], rootZ = (f: number) => points[f * J * 3 + 2];
  const next = frames > 1 ? 1 : 0;
  const start: RootStart = {
    x: 2 * rootX(0) - rootX(next),
    z: 2 * rootZ(0) - rootZ(next),
    heading: 2 * heading[0] - heading[next],
  };
  const features = new Float32Array(frames * D);
  let prev = { ...start };
  for (let f = 0; f < frames; f++) {
    const row = f * D;
    const dx = rootX(f) - prev.x, dz = rootZ(f) - prev.z;
    const c = Math.cos(prev.heading), s = Math.sin(prev.heading);
    features[row] = c * dx - s * dz;
    features[row + 1] = s * dx + c * dz;
    features[row + 2] = heading[f] - prev.heading;
    features[row + 3] = points[f * J * 3 + 1];
    ik.angles(world, f * J * 4, heading[f], features.subarray(row, row + D));
    features[row + D - 2] = contacts ? contacts[f * 2] : 0;
    features[row + D - 1] = contacts ? contacts[f * 2 + 1] : 0;
    prev = { x: rootX(f), z: rootZ(f), heading: heading[f] };
  }
  return { features, start };
}

function wrap(a: number): number {
  return a - 2 * Math.PI * Math.round(a / (2 * Math.PI));
}
