// Messages between DanceClient (main thread) and dance.worker.ts. Every request carries an id; the
// worker answers each with exactly one WorkerReply carrying the same id (see protocol.ts).
import type { BenchmarkResult, FittedModelInit } from '../worker/protocol';

export type { BenchmarkResult };

export interface DanceStreamParams {
  /** One of the model's styles ("salsa", "indian", "martial"). */
  style: string;
  /**
   * Picks the seed motion: seed mod the number of seed motions of the style (an integer ≥ 0). A sampled (mdn) model
   * also seeds its stream's random numbers with it: the same style and seed give the same dance.
   */
  seed: number;
}

export interface DanceGenerateParams extends DanceStreamParams {
  frames: number;
}

/**
 * The ONNX call's inputs, flattened: x (B×D), style (B×S), h and c (layers×B×H), and the steps to run (default 1); a
 * sampled (mdn) model's call also needs the sampler's (DanceMdnFeeds' fields, as numbers).
 */
export interface DanceStepInputs extends Partial<Record<keyof DanceMdnFeeds, ArrayLike<number>>> {
  batch: number;
  steps?: number;
  x: ArrayLike<number>;
  style: ArrayLike<number>;
  h: ArrayLike<number>;
  c: ArrayLike<number>;
}

export interface DanceStepOutputs {
  /** steps × B × D: each step's output frame (normalised), the last one the next input. */
  ys: Float32Array;
  h_out: Float32Array;
  c_out: Float32Array;
}

/** A sampled (mdn) model's inputs besides x, style, h, c and steps (issue 42's interface; B rows, D features). */
export interface DanceMdnFeeds {
  /** B: the held component, −1 = none yet (drawn at the next step). */
  held: BigInt64Array;
  /** B: frames the held component has been held. */
  age: BigInt64Array;
  /** B × D: the AR(1) normals' state. */
  wander: Float32Array;
  /** B each: the phrase rule's settings of each row's style. */
  temperature: Float32Array;
  rho: Float32Array;
  threshold: Float32Array;
  max_hold: BigInt64Array;
  min_hold: BigInt64Array;
  /** steps × B in [0, 1): a component draw's uniform, one per step and row. */
  uniforms: Float32Array;
  /** steps × B × D standard normals: the AR(1) innovations. */
  normals: Float32Array;
  /** B × 4 × D: the output filter's x[t−1], x[t−2], y[t−1], y[t−2] (normalised). */
  filt: Float32Array;
  /** B × 3 and B × 2: the biquad's b₀ b₁ b₂ and a₁ a₂. */
  filter_b: Float32Array;
  filter_a: Float32Array;
}

export interface DanceMdnStepOutputs extends DanceStepOutputs {
  /** steps × B × D: ys through the causal low-pass, what the page draws (never fed back). */
  display: Float32Array;
  held_out: BigInt64Array;
  age_out: BigInt64Array;
  wander_out: Float32Array;
  filt_out: Float32Array;
  /** steps × B × K: the mixture weights of each step. */
  weights: Float32Array;
}

export interface DanceSeedInfo {
  style: string;
  name: string;
}

export interface DanceInitResult extends FittedModelInit {
  styles: string[];
  /** Every seed motion, in file order (`seed` counts within one style's). */
  seeds: DanceSeedInfo[];
  /** Median per-second pose change of real dance, per style (m/s). */
  realPoseChange: Record<string, number>;
  trainingScheme: string;
  /** True for a sampled (mdn) model: the seed also seeds its random draws, so every seed is its own dance. */
  sampled: boolean;
}

/** A run of generated frames. */
export interface DanceChunk {
  frames: number;
  /** frames × D features in physical units (the network's denormalised outputs; a sampled model's filtered `display`). */
  features: Float32Array;
  /** frames × joints × 3: the decoded network points, bone lengths as predicted. */
  predicted: Float32Array;
  /** frames × joints × 3: the points fitted to the skeleton (exact bone lengths), planted feet locked. */
  positions: Float32Array;
  /** frames × 2 (left, right): the foot contacts the feet were locked with (labelled from their heights and speeds). */
  contacts: Uint8Array;
  /** Index into the model's seeds of the seed motion. */
  seedIndex: number;
  /** Index of this chunk's first frame in its stream (0 for `generate`). */
  startFrame: number;
}

export interface DanceStreamInfo {
  style: string;
  seedIndex: number;
  seedName: string;
}

export interface DanceParityResult {
  /** A sampled (mdn) model's call gives DanceMdnStepOutputs. */
  outputs: DanceStepOutputs | DanceMdnStepOutputs;
}
