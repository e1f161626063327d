// Numbers that compare a motion with a cleaned copy of it (Clip mode's Clean up panel, ui/cleanupPanel.ts): jerk,
// foot sliding, bone-length change, mean joint error, and one joint's bend angle over time. Measured as in
// docs/models/cleanup.md (tests/eval/cleanup.eval.ts): jerk and sliding at 30 fps, sliding on the canonical leg
// points above a floor estimated from the lowest foot points.
import { lowFootSliding } from './footSkating';
import { CANONICAL_JOINTS, CANONICAL_PARENTS, mapSkeleton, medianBoneLengths, toCanonical } from './skeletonMap';
import type { Motion } from './types';

/** The frame rate jerk and sliding are measured at (the other reports' rate). */
export const MEASURE_FPS = 30;
/** The floor is this quantile of the per-frame lowest foot point (as the clean-up report rests its clips). */
const FLOOR_QUANTILE = 0.05;
const FOOT_POINTS = ['LeftFoot', 'LeftToeBase', 'LeftToeBase_end', 'RightFoot', 'RightToeBase', 'RightToeBase_end'];

/** Every step-th frame, step = round(fps / `fps`) (at least 1): the motion near `fps`, no filtering. */
export function atRate(motion: Motion, fps = MEASURE_FPS): Motion {
  const step = Math.max(1, Math.round(motion.fps / fps));
  if (step === 1) return motion;
  const n = motion.joints.length * 3;
  const frames = Math.floor((motion.frames - 1) / step) + 1;
  const positions = new Float32Array(frames * n);
  for (let f = 0; f < frames; f++) positions.set(motion.positions.subarray(f * step * n, (f * step + 1) * n), f * n);
  return { fps: motion.fps / step, frames, joints: motion.joints, parents: motion.parents, positions };
}

/** Mean over frames and joints of |third difference of the position| × fps³ (m/s³), at the motion's own rate; NaN under 4 frames. */
export function jerk(motion: Motion): number {
  const J = motion.joints.length, P = motion.positions;
  const k = motion.fps ** 3;
  let sum = 0, count = 0;
  for (let f = 3; f < motion.frames; f++) {
    for (let j = 0; j < J; j++) {
      let q = 0;
      for (let a = 0; a < 3; a++) {
        const at = (back: number) => P[((f - back) * J + j) * 3 + a];
        q += (at(0) - 3 * at(1) + 3 * at(2) - at(3)) ** 2;
      }
      sum += Math.sqrt(q) * k;
      count++;
    }
  }
  return count ? sum / count : NaN;
}

/**
 * The motion's canonical points at its own size (scale 1), named CANONICAL_JOINTS, for measures that need the
 * canonical leg names; throws SkeletonMapError (naming the missing joints) for a skeleton that cannot be mapped.
 */
export function canonicalView(motion: Motion): Motion {
  const mapping = { ...mapSkeleton(motion, 1), scale: 1 };
  return { fps: motion.fps, frames: motion.frames, joints: [...CANONICAL_JOINTS], parents: [...CANONICAL_PARENTS], positions: toCanonical(motion, mapping) };
}

/** The floor height (m) under a canonical view: the 5th percentile over frames of the lowest foot point. */
export function floorHeight(view: Motion): number {
  const K = view.joints.length;
  const feet = FOOT_POINTS.map((n) => view.joints.indexOf(n));
  if (feet.some((j) => j < 0)) throw new Error(`floorHeight needs the canonical foot points ${FOOT_POINTS.join(', ')}`);
  const lows = new Float64Array(view.frames);
  for (let f = 0; f < view.frames; f++) {
    let low = Infinity;
    for (const j of feet) low = Math.min(low, view.positions[(f * K + j) * 3 + 1]);
    lows[f] = low;
  }
  lows.sort();
  return lows[Math.min(view.frames - 1, Math.floor(view.frames * FLOOR_QUANTILE))];
}

/**
 * Foot sliding (m/s): footSkating.ts lowFootSliding (the lowest foot point's horizontal speed while within 4 cm of
 * the floor) on the canonical view at 30 fps, with the floor at `floor` (default: floorHeight of the motion itself).
 * NaN when no foot comes near the floor; throws for a skeleton that cannot be mapped.
 */
export function footSliding(motion: Motion, floor?: number): number {
  const view = canonicalView(atRate(motion));
  const y0 = floor ?? floorHeight(view);
  const positions = view.positions.slice();
  for (let i = 1; i < positions.length; i += 3) positions[i] -= y0;
  return lowFootSliding({ ...view, positions });
}

