// Foot contact detection from joint positions (the Python training side uses the same rule).
//
// Per side, an ankle joint and a toe joint are found by name. For each, height h = y − (5th percentile
// of that joint's y over the clip) and speed v = |central-difference velocity| in m/s. A foot turns
// ON when (h_ankle < 0.05 and v_ankle < 0.5) or (h_toe < 0.04 and v_toe < 0.5), and turns OFF only
// when neither (h_ankle < 0.07 and v_ankle < 0.75) nor (h_toe < 0.06 and v_toe < 0.75) holds.
import { CANONICAL_JOINTS, mapHumanoid } from './humanoid';
import type { Motion } from './types';

export const CONTACT_THRESHOLDS = {
  /** Percentile of a joint's height over the clip taken as its floor level. */
  floorPercentile: 5,
  ankleOnHeight: 0.05,
  toeOnHeight: 0.04,
  onSpeed: 0.5,
  ankleOffHeight: 0.07,
  toeOffHeight: 0.06,
  offSpeed: 0.75,
} as const;

export interface FootJoints {
  ankle: number;
  toe: number;
}

const normalise = (name: string) => name.toLowerCase().replace(/^.*:/, '').replace(/[^a-z0-9]/g, '');

/**
 * Ankle and toe joint indices for one side, or undefined. Covers the CMU ASF bone-end names
 * (ankle = end of "ltibia", toe = end of "lfoot"), CMU BVH / canonical names (LeftFoot, LeftToeBase,
 * LeftToeBase_end), acLSTM-style lFoot / lFoot_end and common variants (LeftAnkle, LeftToe, mixamorig:…).
 */
export function findFootJoints(joints: string[], side: 'left' | 'right'): FootJoints | undefined {
  const index = new Map<string, number>();
  joints.forEach((name, j) => {
    const n = normalise(name);
    if (!index.has(n)) index.set(n, j);
  });
  const first = (names: string[]) => {
    for (const n of names) {
      const j = index.get(n);
      if (j !== undefined) return j;
    }
    return undefined;
  };
  const s = side === 'left' ? 'l' : 'r';
  // ASF names joints by the bone that ends there: the tibia ends at the ankle, the foot at the toe base.
  const asfAnkle = index.get(`${s}tibia`);
  const asfToe = first([`${s}foot`, `${s}toes`]);
  if (asfAnkle !== undefined && asfToe !== undefined) return { ankle: asfAnkle, toe: asfToe };

  const prefixes = side === 'left' ? ['left', 'l'] : ['right', 'r'];
  const names = (suffixes: string[]) => prefixes.flatMap((p) => suffixes.map((x) => p + x));
  const ankle = first(names(['foot', 'ankle']));
  const toe = first(names(['toebase', 'toe', 'toes', 'toebaseend', 'toeend', 'toesend', 'footend', 'ankleend']));
  return ankle !== undefined && toe !== undefined ? { ankle, toe } : undefined;
}

/** p-th percentile with linear interpolation between order statistics (numpy's default). */
export function percentile(values: ArrayLike<number>, p: number): number {
  const sorted = Float64Array.from(values).sort();
  if (sorted.length === 0) return NaN;
  const pos = (p / 100) * (sorted.length - 1);
  const lo = Math.floor(pos);
  const hi = Math.min(lo + 1, sorted.length - 1);
  return sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo);
}

/** Height above the clip's floor level and speed (m/s, central differences) of one joint per frame. */
function heightAndSpeed(motion: Motion, joint: number): { height: Float64Array; speed: Float64Array } {
  const { frames: F, positions: P, fps } = motion;
  const J = motion.joints.length;
  const at = (f: number, axis: number) => P[(f * J + joint) * 3 + axis];
  const y = new Float64Array(F);
  for (let f = 0; f < F; f++) y[f] = at(f, 1);
  const floor = percentile(y, CONTACT_THRESHOLDS.floorPercentile);
  const height = y.map((v) => v - floor);
  const speed = new Float64Array(F);
  for (let f = 0; f < F && F > 1; f++) {
    // One-sided differences at the ends, like numpy.gradient.
    const a = Math.max(f - 1, 0);
    const b = Math.min(f + 1, F - 1);
    const dt = (b - a) / fps;
    speed[f] = Math.hypot(at(b, 0) - at(a, 0), at(b, 1) - at(a, 1), at(b, 2) - at(a, 2)) / dt;
  }
  return { height, speed };
}

/**
 * Both feet's ankle and toe joints (left, right): by name (findFootJoints, the rule the Python side shares), else by
 * the humanoid mapper (humanoid.ts), which finds the feet of any humanoid skeleton whatever its names (a foot without
 * toe joints uses its ankle for both); undefined for a skeleton that is not a humanoid.
 */
export function footJointsOf(motion: Pick<Motion, 'joints' | 'parents' | 'frames' | 'positions'>): [FootJoints, FootJoints] | undefined {
  const named = [findFootJoints(motion.joints, 'left'), findFootJoints(motion.joints, 'right')];
  if (named[0] && named[1]) return named as [FootJoints, FootJoints];
  try {
    const { source } = mapHumanoid(motion);
    const foot = (side: 'Left' | 'Right'): FootJoints => {
      const ankle = source[CANONICAL_JOINTS.indexOf(`${side}Foot`)], toe = source[CANONICAL_JOINTS.indexOf(`${side}ToeBase`)];
      return { ankle, toe: toe >= 0 ? toe : ankle };
    };
    return [foot('Left'), foot('Right')];
  } catch {
    return undefined;
  }
}

/** Foot contacts, frames × 2 (left, right; 1 = planted), or undefined if the feet cannot be found. */
export function detectContacts(motion: Motion): Uint8Array | undefined {
  const sides = footJointsOf(motion) ?? [undefined, undefined];
  if (!sides[0] || !sides[1]) return undefined;
  const T = CONTACT_THRESHOLDS;
  const contacts = new Uint8Array(motion.frames * 2);
  sides.forEach((feet, side) => {
    const ankle = heightAndSpeed(motion, feet!.ankle);
    const toe = heightAndSpeed(motion, feet!.toe);
    let on = false;
    for (let f = 0; f < motion.frames; f++) {
      const ha = ankle.height[f], va = ankle.speed[f], ht = toe.height[f], vt = toe.speed[f];
      const turnOn = (ha < T.ankleOnHeight && va < T.onSpeed) || (ht < T.toeOnHeight && vt < T.onSpeed);
      const stayOn = (ha < T.ankleOffHeight && va < T.offSpeed) || (ht < T.toeOffHeight && vt < T.offSpeed);
      on = turnOn || (on && stayOn);
      contacts[f * 2 + side] = on ? 1 : 0;
    }
  });
  return contacts;
}
