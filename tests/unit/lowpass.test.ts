import { describe, expect, it } from 'vitest';
import { butterworthLowpass, filtfilt, lowpassMotion, sosfilt, type Biquad } from '../../web/motion/lowpass';
import type { Motion } from '../../web/motion/types';

const FPS = 30;
const sine = (hz: number, n: number, phaseFrame = 0) =>
  Float64Array.from({ length: n }, (_, f) => Math.cos((2 * Math.PI * hz * (f - phaseFrame)) / FPS));

/** Amplitude of the `hz` component of x[from..to) by projection (to − from spanning whole periods). */
function amplitude(x: Float64Array, hz: number, from: number, to: number): number {
  let s = 0, c = 0;
  for (let f = from; f < to; f++) {
    s += x[f] * Math.sin((2 * Math.PI * hz * f) / FPS);
    c += x[f] * Math.cos((2 * Math.PI * hz * f) / FPS);
  }
  return (2 / (to - from)) * Math.hypot(s, c);
}

/** Product of the sections' numerators and denominators: the whole transfer function's polynomials. */
function polynomials(sections: Biquad[]): { b: number[]; a: number[] } {
  const mul = (p: number[], q: number[]) => {
    const r = new Array(p.length + q.length - 1).fill(0);
    p.forEach((x, i) => q.forEach((y, j) => (r[i + j] += x * y)));
    return r;
  };
  return sections.reduce((acc, s) => ({ b: mul(acc.b, [s.b0, s.b1, s.b2]), a: mul(acc.a, [1, s.a1, s.a2]) }), { b: [1], a: [1] });
}

