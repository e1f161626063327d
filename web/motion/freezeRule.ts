// The fair freeze rule of the dance reports (training/aclstm/freeze_rule.py), for judging what the page gives
// (scripts/evaluate-dance.mjs): a second is low when its pose change (poseChange.ts) is below 20% of the style's real
// median; a run passes when (a) its share of low seconds is at most twice the real clips' share, (b) no low stretch
// lasts 5 s or more, and (c) its median is at least half the real median. Jitter, reported beside every verdict: the
// mean |second difference| of the joints relative to the root, in cm per frame² (freeze_rule.jitter_cm).
// Parity with Python: tests/fixtures/measures_parity.json (tests/unit/measuresParity.test.ts).

import { percentile } from './contacts';

export const FREEZE_RULE = { lowFraction: 0.2, shareFactor: 2, longestLowS: 5, medianFraction: 0.5 } as const;

/** A style's real held-out clips, as docs/models/aclstm.json stores them (real_reference). */
export interface RealDanceReference {
  /** Median per-second pose change (m/s). */
  median: number;
  /** Share of the real seconds that are low. */
  low_share: number;
}

export interface FreezeVerdict {
  lowShare: number;
  longestLowS: number;
  medianRatio: number;
  a: boolean;
  b: boolean;
  c: boolean;
  passes: boolean;
}

/** One run's per-second pose change against its style's real reference: the three measures and the verdicts. */
export function judgeFreeze(seconds: readonly number[], ref: RealDanceReference): FreezeVerdict {
  const low = seconds.map((v) => v < FREEZE_RULE.lowFraction * ref.median);
  let longest = 0;
  for (let k = 0, run = 0; k < low.length; k++) longest = Math.max(longest, (run = low[k] ? run + 1 : 0));
  const lowShare = low.filter(Boolean).length / low.length;
  const medianRatio = percentile(seconds, 50) / ref.median; // numpy's median: an even count takes the middle two's mean
  const a = lowShare <= FREEZE_RULE.shareFactor * ref.low_share;
  const b = longest < FREEZE_RULE.longestLowS;
  const c = medianRatio >= FREEZE_RULE.medianFraction;
  return { lowShare, longestLowS: longest, medianRatio, a, b, c, passes: a && b && c };
}

/** Mean |second difference| of the joints relative to the root (cm per frame²) of frames × joints × 3 positions (m). */
export function jitterCm(positions: ArrayLike<number>, joints: number): number {
  const stride = joints * 3;
  const frames = Math.floor(positions.length / stride);
  const local = (f: number, j: number, a: number) => positions[f * stride + j * 3 + a] - positions[f * stride + a];
  let sum = 0;
  let count = 0;
  for (let f = 2; f < frames; f++) {
    for (let j = 0; j < joints; j++) {
      let sq = 0;
      for (let a = 0; a < 3; a++) {
        const d = local(f, j, a) - 2 * local(f - 1, j, a) + local(f - 2, j, a);
        sq += d * d;
      }
      sum += Math.sqrt(sq);
      count++;
    }
  }
  return count ? (100 * sum) / count : NaN;
}

/**
 * The raised-foot check of the dance reports (training/aclstm/raised_foot.py): the share of frames in which the
 * higher ankle (`lFoot`, `rFoot`) is more than `metres` above the frame's lowest point. A dancer on one leg waving
 * the other passes the freeze rule; real clips hold a foot that high in 0.2% (salsa) to 14.5% (Indian) of frames, and
 * a run is judged at most `margin` (a share) above its style's.
 */
export const RAISED_FOOT = { metres: 0.3, margin: 0.15, ankles: ['lFoot', 'rFoot'] } as const;

/** Share of frames of frames × joints × 3 positions (m, y up) with the higher ankle above RAISED_FOOT.metres. */
export function raisedFootShare(positions: ArrayLike<number>, joints: readonly string[]): number {
  const [left, right] = RAISED_FOOT.ankles.map((name) => joints.indexOf(name));
  if (left < 0 || right < 0) throw new Error(`raisedFootShare: no ${left < 0 ? RAISED_FOOT.ankles[0] : RAISED_FOOT.ankles[1]} joint`);
  const J = joints.length;
  const frames = Math.floor(positions.length / (J * 3));
  const height = (f: number, j: number) => positions[(f * J + j) * 3 + 1];
  let raised = 0;
  for (let f = 0; f < frames; f++) {
    let lowest = Infinity;
    for (let j = 0; j < J; j++) lowest = Math.min(lowest, height(f, j));
    if (Math.max(height(f, left), height(f, right)) - lowest > RAISED_FOOT.metres) raised++;
  }
  return raised / frames;
}
