// A style generator's switch from one style to another without a pop (issue 39): the style input's weights move
// from the old style (a one-hot, or wherever an unfinished switch had got to) to the new one-hot over
// STYLE_SWITCH_FRAMES frames, one step per frame, through convex blends (the step's embedding is style @ E, so a
// blend of one-hots blends the styles' embeddings: docs/models/style-generator.md "Export"). Pure: the generator's
// core and its live controller ask it for the weights of each stream frame.

/** Frames a style switch takes: one second at the generator's 30 fps. */
export const STYLE_SWITCH_FRAMES = 30;

/**
 * The share of the new style at step `k` (0-based) of an `n`-step switch: a smoothstep of (k + 1) / n, so it rises
 * monotonically, gently at both ends, and step n − 1 is the new style alone.
 */
export function rampShare(k: number, n: number): number {
  if (!Number.isInteger(n) || n < 1) throw new RangeError(`a style switch needs at least 1 frame, got ${n}`);
  const a = Math.min(Math.max((k + 1) / n, 0), 1);
  return a * a * (3 - 2 * a);
}

/** The convex blend (1 − s)·from + s·to, renormalised so its float32 weights sum to 1. */
export function blendWeights(from: ArrayLike<number>, to: ArrayLike<number>, s: number): Float32Array {
  if (from.length !== to.length) throw new Error(`style weights of different lengths: ${from.length} and ${to.length}`);
  const out = new Float32Array(from.length);
  let sum = 0;
  for (let i = 0; i < out.length; i++) {
    out[i] = Math.max(0, (1 - s) * from[i] + s * to[i]);
    sum += out[i];
  }
  for (let i = 0; i < out.length; i++) out[i] /= sum;
  return out;
}

/**
 * One stream's style weights per stream frame: constant until a switch, then a ramp over `frames` frames from the
 * weights in force at the switch's first frame to the new ones, then the new ones.
 */
export class StyleRamp {
  private from: Float32Array;
  private to: Float32Array;
  /** The stream frame the current ramp starts at, and its length (0: no ramp, `to` throughout). */
  private start = 0;
  private frames = 0;

  constructor(weights: ArrayLike<number>) {
    this.from = Float32Array.from(weights);
    this.to = Float32Array.from(weights);
  }

  /** The weights for stream frame `frame`. */
  at(frame: number): Float32Array {
    if (this.frames === 0 || frame >= this.start + this.frames - 1) return this.to.slice();
    if (frame < this.start) return this.from.slice();
    return blendWeights(this.from, this.to, rampShare(frame - this.start, this.frames));
  }

  /** The weights the ramp ends at (the style switched to). */
  get target(): Float32Array {
    return this.to.slice();
  }

  /**
   * Switches to `weights` from stream frame `frame` on, over `frames` frames (1: at once), starting from the weights
   * that frame would have had: a switch during a switch carries on from wherever the blend had got to.
   */
  switchTo(weights: ArrayLike<number>, frame: number, frames = STYLE_SWITCH_FRAMES): void {
    if (weights.length !== this.to.length) throw new Error(`a style switch needs ${this.to.length} weights, got ${weights.length}`);
    if (!Number.isInteger(frames) || frames < 1) throw new RangeError(`a style switch needs at least 1 frame, got ${frames}`);
    this.from = this.at(frame);
    this.to = Float32Array.from(weights);
    this.start = frame;
    this.frames = frames;
  }
}
