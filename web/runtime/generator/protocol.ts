// Messages between GeneratorClient (main thread) and generator.worker.ts, beyond those every model worker
// shares (worker/protocol.ts).
import type { StepOutputs } from '../../model/generatorInfo';
import type { FollowPathRequest, FollowPathStatsReply, ModelInit, WorkerReply } from '../worker/protocol';

export interface GenerateParams {
  frames: number;
  /** PRNG seed (used as an unsigned 32-bit integer). */
  seed: number;
  /** Sampling temperature τ ≥ 0: 0 = always the heaviest component's mean, 1 = the trained distribution. */
  temperature: number;
  /** Which seed state of generator.json to start from; default seed mod the number of seed states. */
  seedIndex?: number;
  /** Also run the refiner (loaded on first use) behind the generator: chunks then carry `refined` too. */
  refine?: boolean;
  /** A style generator's style (one of InitResult.styles; default the first); refused by a generator without styles. */
  style?: string;
}

export type StreamParams = Omit<GenerateParams, 'frames'>;

export interface InitResult extends ModelInit {
  dim: number;
  seeds: string[];
  /** The real held-out clips' foot sliding (lowest foot point, m/s) a user's pack measured on its card; absent for shipped models. */
  heldOutSliding?: number;
  /** A style generator's real held-out foot sliding per style (m/s), where its JSON gives it. */
  heldOutSlidingByStyle?: Record<string, number>;
  /** A style generator's style names (the first is the default) and its licence; absent for a generator without styles. */
  styles?: string[];
  licence?: string;
}

/** A decoded run of generated frames. */
export interface GeneratedChunk {
  frames: number;
  /** frames × D, physical units (see generator.json features.layout). */
  features: Float32Array;
  /** frames × joints × 3, world metres. */
  positions: Float32Array;
  /** frames × 2 (left, right), 1 = planted. */
  contacts: Uint8Array;
  /** Heading per frame, radians, unwrapped. */
  rootHeading: Float32Array;
  seedIndex: number;
  /** Index of this chunk's first frame in its stream (0 for `generate`). */
  startFrame: number;
  /** With `refine`: the same frames through the refiner and the foot lock. */
  refined?: RefinedFrames;
}

/** The refiner's version of a chunk's frames (refinerCore.ts). */
export interface RefinedFrames {
  /** frames × D refined features, physical units (contacts as the refiner outputs them, not snapped). */
  features: Float32Array;
  /** frames × joints × 3, world metres: the refined frames decoded (from their own root channels), then foot-locked. */
  positions: Float32Array;
  /** frames × 2, 1 = planted: refined contact above refiner.json contact_threshold. */
  contacts: Uint8Array;
  rootHeading: Float32Array;
}

/** The refiner's ONNX inputs for `frames` frames per stream, flattened: x (B×T×D), ends (B×T×3E), ends_prev (B×3E), h and c (1×B×H). */
export interface RefinerStepInputs {
  batch: number;
  frames: number;
  x: ArrayLike<number>;
  ends: ArrayLike<number>;
  ends_prev: ArrayLike<number>;
  h: ArrayLike<number>;
  c: ArrayLike<number>;
}

export interface RefinerStepOutputs {
  x_refined: Float32Array;
  h_out: Float32Array;
  c_out: Float32Array;
}

/** Generator worker only (`refinerParity`): one raw refiner step and, for given physical frames, their end effectors. */
export interface RefinerParityResult {
  outputs: RefinerStepOutputs;
  /** frames × 3E root-frame end-effector positions of `frames`, when given. */
  ends?: Float32Array;
}

export interface StreamInfo {
  seedIndex: number;
  seedName: string;
  /** A style generator's stream: its style. */
  style?: string;
}

/** The generator worker's replies (the same shape as every model worker's). */
export type GeneratorReply = WorkerReply;

export interface ParityResult {
  inputs: { batch: number; x: Float32Array; h: Float32Array; c: Float32Array; style?: Float32Array };
  outputs: StepOutputs;
}

/** Generator worker only: follow a ground path (web/optimizer/pathFollower.ts). */
export interface FollowPathParams extends FollowPathRequest {
  /** σ_fit (m) of the path-fit term; default 0.1. */
  fitSigma?: number;
  /** A style generator's style (default its first). */
  style?: string;
}

export interface FollowPathChunk extends GeneratedChunk {
  stats: FollowPathStatsReply;
  /** The path as followed (resampled, and smoothed for strokes): x, z pairs. */
  path: Float32Array;
}

/** Generator worker only: live control (web/optimizer/liveControl.ts). */
export interface ControlStartParams {
  seed: number;
  gait: 'walk' | 'run';
  /** A style generator's style (default its first). */
  style?: string;
}

export interface ControlTargetParams {
  speed: number;
  heading: number;
  /** Particles per round for this batch (default 24): fewer is cheaper and steers less precisely. */
  particles?: number;
}

export interface ControlChunkReply extends GeneratedChunk {
  /** Per frame: achieved speed (m/s, mean over the last half second) and facing heading (rad). */
  speed: Float32Array;
  heading: Float32Array;
  /** Milliseconds the batch took to optimise. */
  computeMs: number;
}

export interface SimulateControlParams {
  /** As FollowPathParams.footLock (default true). */
  footLock?: boolean;
  seconds: number;
  schedule: { t: number; speed: number; heading: number }[];
  seed: number;
  gait?: 'walk' | 'run';
  /** A style generator's style (default its first). */
  style?: string;
}

export interface SimulatedControlChunk extends GeneratedChunk {
  speed: Float32Array;
  heading: Float32Array;
  /** Per frame: the target in force. */
  targetSpeed: Float32Array;
  targetHeading: Float32Array;
  /** Per frame: its batch's optimisation time divided by the batch's frames (ms per model frame). */
  computeMs: Float32Array;
  /** Per optimised batch: milliseconds and frames. */
  batchMs: Float32Array;
  batchFrames: Uint8Array;
}
