// Maps an imported skeleton onto the canonical one (training/mocap/canonical_skeleton.json) with the humanoid
// mapper (humanoid.ts: any humanoid skeleton, by its tree and bone lengths, names as hints), and carries motion
// cleaned on the canonical skeleton back onto the imported skeleton.
//
// Canonical points that a skeleton lacks but that lie between or beyond points it has (the spine and neck
// segments, toe and hand tips, the toes of a skeleton without any) are placed from them at canonical proportions.
import { quatConjugate, quatMultiply, quatRotate, type Quat } from './math';
import type { Motion } from './types';
import { CANONICAL_JOINTS, CANONICAL_PARENTS, mapHumanoid, SkeletonMapError, type CanonicalJoint } from './humanoid';

export {
  CANONICAL_JOINTS, CANONICAL_PARENTS, DESCRIPTIONS, NAME_SCHEMES, SkeletonMapError, matchSchemes, normaliseName, type CanonicalJoint,
} from './humanoid';

/**
 * Points placed from others when a skeleton lacks them: at `t` along from → to (t > 1 extends beyond `to`).
 * The fractions are the canonical skeleton's own segment proportions.
 */
const DERIVED: Partial<Record<CanonicalJoint, { from: CanonicalJoint; to: CanonicalJoint; t: number }>> = {
  Spine: { from: 'Hips', to: 'Neck', t: 0.33 },
  Spine1: { from: 'Hips', to: 'Neck', t: 0.66 },
  Neck1: { from: 'Neck', to: 'Head', t: 0.5 },
  Head_end: { from: 'Neck', to: 'Head', t: 1.5 },
  LeftToeBase_end: { from: 'LeftFoot', to: 'LeftToeBase', t: 1.5 },
  RightToeBase_end: { from: 'RightFoot', to: 'RightToeBase', t: 1.5 },
  LeftHand_end: { from: 'LeftForeArm', to: 'LeftHand', t: 1.3 },
  RightHand_end: { from: 'RightForeArm', to: 'RightHand', t: 1.3 },
};

/**
 * The toe base of a skeleton without toes (canonical metres): ahead of the ankle, where the canonical skeleton's toe
 * base lies from its ankle (training/mocap/canonical_skeleton.json: 0.114 forward, 0.029 down), forward being the
 * hips' facing in that frame (left hip → right hip turned a quarter about y).
 */
const TOE_FORWARD = 0.114;
const TOE_DOWN = 0.029;

/** How an imported skeleton's joints become the canonical points. */
export interface SkeletonMapping {
  /** The naming scheme that gave the mapper its hints ('' when names did not help). */
  scheme: string;
  /** Per canonical point: the imported joint placed there, or -1 when the point is derived (DERIVED). */
  source: number[];
  /** Imported leg length (hip, knee, ankle) divided into the canonical one: canonical = imported × scale. */
  scale: number;
}

function legLength(motion: Motion, source: number[]): number {
  const at = (f: number, j: number) => motion.positions.subarray((f * motion.joints.length + j) * 3, (f * motion.joints.length + j) * 3 + 3);
  const dist = (f: number, a: number, b: number) => Math.hypot(at(f, a)[0] - at(f, b)[0], at(f, a)[1] - at(f, b)[1], at(f, a)[2] - at(f, b)[2]);
  const idx = (name: CanonicalJoint) => source[CANONICAL_JOINTS.indexOf(name)];
  let total = 0;
  for (let f = 0; f < motion.frames; f++) {
    for (const side of ['Left', 'Right'] as const) {
      total += dist(f, idx(`${side}UpLeg`), idx(`${side}Leg`)) + dist(f, idx(`${side}Leg`), idx(`${side}Foot`));
    }
  }
  return total / (2 * motion.frames);
}

/**
 * The canonical mapping of `motion`'s skeleton (`canonicalLegLength`: hip → knee → ankle) by the humanoid mapper
 * (humanoid.ts); throws SkeletonMapError naming what is missing.
 */
export function mapSkeleton(motion: Pick<Motion, 'joints' | 'parents' | 'positions' | 'frames'>, canonicalLegLength: number): SkeletonMapping {
  const { source, scheme } = mapHumanoid(motion);
  const mapping = { scheme, source, scale: 1 };
  const length = legLength(motion as Motion, source);
  if (!(length > 1e-4)) throw new SkeletonMapError('this skeleton cannot be mapped to the canonical one: its legs have no length');
  mapping.scale = canonicalLegLength / length;
  return mapping;
}

