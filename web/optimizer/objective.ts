// Objective terms shared by the path follower and live control (Wang, Chai, Xia eqs. 16–19, 22–23):
// the contact term needs the feet, so it runs forward kinematics on each particle's frames.
import { decodeFeatures, type RootStart } from '../model/featureDecode';
import type { GeneratorInfo } from '../model/generatorInfo';
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
