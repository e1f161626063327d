// Moving per-frame values between frame rates by linear interpolation in time (quaternions by normalised linear
// interpolation along the shorter arc: frames are close enough for that to equal slerp to well under a degree).

/** The number of frames a clip of `frames` at `from` fps has at `to` fps, over the same duration. */
export function resampledFrames(frames: number, from: number, to: number): number {
  return Math.max(1, Math.floor(((frames - 1) * to) / from + 1e-9) + 1);
}

/** Values (frames × width) sampled at `from` fps, at the times of `count` frames at `to` fps (clamped at the end). */
export function resampleLinear(values: ArrayLike<number>, width: number, from: number, to: number, count: number): Float32Array {
  const frames = values.length / width;
  const out = new Float32Array(count * width);
  for (let f = 0; f < count; f++) {
    const t = Math.min((f * from) / to, frames - 1);
    const a = Math.floor(t), b = Math.min(a + 1, frames - 1), u = t - a;
    for (let i = 0; i < width; i++) out[f * width + i] = values[a * width + i] * (1 - u) + values[b * width + i] * u;
  }
  return out;
}

/** Quaternions (frames × n × 4) resampled as resampleLinear does, each kept on the shorter arc and normalised. */
export function resampleQuaternions(values: ArrayLike<number>, n: number, from: number, to: number, count: number): Float32Array {
  const frames = values.length / (n * 4);
  const out = new Float32Array(count * n * 4);
  for (let f = 0; f < count; f++) {
    const t = Math.min((f * from) / to, frames - 1);
    const a = Math.floor(t), b = Math.min(a + 1, frames - 1), u = t - a;
    for (let j = 0; j < n; j++) {
      const pa = (a * n + j) * 4, pb = (b * n + j) * 4;
      const sign = values[pa] * values[pb] + values[pa + 1] * values[pb + 1] + values[pa + 2] * values[pb + 2] + values[pa + 3] * values[pb + 3] < 0 ? -1 : 1;
      let norm = 0;
      for (let i = 0; i < 4; i++) {
        const v = values[pa + i] * (1 - u) + sign * values[pb + i] * u;
        out[(f * n + j) * 4 + i] = v;
        norm += v * v;
      }
      norm = Math.sqrt(norm) || 1;
      for (let i = 0; i < 4; i++) out[(f * n + j) * 4 + i] /= norm;
    }
  }
  return out;
}

/** Bits (frames × width) at the times of `count` frames at `to` fps: the nearest frame's. */
export function resampleNearest(values: Uint8Array, width: number, from: number, to: number, count: number): Uint8Array {
  const frames = values.length / width;
  const out = new Uint8Array(count * width);
  for (let f = 0; f < count; f++) {
    const src = Math.min(Math.round((f * from) / to), frames - 1);
    out.set(values.subarray(src * width, (src + 1) * width), f * width);
  }
  return out;
}

/**
 * Values (frames × width) at `from` fps brought down to `count` frames at `to` fps (to < from), each value a robust
 * mean of the input frames within half an output frame of its time (per value; see below): jitter is averaged over
 * the frames that would be dropped, and a glitch in one of them is ignored. Returns the values and how many frames a
 * window covers.
 */
export function resampleRobust(values: ArrayLike<number>, width: number, from: number, to: number, count: number): { values: Float32Array; window: number } {
  if (to >= from) return { values: resampleLinear(values, width, from, to, count), window: 1 };
  const frames = values.length / width;
  const ratio = from / to;
  const radius = Math.floor(ratio / 2);
  const out = new Float32Array(count * width);
  const window = new Float64Array(2 * radius + 1);
  for (let f = 0; f < count; f++) {
    const centre = Math.min(Math.round(f * ratio), frames - 1);
    const lo = Math.max(0, centre - radius), hi = Math.min(frames - 1, centre + radius);
    for (let i = 0; i < width; i++) {
      const w = window.subarray(0, hi - lo + 1);
      for (let g = lo; g <= hi; g++) w[g - lo] = values[g * width + i];
      w.sort();
      // The mean of the window without its lowest and highest value (the median of 3 or fewer): a glitch in one frame
      // is dropped, and the rest are averaged.
      let sum = 0;
      const drop = w.length >= 5 ? 1 : 0;
      for (let g = drop; g < w.length - drop; g++) sum += w[g];
      out[f * width + i] = w.length >= 5 ? sum / (w.length - 2) : w[Math.floor(w.length / 2)];
    }
  }
  return { values: out, window: 2 * radius + 1 };
}
