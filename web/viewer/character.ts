// The shown motion as the mannequin (mannequin.ts): its canonical points per frame, found once per motion, and the
// look switch. A motion on the canonical skeleton (every model's output) is used as it is; any other skeleton
// goes through the skeleton map (web/motion/skeletonMap.ts) at its own scale; one that does not map (not a
// humanoid) has no character, and the viewer keeps the stick figure for it.

import { CANONICAL_JOINTS, mapSkeleton, toCanonical, type SkeletonMapping } from '../motion/skeletonMap';
import type { Motion } from '../motion/types';
import { BONES, Mannequin, type MannequinOptions } from './mannequin';

export { DEFAULT_LOOK, LOOKS, type Look } from './look';

/** Whether the motion's joints are the canonical skeleton's, in its order. */
export function isCanonical(joints: readonly string[]): boolean {
  return joints.length === BONES && joints.every((name, k) => name === CANONICAL_JOINTS[k]);
}

/**
 * The motion's canonical points (frames × 25 × 3, in its own units and place): the positions themselves for a
 * canonical skeleton, else through the mapping (found when null); null when the skeleton does not map.
 */
export function canonicalPoints(motion: Motion, mapping: SkeletonMapping | null): { points: Float32Array; mapping: SkeletonMapping | null } | null {
  if (isCanonical(motion.joints)) return { points: motion.positions, mapping: null };
  try {
    const found = mapping ?? mapSkeleton(motion, 1);
    // Scale 1: the character stands in the motion's own units, where its stick figure and trail are.
    const points = toCanonical(motion, { ...found, scale: 1 });
    for (let i = 0; i < Math.min(points.length, BONES * 3); i++) if (!Number.isFinite(points[i])) return null;
    return { points, mapping: found };
  } catch {
    return null; // not a humanoid (or a skeleton the map does not know): the stick figure stays
  }
}

/** A mannequin following a motion: build with `CharacterDriver.for`, then `update` per frame. */
export class CharacterDriver {
  private readonly frame = new Float32Array(BONES * 3);

  private constructor(
    readonly mannequin: Mannequin,
    private points: Float32Array,
    private mapping: SkeletonMapping | null,
  ) {}

  /** The mannequin for `motion`, or null when its skeleton has no canonical mapping. */
  static for(motion: Motion, options: MannequinOptions = {}): CharacterDriver | null {
    if (motion.frames < 1) return null;
    const found = canonicalPoints(motion, null);
    if (!found) return null;
    return new CharacterDriver(new Mannequin(found.points, motion.frames, options), found.points, found.mapping);
  }

  /** A new window of the same skeleton (a live stream): its points, with the mapping already found. Returns false if it no longer maps. */
  setMotion(motion: Motion): boolean {
    const found = canonicalPoints(motion, this.mapping);
    if (!found) return false;
    this.points = found.points;
    return true;
  }

  /** Poses the mannequin between frames i0 and i1 (`a` of the way), shifted by (dx, 0, dz). */
  update(i0: number, i1: number, a: number, dx = 0, dz = 0): void {
    const n = BONES * 3, P = this.points, o0 = i0 * n, o1 = i1 * n, F = this.frame;
    if (o1 + n > P.length) return;
    for (let k = 0; k < n; k += 3) {
      F[k] = P[o0 + k] + (P[o1 + k] - P[o0 + k]) * a + dx;
      F[k + 1] = P[o0 + k + 1] + (P[o1 + k + 1] - P[o0 + k + 1]) * a;
      F[k + 2] = P[o0 + k + 2] + (P[o1 + k + 2] - P[o0 + k + 2]) * a + dz;
    }
    this.mannequin.pose(F);
  }

  /** The canonical points last posed (25 × 3). */
  get posed(): Float32Array {
    return this.frame;
  }

  dispose(): void {
    this.mannequin.dispose();
  }
}
