// Foot-contact clean-up (Wang, Chai, Xia §4.3): planted feet stay in place and on the ground. A faithful
// port of training/footlock.py (see its docstring for the method); keep the two in step —
// tests/unit/footLock.test.ts checks this against footlock.py's output (tests/fixtures/footlock_reference.json).
//
// It works on world joint positions of the canonical skeleton plus the contact bits, is causal (FootLock.step
// once per frame, in order, for live streams; footLock() for a whole motion), changes only the knees, ankles
// and feet, and keeps every bone length exactly. Arithmetic is in double precision like the Python. The page
// also runs it on the dance set's skeleton (legs.ts), whose feet end at the toe: there the toes' part is
// skipped; that use has no Python counterpart. PlantedFeet / plantFeet put the contact labels
// (contactLabels.ts) in front of the lock, as footlock.py plant_feet does.

import { ContactLabeller, labelContacts } from './contactLabels';
import { findLegs } from './legs';

export interface FootLockSettings {
  /** Height (m) a planted toe point is brought to. */
  groundHeight: number;
  /** Frames to bring a planted toe to the ground height. */
  blendIn: number;
  /** Frames to release a lifted foot from its anchor. */
  blendOut: number;
  /** Fraction of thigh + shin the IK may stretch to. */
  reach: number;
  /** How much (m) the foot's forward direction adds to the raw knee's bend direction. */
  poleBias: number;
}

/** footlock.py's constants (refiner.json "footlock" carries the same values). */
export const FOOT_LOCK_DEFAULTS: Readonly<FootLockSettings> = Object.freeze({
  groundHeight: 0.03,
  blendIn: 3,
  blendOut: 6,
  reach: 0.999,
  poleBias: 0.05,
});

/** Foot pitch (radians, ankle-to-toe below level) up to which a planted foot's heading is held fully, and from which not at all (footlock.py FLAT_PITCH, STEEP_PITCH). */
export const FLAT_PITCH = 0.6;
/** The most (m) a released foot is lifted while it catches up with its raw position (footlock.py RELEASE_LIFT). */
export const RELEASE_LIFT = 0.08;
export const STEEP_PITCH = 1.0;


type V3 = [number, number, number];
type Pair = [number, number];

const sub = (a: V3, b: V3): V3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a: V3, b: V3): V3 => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a: V3, s: number): V3 => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a: V3, b: V3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const norm = (a: V3): number => Math.sqrt(dot(a, a));
const cross = (a: V3, b: V3): V3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

export function smoothstep(t: number): number {
  t = Math.min(Math.max(t, 0), 1);
  return t * t * (3 - 2 * t);
}

/**
 * Knee and ankle with |knee − hip| = l1 and |ankle − knee| = l2, the ankle at `target` or, out of reach, as
 * close as the leg allows along the hip–target line; the knee bends towards the raw knee's offset from that
 * line plus poleBias × `forward` (footlock.py two_bone_ik).
 */
export function twoBoneIK(hip: V3, knee: V3, target: V3, l1: number, l2: number, reach: number, forward: V3 | null, poleBias: number): [V3, V3] {
  const dVec = sub(target, hip);
  let d = norm(dVec);
  const u: V3 = d > 1e-9 ? scale(dVec, 1 / d) : [0, -1, 0];
  d = Math.min(Math.max(d, Math.abs(l1 - l2) + 1e-6), reach * (l1 + l2));
  const pole = forward ? add(sub(knee, hip), scale(forward, poleBias)) : sub(knee, hip);
  let bend = sub(pole, scale(u, dot(pole, u)));
  let n = norm(bend);
  if (n < 1e-9) {
    // raw leg straight: bend forward (+z of the hip–target line's frame)
    bend = cross(u, [1, 0, 0]);
    n = norm(bend);
    if (n < 1e-9) {
      bend = [0, 0, 1];
      n = 1;
    }
  }
  bend = scale(bend, 1 / n);
  const a = (l1 * l1 - l2 * l2 + d * d) / (2 * d);
  const r = Math.sqrt(Math.max(l1 * l1 - a * a, 0));
  return [add(add(hip, scale(u, a)), scale(bend, r)), add(hip, scale(u, d))];
}

/**
 * The ankle target when the foot pivots about its locked toe (a heel lift) because the target is beyond
 * `reach` from the hip; null when it is reachable as it is or when even pivoting cannot reach
 * (footlock.py pivot_foot).
 */
