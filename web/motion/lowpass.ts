// Zero-phase Butterworth low-pass of joint positions: the baseline clean-up motion-capture users know
// (scipy.signal.butter + sosfiltfilt). Filters are kept as second-order sections (biquads) because a
// cascade of biquads stays numerically stable where one high-order polynomial would not.
import type { Motion } from './types';

/** One biquad, normalised so a0 = 1: y = b0 x + b1 x₋₁ + b2 x₋₂ − a1 y₋₁ − a2 y₋₂. */
export interface Biquad {
  b0: number;
  b1: number;
  b2: number;
  a1: number;
  a2: number;
}

/**
 * Digital Butterworth low-pass of order 2 (one biquad) or 4 (two), by the bilinear transform with the
 * cutoff pre-warped so the response is exactly 1/√2 at `cutoffHz` (the same filter as scipy's butter).
 */
export function butterworthLowpass(cutoffHz: number, fps: number, order = 2): Biquad[] {
  if (!(Number.isFinite(fps) && fps > 0)) throw new Error(`lowpass: fps must be a positive number, got ${fps}`);
  if (!(Number.isFinite(cutoffHz) && cutoffHz > 0 && cutoffHz < fps / 2)) {
    throw new Error(`lowpass: cutoff must be above 0 and below the Nyquist frequency ${fps / 2} Hz, got ${cutoffHz}`);
  }
  if (order !== 2 && order !== 4) throw new Error(`lowpass: order must be 2 or 4, got ${order}`);
  // Pre-warping: the analogue cutoff that the bilinear transform maps onto cutoffHz.
  const k = Math.tan((Math.PI * cutoffHz) / fps);
  const sections: Biquad[] = [];
  for (let i = 0; i < order / 2; i++) {
    // Each conjugate pair of Butterworth poles sits at angle (2i+1)π/(2N) from the negative real axis;
    // the section's damping 1/Q is twice that angle's cosine.
    const invQ = 2 * Math.cos(((2 * i + 1) * Math.PI) / (2 * order));
    const norm = 1 / (1 + k * invQ + k * k);
    const b0 = k * k * norm;
    sections.push({ b0, b1: 2 * b0, b2: b0, a1: 2 * (k * k - 1) * norm, a2: (1 - k * invQ + k * k) * norm });
  }
  return sections;
}

/**
 * One causal pass through the cascade (transposed direct form II, as scipy's sosfilt). `zi` holds two
 * state values per section; zero state when omitted.
 */
export function sosfilt(signal: ArrayLike<number>, sections: Biquad[], zi?: Float64Array): Float64Array {
  const out = Float64Array.from(signal);
  sections.forEach((s, i) => {
    let z0 = zi ? zi[2 * i] : 0;
    let z1 = zi ? zi[2 * i + 1] : 0;
    for (let n = 0; n < out.length; n++) {
      const x = out[n];
      const y = s.b0 * x + z0;
      z0 = s.b1 * x - s.a1 * y + z1;
      z1 = s.b2 * x - s.a2 * y;
      out[n] = y;
    }
  });
  return out;
}

/**
 * The state of each section after a long unit step (scipy's sosfilt_zi): scaled by the first sample,
 * the filter starts as if the signal had always been there, so it has no start transient.
 */
export function sosfiltZi(sections: Biquad[]): Float64Array {
  const zi = new Float64Array(2 * sections.length);
  let scale = 1; // the steady input reaching this section: the DC gains of the sections before it
  sections.forEach((s, i) => {
    const gain = (s.b0 + s.b1 + s.b2) / (1 + s.a1 + s.a2);
    // Steady state of the transposed direct form II with input `scale` and output gain × scale.
    const z1 = (s.b2 - s.a2 * gain) * scale;
    zi[2 * i] = (s.b1 - s.a1 * gain) * scale + z1;
    zi[2 * i + 1] = z1;
    scale *= gain;
  });
  return zi;
}

/**
 * Zero-phase filtering of one channel: forward, then backward, so the phase cancels and the magnitude
 * response is squared. Like scipy's sosfiltfilt (padtype 'odd'): the ends are extended by point
 * reflection, 3 × (2·sections + 1) samples or at most length − 1, and each pass starts from the step
 * state, so a constant comes back unchanged. Signals of 3 samples or fewer come back unchanged.
 */
export function filtfilt(signal: Float64Array, sections: Biquad[]): Float64Array {
  const n = signal.length;
  if (n <= 3 || sections.length === 0) return Float64Array.from(signal);
  const pad = Math.min(3 * (2 * sections.length + 1), n - 1);
  // Odd extension: 2·x[0] − x[pad..1] before, 2·x[n−1] − x[n−2..n−1−pad] after; it continues the
  // slope through each end, which a lowpass disturbs far less than a jump would.
  const ext = new Float64Array(n + 2 * pad);
  for (let i = 0; i < pad; i++) {
    ext[i] = 2 * signal[0] - signal[pad - i];
    ext[n + pad + i] = 2 * signal[n - 1] - signal[n - 2 - i];
  }
  ext.set(signal, pad);
  const zi = sosfiltZi(sections);
  const forward = sosfilt(ext, sections, zi.map((z) => z * ext[0]));
  const reversed = forward.reverse();
  const backward = sosfilt(reversed, sections, zi.map((z) => z * reversed[0])).reverse();
  return backward.slice(pad, pad + n);
}

export interface LowpassOptions {
  /** Cutoff frequency in Hz, default 6 (a common choice for human movement). */
  cutoffHz?: number;
  /** Butterworth order, 2 or 4, default 2. */
  order?: number;
}

/**
 * Every joint's x, y and z filtered over time with a zero-phase Butterworth low-pass. Returns a new
 * Motion (same joints, parents, fps, frames; contacts copied); the input is untouched.
 */
export function lowpassMotion(motion: Motion, { cutoffHz = 6, order = 2 }: LowpassOptions = {}): Motion {
  const out = lowpassRows(motion.positions, motion.joints.length * 3, motion.fps, { cutoffHz, order });
  const result: Motion = { fps: motion.fps, frames: motion.frames, joints: [...motion.joints], parents: [...motion.parents], positions: out };
  if (motion.contacts) result.contacts = motion.contacts.slice();
  return result;
}

/** Each of the `width` columns of frames × width `values` (at `fps`) filtered over time, zero-phase; a new array. */
export function lowpassRows(values: ArrayLike<number>, width: number, fps: number, { cutoffHz = 6, order = 2 }: LowpassOptions = {}): Float32Array {
  const sections = butterworthLowpass(cutoffHz, fps, order);
  const F = values.length / width;
  const out = new Float32Array(values.length);
  const channel = new Float64Array(F);
  for (let c = 0; c < width; c++) {
    for (let f = 0; f < F; f++) channel[f] = values[f * width + c];
    const filtered = filtfilt(channel, sections);
    for (let f = 0; f < F; f++) out[f * width + c] = filtered[f];
  }
  return out;
}