/** A tiny deterministic LCG in [-1, 1), so the test does not depend on the noise module. */
function lcg(seed: number) {
  let s = seed >>> 0;
  return () => ((s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 2 ** 31) - 1;
}

describe('butterworthLowpass', () => {
  it("matches scipy.signal.butter's published coefficients (Wn = 0.2, orders 2 and 4)", () => {
    // butter(2, 0.2) and butter(4, 0.2): cutoff 0.1 × the sample rate.
    const two = polynomials(butterworthLowpass(3, 30, 2));
    [0.06745527, 0.13491055, 0.06745527].forEach((v, i) => expect(two.b[i]).toBeCloseTo(v, 8));
    [1, -1.1429805, 0.4128016].forEach((v, i) => expect(two.a[i]).toBeCloseTo(v, 7));
    const four = polynomials(butterworthLowpass(3, 30, 4));
    [0.00482434, 0.01929737, 0.02894606, 0.01929737, 0.00482434].forEach((v, i) => expect(four.b[i]).toBeCloseTo(v, 8));
    [1, -2.36951301, 2.31398841, -1.05466541, 0.18737949].forEach((v, i) => expect(four.a[i]).toBeCloseTo(v, 8));
  });

  it('rejects a cutoff outside (0, fps/2) and unsupported orders', () => {
    expect(() => butterworthLowpass(0, 30)).toThrow(/cutoff/);
    expect(() => butterworthLowpass(-1, 30)).toThrow(/cutoff/);
    expect(() => butterworthLowpass(15, 30)).toThrow(/Nyquist/);
    expect(() => butterworthLowpass(NaN, 30)).toThrow(/cutoff/);
    expect(() => butterworthLowpass(4, 30, 3)).toThrow(/order must be 2 or 4, got 3/);
    expect(() => butterworthLowpass(4, 0)).toThrow(/fps/);
  });

  it('has magnitude 1/√2 at the cutoff for a single pass (steady state)', () => {
    for (const order of [2, 4]) {
      const out = sosfilt(sine(4, 600), butterworthLowpass(4, FPS, order));
      // The last 300 frames are 40 whole periods of 4 Hz at 30 fps, long after the start transient.
      expect(amplitude(out, 4, 300, 600)).toBeCloseTo(Math.SQRT1_2, 2);
      expect(Math.abs(amplitude(out, 4, 300, 600) / Math.SQRT1_2 - 1)).toBeLessThan(0.02);
    }
  });
});

describe('filtfilt', () => {
  const sections = butterworthLowpass(4, FPS, 2);

  it('leaves a constant unchanged, with no start transient', () => {
    for (const order of [2, 4]) {
      const out = filtfilt(new Float64Array(50).fill(1.7), butterworthLowpass(4, FPS, order));
      out.forEach((v) => expect(Math.abs(v - 1.7)).toBeLessThan(1e-9));
    }
  });

  it('passes 1 Hz nearly unchanged and without phase shift, and stops 12 Hz (cutoff 4 Hz)', () => {
    const slow = filtfilt(sine(1, 300, 45), sections);
    // Frames 60..240 are 6 whole periods of 1 Hz, away from the ends.
    expect(Math.abs(amplitude(slow, 1, 60, 240) - 1)).toBeLessThan(0.02);
    const window = Array.from(slow.subarray(60, 90));
    expect(60 + window.indexOf(Math.max(...window))).toBe(75); // the input peaks at 45 + 30k
    const fast = filtfilt(sine(12, 300), sections);
    expect(amplitude(fast, 12, 50, 250)).toBeLessThan(0.05);
  });

  it('is linear', () => {
    const r = lcg(3);
    const x = Float64Array.from({ length: 40 }, r);
    const y = Float64Array.from({ length: 40 }, r);
    const combined = filtfilt(x.map((v, i) => 2 * v - 0.5 * y[i]), sections);
    const fx = filtfilt(x, sections), fy = filtfilt(y, sections);
    combined.forEach((v, i) => expect(v).toBeCloseTo(2 * fx[i] - 0.5 * fy[i], 12));
  });

  it('keeps a symmetric pulse symmetric about its centre (zero phase)', () => {
    // Long enough that the response has died out at both ends, where forward and backward passes differ.
    const pulse = new Float64Array(201);
    for (let i = 97; i <= 103; i++) pulse[i] = 1 - Math.abs(i - 100) / 4;
    const out = filtfilt(pulse, butterworthLowpass(4, FPS, 4));
    for (let d = 1; d <= 30; d++) expect(out[100 - d]).toBeCloseTo(out[100 + d], 12);
    expect(out.indexOf(Math.max(...out))).toBe(100);
  });

  it('returns signals of 1..3 samples unchanged and handles short ones (pad capped at length − 1)', () => {
    for (const x of [[0.5], [1, 2], [1, 5, 2]]) expect(Array.from(filtfilt(Float64Array.from(x), sections))).toEqual(x);
    const short = filtfilt(Float64Array.from([1, 2, 3, 2, 1]), sections);
    expect(short.length).toBe(5);
    short.forEach((v) => expect(Number.isFinite(v)).toBe(true));
  });
});

describe('lowpassMotion', () => {
  function jitteredMotion(): Motion {
    const frames = 120, joints = ['Hips', 'Spine', 'Head'];
    const r = lcg(11);
    const positions = new Float32Array(frames * joints.length * 3);
    for (let f = 0; f < frames; f++) {
      for (let j = 0; j < joints.length; j++) {
        const i = (f * joints.length + j) * 3;
        positions[i] = 0.02 * f + 0.01 * r();
        positions[i + 1] = 0.9 + 0.3 * j + 0.05 * Math.sin(f / 5) + 0.01 * r();
        positions[i + 2] = 0.1 * Math.cos(f / 9) + 0.01 * r();
      }
    }
    return { fps: FPS, frames, joints, parents: [-1, 0, 1], positions, contacts: new Uint8Array(frames * 2).fill(1) };
  }

  /** Sum of squared third differences over every coordinate: jerk up to a constant factor. */
  function jerk(m: Motion): number {
    const stride = m.joints.length * 3;
    let sum = 0;
    for (let f = 3; f < m.frames; f++) {
      for (let c = 0; c < stride; c++) {
        const p = (k: number) => m.positions[(f - k) * stride + c];
        sum += (p(0) - 3 * p(1) + 3 * p(2) - p(3)) ** 2;
      }
    }
    return sum;
  }

  it('keeps joints, parents, fps, frames and contacts, reduces jerk, and leaves the input untouched', () => {
    const m = jitteredMotion();
    const before = m.positions.slice();
    const out = lowpassMotion(m);
    expect(out.joints).toEqual(m.joints);
    expect(out.parents).toEqual(m.parents);
    expect(out.fps).toBe(m.fps);
    expect(out.frames).toBe(m.frames);
    expect(out.positions.length).toBe(m.positions.length);
    expect(out.contacts).toEqual(m.contacts);
    expect(out.contacts).not.toBe(m.contacts);
    expect(jerk(out)).toBeLessThan(0.05 * jerk(m));
    expect(m.positions).toEqual(before);
    expect(lowpassMotion(m, { cutoffHz: 3, order: 4 }).frames).toBe(m.frames);
  });

  it('returns no contacts when the input has none, and rejects a bad cutoff', () => {
    const { contacts: _, ...m } = jitteredMotion();
    expect(lowpassMotion(m).contacts).toBeUndefined();
    expect(() => lowpassMotion(m, { cutoffHz: 20 })).toThrow(/cutoff/);
  });
});