function pivotFoot(hip: V3, ankleTarget: V3, toeTarget: V3, reach: number): V3 | null {
  if (norm(sub(ankleTarget, hip)) <= reach) return null;
  const r = norm(sub(toeTarget, ankleTarget));
  const dVec = sub(toeTarget, hip);
  const d = norm(dVec);
  if (d >= reach + r || d <= Math.abs(reach - r) || d < 1e-9) return null;
  const u = scale(dVec, 1 / d);
  const a = (reach * reach - r * r + d * d) / (2 * d);
  const rho = Math.sqrt(Math.max(reach * reach - a * a, 0));
  const centre = add(hip, scale(u, a));
  const rel = sub(ankleTarget, centre);
  const off = sub(rel, scale(u, dot(rel, u)));
  const n = norm(off);
  if (n < 1e-9) return null;
  return add(centre, scale(off, rho / n));
}

/** Heading (radians, 0 = +z, positive towards +x) of a foot's ankle-to-toe vector on the ground (footlock.py foot_heading). */
export function footHeading(toeFromAnkle: V3): number {
  return Math.atan2(toeFromAnkle[0], toeFromAnkle[2]);
}

/** How much of a planted foot's heading is held: 1 up to FLAT_PITCH, smoothly 0 at STEEP_PITCH (footlock.py flatness). */
export function flatness(toeFromAnkle: V3): number {
  const pitch = Math.atan2(-toeFromAnkle[1], Math.hypot(toeFromAnkle[0], toeFromAnkle[2]));
  return 1 - smoothstep((pitch - FLAT_PITCH) / (STEEP_PITCH - FLAT_PITCH));
}

/** a in [−π, π) (footlock.py wrap_angle). */
export function wrapAngle(a: number): number {
  const t = (a + Math.PI) % (2 * Math.PI);
  return (t < 0 ? t + 2 * Math.PI : t) - Math.PI;
}

/** `v` with `angle` added to its heading, turned about the vertical (footlock.py turn_about_y). */
function turnAboutY(v: V3, angle: number): V3 {
  const c = Math.cos(angle), s = Math.sin(angle);
  return [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]];
}

interface FootState {
  /** Locked toe (x, z), or null. */
  anchor: [number, number] | null;
  /** Toe height when the contact started. */
  startY: number;
  /** Where the locked toe was drawn in the last planted frame, or null. */
  locked: V3 | null;
  /** Frames since the contact started (0 = not planted). */
  planted: number;
  /** Frames left of the blend-out. */
  release: number;
  /** Held headings (radians) of the foot (ankle → toe) and the toes (toe → toe tip), from the contact's start. */
  heading: Pair;
  /** The same in the last planted frame, or null before any contact. */
  lockedHeading: Pair | null;
}

/** Streaming foot lock: `step` once per frame, in order; `reset` before a new motion. */
export class FootLock {
  readonly settings: FootLockSettings;
  private readonly joints: number;
  /** Per leg: joint indices (hip, knee, ankle, toe, toe end) and bone lengths (thigh, shin). */
  private readonly legs: { index: number[]; l1: number; l2: number }[];
  private feet: FootState[] = [];

