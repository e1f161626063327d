// Messages between DanceClient (main thread) and dance.worker.ts. Every request carries an id; the
// worker answers each with exactly one WorkerReply carrying the same id (see protocol.ts).
import type { BenchmarkResult, FittedModelInit } from '../worker/protocol';

export type { BenchmarkResult };

export interface DanceStreamParams {
  /** One of the model's styles ("salsa", "indian", "martial"). */
  style: string;
  /** Picks the seed motion: seed mod the number of seed motions of the style (an integer ≥ 0). */
  seed: number;
}

export interface DanceGenerateParams extends DanceStreamParams {
  frames: number;
}

/** The ONNX call's inputs, flattened: x (B×D), style (B×S), h and c (layers×B×H), and the steps to run (default 1). */
export interface DanceStepInputs {
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
}

/** A run of generated frames. */
export interface DanceChunk {
  frames: number;
  /** frames × D features in physical units (the network's denormalised outputs). */
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
  outputs: DanceStepOutputs;
}