/** The canonical points (frames × 25 × 3) of `motion`, scaled by mapping.scale; derived points placed (DERIVED). */
export function toCanonical(motion: Motion, mapping: SkeletonMapping): Float32Array {
  const J = motion.joints.length;
  const K = CANONICAL_JOINTS.length;
  const out = new Float32Array(motion.frames * K * 3);
  const s = mapping.scale;
  for (let f = 0; f < motion.frames; f++) {
    const o = f * K * 3;
    mapping.source.forEach((j, k) => {
      if (j < 0) return;
      for (let a = 0; a < 3; a++) out[o + k * 3 + a] = motion.positions[(f * J + j) * 3 + a] * s;
    });
    // Toes of a skeleton without any: ahead of the ankle along the hips' facing.
    for (const side of ['Left', 'Right'] as const) {
      const toe = CANONICAL_JOINTS.indexOf(`${side}ToeBase`);
      if (mapping.source[toe] >= 0) continue;
      const ankle = CANONICAL_JOINTS.indexOf(`${side}Foot`) * 3 + o;
      const l = CANONICAL_JOINTS.indexOf('LeftUpLeg') * 3 + o, r = CANONICAL_JOINTS.indexOf('RightUpLeg') * 3 + o;
      const lx = out[l] - out[r], lz = out[l + 2] - out[r + 2];
      const n = Math.hypot(lx, lz) || 1;
      out[o + toe * 3] = out[ankle] + (-lz / n) * TOE_FORWARD;
      out[o + toe * 3 + 1] = out[ankle + 1] - TOE_DOWN;
      out[o + toe * 3 + 2] = out[ankle + 2] + (lx / n) * TOE_FORWARD;
    }
    // Derived points, in canonical order (a derived point only uses earlier or mapped ones).
    CANONICAL_JOINTS.forEach((point, k) => {
      const d = DERIVED[point];
      if (!d || mapping.source[k] >= 0) return;
      const a = CANONICAL_JOINTS.indexOf(d.from), b = CANONICAL_JOINTS.indexOf(d.to);
      for (let c = 0; c < 3; c++) out[o + k * 3 + c] = out[o + a * 3 + c] + d.t * (out[o + b * 3 + c] - out[o + a * 3 + c]);
    });
  }
  return out;
}

/**
 * Per joint, its bone's length over the frames (0 for the root): the median, or with `jitter` (σ per coordinate
 * of the positions' noise, m) the noise taken out: noise lengthens a bone on average (E|b + n|² = |b|² + 6σ² with
 * both ends jittered), most of all a short one.
 */
export function medianBoneLengths(motion: Motion, jitter = 0): Float64Array {
  const J = motion.joints.length;
  const out = new Float64Array(J);
  const values = new Float64Array(motion.frames);
  for (let j = 0; j < J; j++) {
    const p = motion.parents[j];
    if (p < 0) continue;
    for (let f = 0; f < motion.frames; f++) {
      const a = (f * J + j) * 3, b = (f * J + p) * 3;
      const P = motion.positions;
      values[f] = (P[a] - P[b]) ** 2 + (P[a + 1] - P[b + 1]) ** 2 + (P[a + 2] - P[b + 2]) ** 2;
    }
    const sorted = Float64Array.from(values).sort();
    const squared = sorted[Math.floor(sorted.length / 2)];
    out[j] = Math.sqrt(Math.max(squared - 6 * jitter * jitter, squared / 4));
  }
  return out;
}

/**
 * Which canonical segment carries each imported bone (parent → joint), and whether the bone is a whole canonical
 * segment (both ends mapped, parent to child), whose cleaned direction it then takes exactly.
 *   - a mapped joint: the canonical segment that ends at its point;
 *   - an unmapped joint with a mapped joint below it (an extra spine or shoulder joint): the segment ending at the
 *     first mapped joint below;
 *   - an unmapped joint with none below (fingers, a head-top, a prop): the segment beyond its nearest mapped
 *     ancestor (that point's only canonical child), or the ancestor's own segment where it has several (hips, chest).
 */
