// Foot contacts for the motion that is shown: the model's contact bit combined with the foot's own height and
// speed, so a foot resting on the floor is planted (and locked) even when the bit is off, and a foot in the
// air is not pulled down because the bit is on. A model without contact bits (the dance models) passes zeros:
// then height and speed alone decide. A port of training/contact_labels.py (see its docstring for
// why); tests/fixtures/contact_labels.json checks the two.
//
// Per foot and frame, causal (live streams label each frame as it arrives; labelContacts does a whole motion):
//   - the lowest of the foot's ankle, toe and toe tip (legs.ts footPoints) this frame; h = its height above the floor (y = 0);
//   - v = that point's horizontal speed since the previous frame (m/s; 0 in the first frame);
//   - planted when (h < near and v < slow) or (bit and h < bitNear); once planted it stays while
//     (h < stayNear and v < staySlow) or (bit and h < bitNear).

import { findLegs, footPoints } from './legs';

/** metres and metres per second (training/contact_labels.py LABEL_THRESHOLDS). */
export const LABEL_THRESHOLDS = Object.freeze({ near: 0.04, slow: 1.0, stayNear: 0.06, staySlow: 1.5, bitNear: 0.1 });


/** Streaming labels: `step` once per frame, in order; `reset` before a new motion. */
export class ContactLabeller {
  private readonly feet: number[][];
  private readonly n: number;
  private previous: Float64Array | null = null;
  private planted = [false, false];

  constructor(joints: readonly string[], private readonly fps: number) {
    if (!(fps > 0)) throw new RangeError(`contact labels: fps must be positive, got ${fps}`);
    this.feet = findLegs(joints, 'contact labels').map(footPoints);
    this.n = joints.length * 3;
  }

  reset(): void {
    this.previous = null;
    this.planted = [false, false];
  }

  /** One frame's world positions (joints × 3) and the model's bits (left, right; non-zero = contact) → labels in `out`. */
  step(pose: ArrayLike<number>, bits: ArrayLike<number>, out: Uint8Array = new Uint8Array(2)): Uint8Array {
    if (pose.length !== this.n) throw new Error(`contact labels: expected ${this.n} position values, got ${pose.length}`);
    const T = LABEL_THRESHOLDS;
    const prev = this.previous;
    for (let side = 0; side < 2; side++) {
      let low = this.feet[side][0];
      for (const j of this.feet[side]) if (pose[j * 3 + 1] < pose[low * 3 + 1]) low = j;
      const h = pose[low * 3 + 1];
      const v = prev ? Math.hypot(pose[low * 3] - prev[low * 3], pose[low * 3 + 2] - prev[low * 3 + 2]) * this.fps : 0;
      const byBit = bits[side] > 0 && h < T.bitNear;
      const touches = h < T.near && v < T.slow;
      const stays = h < T.stayNear && v < T.staySlow;
      this.planted[side] = byBit || touches || (this.planted[side] && stays);
      out[side] = this.planted[side] ? 1 : 0;
    }
    if (!prev) this.previous = Float64Array.from(pose);
    else prev.set(pose);
    return out;
  }
}

/** Labels (frames × 2) of a whole motion: positions frames × joints × 3, the model's bits frames × 2. */
export function labelContacts(positions: ArrayLike<number>, bits: ArrayLike<number>, joints: readonly string[], fps: number): Uint8Array {
  const n = joints.length * 3;
  const frames = positions.length / n;
  if (!Number.isInteger(frames)) throw new Error(`contact labels: ${positions.length} position values is not a whole number of ${joints.length}-joint frames`);
  if (bits.length !== frames * 2) throw new Error(`contact labels: ${bits.length} contact values for ${frames} frames (expected ${frames * 2})`);
  const labeller = new ContactLabeller(joints, fps);
  const out = new Uint8Array(frames * 2);
  const pose = new Float64Array(n);
  for (let f = 0; f < frames; f++) {
    for (let k = 0; k < n; k++) pose[k] = positions[f * n + k];
    labeller.step(pose, [bits[f * 2], bits[f * 2 + 1]], out.subarray(f * 2, f * 2 + 2));
  }
  return out;
}
