// Parity of the rules that exist on both sides: foot contacts (web/motion/contacts.ts vs
// training/mocap/contacts.py), foot skating (web/motion/footSkating.ts vs training/metrics.py foot_skating)
// per-second pose change (web/motion/poseChange.ts vs training/metrics.py pose_change_per_second), and the dance
// reports' freeze rule and jitter (web/motion/freezeRule.ts vs training/aclstm/freeze_rule.py judge, jitter_cm).
// tests/fixtures/measures_parity.json (python -m training.fixtures.measures) holds real clips as the
// Python loader gives them plus synthetic threshold cases, and what the Python rules make of them.
// Positions are stored as whole multiples of 1/8192 m, exact in float32, so the Float32Array the page would
// hold has exactly the values Python computed on; two cases put heights or speeds exactly on a threshold and
// are computed in float64 on both sides. So contacts must agree on every frame (no tolerance; every stored
// real case is at least 1e-5 m or m/s from any threshold) and the measures to 1e-9 m/s (float64 rounding
// differences only, far below any reported digit).
import { describe, expect, it } from 'vitest';
import { CONTACT_THRESHOLDS, detectContacts } from '../../web/motion/contacts';
import { footSkating, skatingSample } from '../../web/motion/footSkating';
import { FREEZE_RULE, jitterCm, judgeFreeze, RAISED_FOOT, raisedFootShare, type RealDanceReference } from '../../web/motion/freezeRule';
import { PoseChangeMeter, poseChangePerSecond } from '../../web/motion/poseChange';
import type { Motion } from '../../web/motion/types';
import { readRepoFile } from './corpus';

const MEASURE_TOLERANCE = 1e-9; // m/s

interface Clip {
  name: string;
  source: string;
  fps: number;
  frames: number;
  joints: string[];
  /** frames × joints × 3: metres × scale as whole numbers, or metres (float64) where there is no scale. */
  positions: number[];
  scale?: number;
}
interface ContactCase extends Clip {
  contacts: number[];
  /** Smallest |value − threshold| over the frames' height and speed comparisons (m or m/s). */
  closest_margin: number;
  skating: number | null;
  skating_pairs: number;
}
interface SkatingCase extends Clip {
  contacts: number[];
  skating: number | null;
  skating_pairs: number;
}
interface PoseChangeCase extends Clip {
  per_second: number[];
  jitter_cm: number;
  /** Where the clip has both ankles (lFoot, rFoot). */
  raised_foot_share?: number;
}
interface FreezeCase {
  name: string;
  seconds: number[];
  reference: RealDanceReference;
  verdict: { low_share: number; longest_low_s: number; median_ratio: number; pass_a: boolean; pass_b: boolean; pass_c: boolean; passes: boolean };
}
interface Fixture {
  contact_thresholds: Record<string, number>;
  contacts: ContactCase[];
  skating: SkatingCase[];
  skating_pooled: { cases: string[]; skating: number; pairs: number };
  pose_change: PoseChangeCase[];
  freeze_rule: {
    constants: { low_fraction: number; share_factor: number; longest_low_s: number; median_fraction: number; raised_foot_m: number; raised_margin: number };
    cases: FreezeCase[];
  };
}

const fixture = JSON.parse(readRepoFile('tests/fixtures/measures_parity.json')) as Fixture;

/** The positions as the page holds them (Float32Array, exact for scaled cases), or float64 for the exact-threshold cases. */
function positionsOf(c: Clip): Float32Array {
  expect(c.positions.length).toBe(c.frames * c.joints.length * 3);
  if (c.scale) return Float32Array.from(c.positions, (k) => k / c.scale!);
  return Float64Array.from(c.positions) as unknown as Float32Array; // the rules only index the array
}

function motionOf(c: Clip, contacts?: number[]): Motion & { contacts?: Uint8Array } {
  return {
    fps: c.fps,
    frames: c.frames,
    joints: c.joints,
    parents: c.joints.map((_, j) => j - 1),
    positions: positionsOf(c),
    ...(contacts ? { contacts: Uint8Array.from(contacts) } : {}),
  };
}

describe('foot contacts: web/motion/contacts.ts = training/mocap/contacts.py', () => {
  it('uses the same thresholds', () => {
    const py = fixture.contact_thresholds;
    const T = CONTACT_THRESHOLDS;
    expect({
      ankle_on: T.ankleOnHeight, toe_on: T.toeOnHeight, speed_on: T.onSpeed,
      ankle_off: T.ankleOffHeight, toe_off: T.toeOffHeight, speed_off: T.offSpeed, floor_percentile: T.floorPercentile,
    }).toEqual(py);
  });

  for (const c of fixture.contacts) {
    it(`${c.name}: every frame's bits agree (${c.frames} frames, ${c.fps} fps)`, () => {
      // No tolerance: a stored (scaled) case keeps every height and speed at least 1e-9 from a threshold, and
      // the two exact-threshold cases compute the same float64 operations on both sides.
      if (c.scale) expect(c.closest_margin).toBeGreaterThan(1e-9);
      const got = detectContacts(motionOf(c));
      expect(got).toBeDefined();
      const mismatched: string[] = [];
      for (let i = 0; i < c.frames * 2; i++) {
        if (got![i] !== c.contacts[i]) mismatched.push(`frame ${i >> 1} ${i & 1 ? 'right' : 'left'}`);
      }
      expect(mismatched).toEqual([]);
    });
  }

  it('the real clips have planted and lifted frames on both feet', () => {
    for (const c of fixture.contacts.filter((x) => x.source.startsWith('cmu/'))) {
      for (let side = 0; side < 2; side++) {
        const bits = c.contacts.filter((_, i) => i % 2 === side);
        const share = bits.reduce((a, b) => a + b, 0) / bits.length;
        expect(share, `${c.name} side ${side}`).toBeGreaterThan(0.05);
        expect(share, `${c.name} side ${side}`).toBeLessThan(1);
      }
    }
  });
});