export function boneOwners(parents: readonly number[], mapping: SkeletonMapping): { owner: number[]; whole: boolean[] } {
  const J = parents.length;
  const pointOf = new Array<number>(J).fill(-1);
  mapping.source.forEach((j, k) => {
    if (j >= 0) pointOf[j] = k;
  });
  const children = parents.map(() => [] as number[]);
  parents.forEach((p, j) => p >= 0 && children[p].push(j));
  const firstMappedBelow = (j: number): number => {
    const queue = [...children[j]];
    while (queue.length) {
      const c = queue.shift()!;
      if (pointOf[c] >= 0) return pointOf[c];
      queue.push(...children[c]);
    }
    return -1;
  };
  const canonicalChildren = CANONICAL_PARENTS.map((_, k) => CANONICAL_PARENTS.flatMap((p, c) => (p === k ? [c] : [])));
  const owner = new Array<number>(J).fill(0);
  const whole = new Array<boolean>(J).fill(false);
  for (let j = 0; j < J; j++) {
    if (parents[j] < 0) continue;
    if (pointOf[j] >= 0) {
      owner[j] = pointOf[j];
      whole[j] = pointOf[parents[j]] >= 0 && CANONICAL_PARENTS[pointOf[j]] === pointOf[parents[j]];
      continue;
    }
    const below = firstMappedBelow(j);
    if (below >= 0) {
      owner[j] = below;
      continue;
    }
    let a = parents[j];
    while (a >= 0 && pointOf[a] < 0) a = parents[a];
    const k = a >= 0 ? pointOf[a] : 0;
    owner[j] = canonicalChildren[k].length === 1 ? canonicalChildren[k][0] : k;
  }
  return { owner, whole };
}

/**
 * How far (m) a joint riding rigidly at its median offset lands from where it was captured, on clean capture
 * (fingers and thumbs of held-out CMU walks: 3-6 mm; docs/models/cleanup.md). fromCanonical weighs it against the
 * jitter left in the joint's own captured point.
 */
const RIDER_OFFSET_ERROR = 0.005;

/**
 * `motion` (the imported skeleton) moved as the canonical motion changed from `before` to `after`. A bone that is a
 * whole canonical segment points from where its parent was placed at the cleaned canonical point (unscaled); any
 * other bone rides on its owning canonical segment (boneOwners) at its median offset in that segment's frame, fused
 * with its own point in `motion` moved as the owner's end moved (weighted by RIDER_OFFSET_ERROR against `jitter`, the
 * noise left in `motion`'s points). Every bone gets the skeleton's length for it, the median over the
 * frames (a file's skeleton has one length per bone; noisy positions give a different one each frame, and the
 * median ignores glitches). The root follows the canonical hips.
 *
 * before/after: canonical points (frames × 25 × 3, canonical scale) and the world rotations of their segments
 * (frames × 25 × 4, x y z w; the rotation at a point turns the segment that ends there).
 */
