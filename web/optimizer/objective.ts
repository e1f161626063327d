// Objective terms shared by the path follower and live control (Wang, Chai, Xia eqs. 16–19, 22–23):
// the contact term needs the feet, so it runs forward kinematics on each particle's frames.
import { decodeFeatures, type RootStart } from '../model/featureDecode';
import type { GeneratorInfo } from '../model/generatorInfo';
import { findLegs, footPoints } from '../motion/legs';
import type { RolloutResult } from './rollout';

/** Eq. (18)'s σ_con for the path follower: a planted toe moving 1 cm in a frame (0.3 m/s) costs 1. */
export const CONTACT_SIGMA = 0.01;

/** Indices of the toe joints the contact bits describe (left, right). */
export function toeJoints(info: GeneratorInfo): [number, number] {
  const left = info.skeleton.joints.indexOf('LeftToeBase');
  const right = info.skeleton.joints.indexOf('RightToeBase');
  if (left < 0 || right < 0) throw new Error('the generator skeleton has no LeftToeBase / RightToeBase joints for the contact term');
  return [left, right];
}

/** Particle b's frames (T×D) out of a rollout. */
export function particleFeatures(r: RolloutResult, b: number, frames = r.T): Float32Array {
  const D = r.features.length / (r.P * r.T);
  return r.features.subarray(b * r.T * D, (b * r.T + frames) * D);
}

/**
 * Contact term (eq. 18), horizontal part: Σ over frames where a foot is planted in this frame and the
 * previous one of |Δ toe (x, z)|² / σ_con². `previous` (the toes at the end of what came before) links
 * the window to it; null starts fresh.
 */
export function contactCost(info: GeneratorInfo, features: Float32Array, start: RootStart, previous: ToeState | null, sigma = CONTACT_SIGMA, toes = toeJoints(info)): number {
  const decoded = decodeFeatures(info, features, start);
  const J = info.skeleton.joints.length;
  const D = info.onnx.dim;
  const frames = features.length / D;
  let cost = 0;
  for (let side = 0; side < 2; side++) {
    const j = toes[side];
    let px = previous?.x[side] ?? NaN, pz = previous?.z[side] ?? NaN, planted = previous?.planted[side] ?? false;
    for (let f = 0; f < frames; f++) {
      const x = decoded.positions[(f * J + j) * 3], z = decoded.positions[(f * J + j) * 3 + 2];
      const on = decoded.contacts[f * 2 + side] === 1;
      if (on && planted && Number.isFinite(px)) cost += ((x - px) ** 2 + (z - pz) ** 2) / (sigma * sigma);
      px = x;
      pz = z;
      planted = on;
    }
  }
  return cost;
}

/** Where the toes were at the end of the committed motion, for the next window's contact term. */
export interface ToeState {
  x: [number, number];
  z: [number, number];
  planted: [boolean, boolean];
}

export function lastToes(info: GeneratorInfo, positions: Float32Array, contacts: Uint8Array, toes = toeJoints(info)): ToeState | null {
  const J = info.skeleton.joints.length;
  const frames = contacts.length / 2;
  if (frames === 0) return null;
  const f = frames - 1;
  const at = (side: number, axis: number) => positions[(f * J + toes[side]) * 3 + axis];
  return {
    x: [at(0, 0), at(1, 0)],
    z: [at(0, 2), at(1, 2)],
    planted: [contacts[f * 2] === 1, contacts[f * 2 + 1] === 1],
  };
}

/** Heights (m) below which the low-foot term weighs a foot point's step fully, and from which not at all. */
const LOW_FOOT_FULL = 0.02;
const LOW_FOOT_NONE = 0.06;

/**
 * Low-foot term, the contact term by foot height instead of the model's bits (what lowFootSliding measures,
 * web/motion/footSkating.ts): per foot and frame pair, the foot's lowest point (ankle, toe or toe tip) in the
 * first frame costs |Δ (x, z)|² / σ², weighted 1 up to LOW_FOOT_FULL above the floor and smoothly 0 at
 * LOW_FOOT_NONE (higher of the two frames; a smooth weight, so no particle gains by lifting a foot just past
 * lowFootSliding's 4 cm). The bits miss a foot that skims the floor in its swing (toe tip 2–3 cm up at
 * 3 m/s): ranking by this term picks the particles that lift it, which the foot lock (it holds planted feet
 * only) cannot do afterwards.
 */
export function lowFootCost(info: GeneratorInfo, features: Float32Array, start: RootStart, sigma: number, previousPose: Float32Array | null = null): number {
  const P = decodeFeatures(info, features, start).positions;
  const J = info.skeleton.joints.length;
  const frames = features.length / info.onnx.dim;
  let cost = 0;
  for (const points of lowFootPoints(info)) {
    for (let f = previousPose ? 0 : 1; f < frames; f++) {
      // Frame f − 1 from `previousPose` (the last committed frame) links the window to what came before.
      const a = f > 0 ? P : previousPose!, aAt = f > 0 ? (f - 1) * J * 3 : 0, bAt = f * J * 3;
      let low = points[0];
      for (const j of points) if (a[aAt + j * 3 + 1] < a[aAt + low * 3 + 1]) low = j;
      const i = aAt + low * 3, k = bAt + low * 3;
      const h = Math.max(a[i + 1], P[k + 1]);
      if (h >= LOW_FOOT_NONE) continue;
      const t = Math.min(Math.max((h - LOW_FOOT_FULL) / (LOW_FOOT_NONE - LOW_FOOT_FULL), 0), 1);
      cost += ((1 - t * t * (3 - 2 * t)) * ((P[k] - a[i]) ** 2 + (P[k + 2] - a[i + 2]) ** 2)) / (sigma * sigma);
    }
  }
  return cost;
}

const footPointsOf = new WeakMap<GeneratorInfo, number[][]>();
/** Each foot's points (ankle, toe, toe tip) of the generator's skeleton, found once per model. */
function lowFootPoints(info: GeneratorInfo): number[][] {
  let feet = footPointsOf.get(info);
  if (!feet) footPointsOf.set(info, (feet = findLegs(info.skeleton.joints, 'the low-foot term').map(footPoints)));
  return feet;
}