  /**
   * `joints`: the skeleton's joint names (the canonical or the dance set's legs, legs.ts); `offsets`: joints × 3
   * rest offsets (metres), whose lengths give thigh and shin.
   */
  constructor(joints: readonly string[], offsets: ArrayLike<number>, settings: Partial<FootLockSettings> = {}) {
    this.settings = { ...FOOT_LOCK_DEFAULTS, ...settings };
    const { blendIn, blendOut, reach } = this.settings;
    if (!Number.isInteger(blendIn) || blendIn < 0 || !Number.isInteger(blendOut) || blendOut < 1) {
      throw new RangeError(`footLock: blendIn must be an integer ≥ 0 and blendOut ≥ 1, got ${blendIn} and ${blendOut}`);
    }
    if (!(reach > 0 && reach <= 1)) throw new RangeError(`footLock: reach must be in (0, 1], got ${reach}`);
    if (offsets.length !== joints.length * 3) throw new Error(`footLock: ${offsets.length} offset values for ${joints.length} joints`);
    this.joints = joints.length;
    const length = (j: number) => Math.hypot(offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2]);
    this.legs = findLegs(joints, 'footLock').map((leg) => ({ index: [leg.hip, leg.knee, leg.ankle, leg.toe, leg.toeEnd], l1: length(leg.knee), l2: length(leg.ankle) }));
    this.reset();
  }

  reset(): void {
    this.feet = [0, 1].map(() => ({ anchor: null, startY: 0, locked: null, planted: 0, release: 0, heading: [0, 0], lockedHeading: null }));
  }

  /**
   * One frame: world positions `pose` (joints × 3) and contact bits (left, right; non-zero = planted) →
   * cleaned positions in `out` (may be `pose` itself). Only knees, ankles, toes and toe ends change.
   */
  step(pose: ArrayLike<number>, contacts: ArrayLike<number>, out: Float32Array | Float64Array = new Float64Array(this.joints * 3)): Float32Array | Float64Array {
    const n = this.joints * 3;
    if (pose.length !== n || out.length !== n) throw new Error(`footLock.step: expected ${n} position values, got ${pose.length} in and ${out.length} out`);
    if (out !== pose) for (let k = 0; k < n; k++) out[k] = pose[k];
    const at = (j: number): V3 => [pose[j * 3], pose[j * 3 + 1], pose[j * 3 + 2]];
    const put = (j: number, p: V3) => {
      out[j * 3] = p[0];
      out[j * 3 + 1] = p[1];
      out[j * 3 + 2] = p[2];
    };
    const { groundHeight, blendIn, blendOut, reach, poleBias } = this.settings;
    for (let side = 0; side < 2; side++) {
      const foot = this.feet[side];
      const { index, l1, l2 } = this.legs[side];
      const [hipJ, kneeJ, ankleJ, toeJ, endJ] = index;
      const rawToe = at(toeJ), rawAnkle = at(ankleJ), hip = at(hipJ);
      const rawToeFromAnkle = sub(rawToe, rawAnkle);
      // the foot and the toes (none on a skeleton whose feet end at the toe)
      const rawParts: [V3, V3] = [rawToeFromAnkle, endJ >= 0 ? sub(at(endJ), rawToe) : [0, 0, 0]];
      const rawHeading: Pair = [footHeading(rawParts[0]), footHeading(rawParts[1])];
      const flat: Pair = [flatness(rawParts[0]), flatness(rawParts[1])];
      const planted = contacts[side] > 0;
      let target: V3;
      let heading: Pair;
      if (planted) {
        if (foot.planted === 0) {
          // contact starts where the foot is drawn now: no jump
          const start = this.drawnToe(foot, rawToe);
          foot.anchor = [start[0], start[2]];
          foot.startY = start[1];
          foot.heading = this.drawnHeading(foot, rawHeading, flat);
        }
        const w = blendIn > 0 ? smoothstep(foot.planted / blendIn) : 1;
        foot.planted++;
        target = [foot.anchor![0], (1 - w) * foot.startY + w * groundHeight, foot.anchor![1]];
        heading = [0, 1].map((k) => rawHeading[k] + flat[k] * wrapAngle(foot.heading[k] - rawHeading[k])) as Pair;
      } else {
        foot.planted = 0;
        if (foot.release <= 0) continue; // free foot: raw pose
        target = this.drawnToe(foot, rawToe);
        heading = this.drawnHeading(foot, rawHeading, flat);
        foot.release--;
      }
      const toeFromAnkle = turnAboutY(rawParts[0], heading[0] - rawHeading[0]);
      const endFromToe = turnAboutY(rawParts[1], heading[1] - rawHeading[1]);
      let ankleTarget = sub(target, toeFromAnkle);
      const pivoted = pivotFoot(hip, ankleTarget, target, reach * (l1 + l2));
      if (pivoted) ankleTarget = pivoted;
      // the knee follows the raw foot: a steep foot's heading is noise
      const level: V3 = [rawToeFromAnkle[0], 0, rawToeFromAnkle[2]];
      const forward = scale(level, 1 / Math.max(norm(level), 1e-9));
      const [newKnee, newAnkle] = twoBoneIK(hip, at(kneeJ), ankleTarget, l1, l2, reach, forward, poleBias);
      let newToe: V3;
      if (!pivoted) {
        // the foot moves rigidly with the ankle
        newToe = add(newAnkle, toeFromAnkle);
        if (endJ >= 0) put(endJ, add(newToe, endFromToe));
      } else {
        // the foot turns about the toe (heel lifts); the toes stay as they are
        if (endJ >= 0) put(endJ, add(target, endFromToe));
        newToe = target;
      }
      put(toeJ, newToe);
      put(kneeJ, newKnee);
      put(ankleJ, newAnkle);
      if (planted) {
        if (norm(sub(newAnkle, ankleTarget)) > 1e-6) foot.anchor = [newToe[0], newToe[2]]; // out of reach: the anchor follows the body
        foot.locked = newToe;
        foot.lockedHeading = foot.heading;
        foot.release = blendOut;
      }
    }
    return out;
  }

  /** The foot's and toes' headings this frame if nothing new happens: the raw ones, or during a release the blend from the last locked ones (the toe's weight times each part's flatness, the shorter way round). */
  private drawnHeading(foot: FootState, rawHeading: Pair, flat: Pair): Pair {
    const locked = foot.lockedHeading;
    if (foot.release <= 0 || locked === null) return rawHeading;
    const w = smoothstep(foot.release / this.settings.blendOut);
    return [0, 1].map((k) => rawHeading[k] + w * flat[k] * wrapAngle(locked[k] - rawHeading[k])) as Pair;
  }

  /** Where the toe is drawn this frame if nothing new happens: the raw toe, or during a release the blend from the last locked position (with a lift, footlock.py _drawn_toe). */
  private drawnToe(foot: FootState, rawToe: V3): V3 {
    if (foot.release <= 0 || !foot.locked) return rawToe;
    const w = smoothstep(foot.release / this.settings.blendOut);
    // A foot catching up with its raw position steps over the floor rather than dragging along it: a lift of half
    // the horizontal gap (at most RELEASE_LIFT), zero at both ends of the blend.
    const gap = Math.hypot(foot.locked[0] - rawToe[0], foot.locked[2] - rawToe[2]);
    const arc = 4 * w * (1 - w) * Math.min(0.5 * gap, RELEASE_LIFT);
    return [w * foot.locked[0] + (1 - w) * rawToe[0], w * foot.locked[1] + (1 - w) * rawToe[1] + arc, w * foot.locked[2] + (1 - w) * rawToe[2]];
  }
}