export function fromCanonical(
  motion: Motion,
  mapping: SkeletonMapping,
  before: { points: Float32Array; rotations: Float32Array },
  after: { points: Float32Array; rotations: Float32Array },
  jitter = 0,
): Motion {
  const J = motion.joints.length;
  const K = CANONICAL_JOINTS.length;
  const { owner, whole } = boneOwners(motion.parents, mapping);
  const out = new Float32Array(motion.positions.length);
  const inv = 1 / mapping.scale;
  const hips = 0;
  // The joint at the canonical hips, when it is not the root (a Biped's pelvis, Bandai's Hips under a floor root,
  // iClone's CC_Base_Hip): it is placed at the cleaned hips itself, not carried on its parent (its offset from a
  // root that stays at the origin changes every frame: it has position channels of its own).
  const hipsJoint = motion.parents[mapping.source[hips]] >= 0 ? mapping.source[hips] : -1;
  const p = motion.positions;
  const lengths = medianBoneLengths(motion, jitter);
  // A bone that is not a whole canonical segment rides rigidly on its owner: its offset in the owner's frame is the
  // median over the frames (per component), so jitter of short bones such as fingers is not carried over.
  const attached: [number, number, number][] = motion.parents.map(() => [0, 0, 0]);
  {
    const values = [new Float64Array(motion.frames), new Float64Array(motion.frames), new Float64Array(motion.frames)];
    for (let j = 0; j < J; j++) {
      const parent = motion.parents[j];
      if (parent < 0 || whole[j] || j === hipsJoint) continue;
      for (let f = 0; f < motion.frames; f++) {
        const o = (f * J + j) * 3, q = (f * J + parent) * 3, r = (f * K + owner[j]) * 4;
        const g = before.rotations;
        const local = quatRotate([-g[r], -g[r + 1], -g[r + 2], g[r + 3]], [p[o] - p[q], p[o + 1] - p[q + 1], p[o + 2] - p[q + 2]]);
        for (let a = 0; a < 3; a++) values[a][f] = local[a];
      }
      attached[j] = values.map((v) => Float64Array.from(v).sort()[Math.floor(motion.frames / 2)]) as [number, number, number];
    }
  }
  // Per frame: every joint starts at its target (a whole segment's end at the cleaned canonical point, unscaled;
  // any other joint rigidly on its owner), the bone lengths are then imposed by a few rounds of moving both ends of
  // each whole bone halfway (so a target chain a few centimetres too short or long spreads the difference instead of
  // piling it up at the chain's end), and a last pass in parent order places each joint exactly at its bone's length,
  // aimed at where the rounds put it.
  const target = new Float64Array(J * 3);
  const placed = new Float64Array(J * 3);
  const riderWeight = RIDER_OFFSET_ERROR ** 2 / (RIDER_OFFSET_ERROR ** 2 + 3 * jitter ** 2);
  const ROUNDS = 8;
  for (let f = 0; f < motion.frames; f++) {
    const rot = (src: Float32Array, k: number): Quat => {
      const o = (f * K + k) * 4;
      return [src[o], src[o + 1], src[o + 2], src[o + 3]];
    };
    const pt = (src: Float32Array, k: number, a: number) => src[(f * K + k) * 3 + a];
    const attach = (j: number, from: Float64Array, to: Float64Array) => {
      const moved = quatRotate(rot(after.rotations, owner[j]), attached[j]);
      for (let a = 0; a < 3; a++) to[j * 3 + a] = from[motion.parents[j] * 3 + a] + moved[a];
    };
    for (let j = 0; j < J; j++) {
      const parent = motion.parents[j];
      if (parent < 0) {
        // The root moves with the canonical hips (it is the hips in every scheme but a Biped's root node).
        for (let a = 0; a < 3; a++) target[a + j * 3] = p[(f * J + j) * 3 + a] + (pt(after.points, hips, a) - pt(before.points, hips, a)) * inv;
      } else if (whole[j] || j === hipsJoint) {
        for (let a = 0; a < 3; a++) target[j * 3 + a] = pt(after.points, owner[j], a) * inv;
      } else {
        attach(j, target, target);
      }
    }
    for (let round = 0; round < ROUNDS; round++) {
      for (let j = 0; j < J; j++) {
        const parent = motion.parents[j];
        if (parent < 0 || !whole[j]) continue;
        const d = [0, 1, 2].map((a) => target[j * 3 + a] - target[parent * 3 + a]);
        const n = Math.hypot(d[0], d[1], d[2]);
        if (n < 1e-9) continue;
        const c = (n - lengths[j]) / n;
        const parentMoves = motion.parents[parent] >= 0 && parent !== hipsJoint ? 0.5 : 0; // the root and hips stay where the hips put them
        for (let a = 0; a < 3; a++) {
          target[j * 3 + a] -= (1 - parentMoves) * c * d[a];
          target[parent * 3 + a] += parentMoves * c * d[a];
        }
      }
    }
    for (let j = 0; j < J; j++) {
      const parent = motion.parents[j];
      if (parent < 0 || j === hipsJoint) {
        for (let a = 0; a < 3; a++) placed[j * 3 + a] = target[j * 3 + a];
      } else if (whole[j]) {
        const d = [0, 1, 2].map((a) => target[j * 3 + a] - placed[parent * 3 + a]);
        const n = Math.hypot(d[0], d[1], d[2]);
        const q = (f * J + parent) * 3, o = (f * J + j) * 3;
        const dir = n > 1e-9 ? d.map((v) => v / n) : [p[o] - p[q], p[o + 1] - p[q + 1], p[o + 2] - p[q + 2]].map((v, _, all) => v / (Math.hypot(...all) || 1));
        for (let a = 0; a < 3; a++) placed[j * 3 + a] = placed[parent * 3 + a] + dir[a] * lengths[j];
      } else {
        attach(j, placed, placed);
        // Fused with the joint's own captured point, carried as its owner segment moved (its end's shift and turn):
        // each estimate weighted by the inverse of its variance (RIDER_OFFSET_ERROR against the point's jitter).
        const k = owner[j], o = (f * J + j) * 3;
        const turn = quatMultiply(rot(after.rotations, k), quatConjugate(rot(before.rotations, k)));
        const own = quatRotate(turn, [0, 1, 2].map((a) => p[o + a] - pt(before.points, k, a) * inv) as [number, number, number]);
        for (let a = 0; a < 3; a++) placed[j * 3 + a] = riderWeight * (pt(after.points, k, a) * inv + own[a]) + (1 - riderWeight) * placed[j * 3 + a];
        // Rigid offsets keep their own median length; scale to the bone's median length like every bone.
        const d = [0, 1, 2].map((a) => placed[j * 3 + a] - placed[parent * 3 + a]);
        const n = Math.hypot(d[0], d[1], d[2]);
        if (n > 1e-12) for (let a = 0; a < 3; a++) placed[j * 3 + a] = placed[parent * 3 + a] + (d[a] / n) * lengths[j];
      }
    }
    out.set(placed, f * J * 3);
  }
  return { fps: motion.fps, frames: motion.frames, joints: motion.joints.slice(), parents: motion.parents.slice(), positions: out };
}