function boneLength(motion: Motion, frame: number, j: number): number {
  const J = motion.joints.length, P = motion.positions;
  const a = (frame * J + j) * 3, b = (frame * J + motion.parents[j]) * 3;
  return Math.hypot(P[a] - P[b], P[a + 1] - P[b + 1], P[a + 2] - P[b + 2]);
}

/**
 * Bone-length change (m): the mean over bones and frames of |the bone's length − its median length in
 * `reference`| (default: the motion itself, so how much its bones stretch). `reference` has the same joints.
 */
export function boneLengthChange(motion: Motion, reference: Motion = motion): number {
  if (reference.joints.length !== motion.joints.length) throw new Error(`boneLengthChange: the reference has ${reference.joints.length} joints, the motion ${motion.joints.length}`);
  const lengths = medianBoneLengths(reference);
  let sum = 0, count = 0;
  for (let f = 0; f < motion.frames; f++) {
    for (let j = 0; j < motion.joints.length; j++) {
      if (motion.parents[j] < 0) continue;
      sum += Math.abs(boneLength(motion, f, j) - lengths[j]);
      count++;
    }
  }
  return count ? sum / count : 0;
}

/** Mean distance (m) between the same joint in the same frame of two motions with the same layout. */
export function meanJointError(a: Motion, b: Motion): number {
  if (a.positions.length !== b.positions.length) {
    throw new Error(`meanJointError: ${a.frames} frames × ${a.joints.length} joints against ${b.frames} × ${b.joints.length}`);
  }
  const P = a.positions, Q = b.positions;
  let sum = 0;
  for (let i = 0; i < P.length; i += 3) sum += Math.hypot(P[i] - Q[i], P[i + 1] - Q[i + 1], P[i + 2] - Q[i + 2]);
  return P.length ? sum / (P.length / 3) : 0;
}

/** The joints that have a bone in (a parent) and a bone out (a child), with the child used: the first in order. */
export function bendJoints(parents: readonly number[]): { joint: number; child: number }[] {
  const out: { joint: number; child: number }[] = [];
  parents.forEach((p, j) => {
    if (p < 0) return;
    const child = parents.indexOf(j);
    if (child >= 0) out.push({ joint: j, child });
  });
  return out;
}

/**
 * A joint's bend angle per frame, degrees: the angle between the bone into it (parent → joint) and the bone out of
 * it (joint → its first child), 0 for a straight limb. NaN in frames where either bone has no length; throws for a
 * joint without both bones.
 */
export function bendAngles(motion: Motion, joint: number): Float32Array {
  const bend = bendJoints(motion.parents).find((b) => b.joint === joint);
  if (!bend) throw new Error(`bendAngles: joint ${motion.joints[joint] ?? joint} has no bone into it and out of it`);
  const J = motion.joints.length, P = motion.positions, p = motion.parents[joint];
  const out = new Float32Array(motion.frames);
  for (let f = 0; f < motion.frames; f++) {
    const o = f * J * 3;
    let dot = 0, aa = 0, bb = 0;
    for (let c = 0; c < 3; c++) {
      const a = P[o + joint * 3 + c] - P[o + p * 3 + c];
      const b = P[o + bend.child * 3 + c] - P[o + joint * 3 + c];
      dot += a * b;
      aa += a * a;
      bb += b * b;
    }
    const norm = Math.sqrt(aa * bb);
    out[f] = norm > 1e-12 ? (Math.acos(Math.min(1, Math.max(-1, dot / norm))) * 180) / Math.PI : NaN;
  }
  return out;
}

/** The numbers the Clean up panel shows for one motion. */
export interface CleanupNumbers {
  /** m/s³ at 30 fps. */
  jerk: number;
  /** m/s, NaN when the skeleton cannot be mapped or no foot comes near the floor. */
  sliding: number;
  /** m, against the reference's median bone lengths. */
  boneChange: number;
  /** m, mean joint error to the clean original; NaN when there is none. */
  error: number;
}

/**
 * The panel's numbers for `motion`: bone-length change against `reference` (default the motion), joint error to
 * `original` when given, sliding above the floor of `original` (else of `reference`) so two motions compare on one floor.
 */
export function cleanupNumbers(motion: Motion, options: { reference?: Motion; original?: Motion } = {}): CleanupNumbers {
  const reference = options.reference ?? motion;
  let sliding = NaN;
  try {
    const floor = floorHeight(canonicalView(atRate(options.original ?? reference)));
    sliding = footSliding(motion, floor);
  } catch {
    // A skeleton without the canonical legs has no sliding number; the others still hold.
  }
  return {
    jerk: jerk(atRate(motion)),
    sliding,
    boneChange: boneLengthChange(motion, reference),
    error: options.original ? meanJointError(motion, options.original) : NaN,
  };
}