/**
 * The foot lock over a whole motion: positions (frames × joints × 3) and contacts (frames × 2) → new
 * positions (float32, like a Motion's).
 */
export function footLock(
  positions: Float32Array | Float64Array,
  contacts: ArrayLike<number>,
  joints: readonly string[],
  offsets: ArrayLike<number>,
  settings: Partial<FootLockSettings> = {},
): Float32Array {
  const n = joints.length * 3;
  const frames = positions.length / n;
  if (!Number.isInteger(frames)) throw new Error(`footLock: ${positions.length} position values is not a whole number of ${joints.length}-joint frames`);
  if (contacts.length !== frames * 2) throw new Error(`footLock: ${contacts.length} contact values for ${frames} frames (expected ${frames * 2})`);
  const lock = new FootLock(joints, offsets, settings);
  const out = new Float32Array(positions.length);
  const pose = new Float64Array(n);
  for (let f = 0; f < frames; f++) {
    lock.step(positions.subarray(f * n, (f + 1) * n), [contacts[f * 2], contacts[f * 2 + 1]], pose);
    out.set(pose, f * n);
  }
  return out;
}

/**
 * Contacts labelled on the shown motion (contactLabels.ts: the model's bit with the foot's height and speed),
 * then the lock on those labels, frame by frame: what every locomotion mode shows.
 */
export class PlantedFeet {
  private readonly labeller: ContactLabeller;
  private readonly lock: FootLock;

  constructor(joints: readonly string[], offsets: ArrayLike<number>, fps: number, settings: Partial<FootLockSettings> = {}) {
    this.labeller = new ContactLabeller(joints, fps);
    this.lock = new FootLock(joints, offsets, settings);
  }

  reset(): void {
    this.labeller.reset();
    this.lock.reset();
  }

  /** One frame: `pose` (joints × 3, world) and the model's bits → the labels in `labels` and the locked pose in `out` (may be `pose`). */
  step(pose: Float32Array | Float64Array, bits: ArrayLike<number>, labels: Uint8Array, out: Float32Array | Float64Array = pose): void {
    this.labeller.step(pose, bits, labels);
    this.lock.step(pose, labels, out);
  }
}

/**
 * PlantedFeet over a whole motion: positions (frames × joints × 3) and the model's bits (frames × 2) → the
 * locked positions (float32) and the labels they were locked with.
 */
export function plantFeet(
  positions: Float32Array | Float64Array,
  bits: ArrayLike<number>,
  joints: readonly string[],
  offsets: ArrayLike<number>,
  fps: number,
  settings: Partial<FootLockSettings> = {},
): { positions: Float32Array; contacts: Uint8Array } {
  const contacts = labelContacts(positions, bits, joints, fps);
  return { positions: footLock(positions, contacts, joints, offsets, settings), contacts };
}