describe('foot skating: web/motion/footSkating.ts = training/metrics.py foot_skating', () => {
  const cases: SkatingCase[] = [...fixture.contacts, ...fixture.skating];
  for (const c of cases) {
    it(`${c.name}: ${c.skating === null ? 'no planted pairs (NaN)' : `${c.skating.toFixed(4)} m/s over ${c.skating_pairs} planted pairs`}`, () => {
      const m = motionOf(c, c.contacts) as Motion & { contacts: Uint8Array };
      expect(skatingSample(m).count).toBe(c.skating_pairs);
      const value = footSkating(m);
      if (c.skating === null) expect(value).toBeNaN();
      else expect(Math.abs(value - c.skating)).toBeLessThan(MEASURE_TOLERANCE);
    });
  }

  it('pooled over separate clips (metrics.foot_skating_clips) equals the summed samples', () => {
    const p = fixture.skating_pooled;
    let sum = 0, count = 0;
    for (const name of p.cases) {
      const c = cases.find((x) => x.name === name)!;
      const s = skatingSample(motionOf(c, c.contacts) as Motion & { contacts: Uint8Array });
      sum += s.sum;
      count += s.count;
    }
    expect(count).toBe(p.pairs);
    expect(Math.abs(sum / count - p.skating)).toBeLessThan(MEASURE_TOLERANCE);
  });
});

describe('per-second pose change: web/motion/poseChange.ts = training/metrics.py pose_change_per_second', () => {
  for (const c of fixture.pose_change) {
    it(`${c.name}: ${c.per_second.length} whole seconds from ${c.frames} frames at ${c.fps} fps`, () => {
      const positions = positionsOf(c);
      const J = c.joints.length;
      const whole = poseChangePerSecond(positions, J, c.fps);
      expect(whole).toHaveLength(c.per_second.length);
      whole.forEach((v, k) => expect(Math.abs(v - c.per_second[k]), `second ${k}`).toBeLessThan(MEASURE_TOLERANCE));
      // The page streams frames in chunks (Dance mode): the same seconds.
      const meter = new PoseChangeMeter(J, c.fps);
      const streamed: number[] = [];
      for (let f = 0; f < c.frames; f += 7) streamed.push(...meter.push(positions.subarray(f * J * 3, Math.min(f + 7, c.frames) * J * 3)));
      expect(streamed).toEqual(whole);
    });
  }
});

describe('the dance freeze rule and jitter: web/motion/freezeRule.ts = training/aclstm/freeze_rule.py', () => {
  it('uses the same constants', () => {
    const py = fixture.freeze_rule.constants;
    expect({
      low_fraction: FREEZE_RULE.lowFraction, share_factor: FREEZE_RULE.shareFactor, longest_low_s: FREEZE_RULE.longestLowS, median_fraction: FREEZE_RULE.medianFraction,
      raised_foot_m: RAISED_FOOT.metres, raised_margin: RAISED_FOOT.margin,
    }).toEqual(py);
  });
  for (const c of fixture.freeze_rule.cases) {
    it(`judges: ${c.name}`, () => {
      const v = judgeFreeze(c.seconds, c.reference);
      expect({ a: v.a, b: v.b, c: v.c, passes: v.passes, longest: v.longestLowS }).toEqual({
        a: c.verdict.pass_a, b: c.verdict.pass_b, c: c.verdict.pass_c, passes: c.verdict.passes, longest: c.verdict.longest_low_s,
      });
      expect(Math.abs(v.lowShare - c.verdict.low_share)).toBeLessThan(1e-12);
      expect(Math.abs(v.medianRatio - c.verdict.median_ratio)).toBeLessThan(1e-12);
    });
  }
  for (const c of fixture.pose_change) {
    it(`jitter of ${c.name}`, () => {
      expect(Math.abs(jitterCm(positionsOf(c), c.joints.length) - c.jitter_cm)).toBeLessThan(1e-9);
    });
  }
  const withAnkles = fixture.pose_change.filter((c) => c.raised_foot_share !== undefined);
  it('has raised-foot cases: a real dance clip and one strictly between never and always', () => {
    expect(withAnkles.length).toBeGreaterThanOrEqual(2);
    expect(withAnkles.some((c) => c.raised_foot_share! > 0 && c.raised_foot_share! < 1)).toBe(true);
  });
  for (const c of withAnkles) {
    it(`raised-foot share of ${c.name}`, () => {
      expect(raisedFootShare(positionsOf(c), c.joints)).toBe(c.raised_foot_share);
    });
  }
});
