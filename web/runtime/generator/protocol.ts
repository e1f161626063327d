// Messages between GeneratorClient (main thread) and generator.worker.ts. Every request carries an id;
// the worker answers each with exactly one reply carrying the same id (WorkerReply, also used by the
// dance worker: danceProtocol.ts).
import type { StepOutputs } from '../../model/generatorInfo';

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
}

export type StreamParams = Omit<GenerateParams, 'frames'>;

/** The requests every model worker understands (ortWorker.ts serveModel); `P` is the model's stream parameters. */
export type ModelRequest<P, Inputs> =
  /** threads: onnxruntime-web wasm threads when cross-origin isolated (default 2; always 1 otherwise). */
  | { type: 'init'; modelUrl: string; infoUrl: string; threads?: number }
  | ({ type: 'generate'; frames: number } & P)
  | ({ type: 'startStream' } & P)
  | { type: 'pull'; frames: number }
  | { type: 'restart' }
  | { type: 'benchmark'; batch: number; steps: number }
  | { type: 'parity'; inputs?: Inputs };

export interface InitResult {
  ok: true;
  /** Threads onnxruntime-web runs with (by default 2 when the page is cross-origin isolated, else 1). */
  threads: number;
  /** Milliseconds to fetch and check the JSON and model and create the session. */
  loadMs: number;
  fps: number;
  joints: string[];
  parents: number[];
  dim: number;
  seeds: string[];
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
}

export interface BenchmarkResult {
  batch: number;
  steps: number;
  threads: number;
  /** Session calls per second. */
  stepsPerSecond: number;
  msPerCall: number;
  /** stepsPerSecond × batch: frames generated per second across the batch. */
  particleStepsPerSecond: number;
}

export interface ParityResult {
  inputs: { batch: number; x: Float32Array; h: Float32Array; c: Float32Array };
  outputs: StepOutputs;
}

/**
 * A worker's answer to one request (the same shape for every model worker). A cancelled request's error
 * reply has `name` "AbortError" (cancellation.ts).
 */
export type WorkerReply = { id: number; ok: true; result: unknown } | { id: number; ok: false; error: string; name?: string };
/**
 * Asks the worker to cancel request `request` (the id it was sent with); not itself answered. A queued
 * request is dropped without running and answered with an AbortError reply; a running one stops at its
 * next checkpoint (requestLoop.ts) and is answered so too, or, having none left, is answered as usual.
 */
export interface CancelMessage {
  type: 'cancel';
  request: number;
}
/** Sent any number of times before a long request's reply: the share done (0…1). */
export interface WorkerProgress {
  id: number;
  progress: number;
}
export type WorkerMessage = WorkerReply | WorkerProgress;
export type GeneratorReply = WorkerReply;

/** Id of replies that are about the worker as a whole (an uncaught error), not one request. */
export const WORKER_ERROR_ID = -1;

/** Generator worker only: follow a ground path (web/optimizer/pathFollower.ts). */
export interface FollowPathParams {
  /** [x, z] pairs, metres. */
  points: [number, number][];
  gait: 'walk' | 'run';
  seed: number;
  /** σ_fit (m) of the path-fit term; default 0.1. */
  fitSigma?: number;
  /** The points are a hand-drawn stroke: drop jitter and smooth before following. */
  stroke?: boolean;
  /** Clean planted feet with the foot lock (web/motion/footLock.ts; default true). The root is not moved. */
  footLock?: boolean;
}

export interface FollowPathStatsReply {
  meanError: number;
  maxError: number;
  arcProgress: number;
  optimizeMs: number;
  windows: number;
  particleSteps: number;
  /** Foot skating (m/s, planted toe speed by the contacts returned) of the returned motion and of the motion before the foot lock (by the model's bits). */
  skating: number;
  skatingBeforeLock: number;
  /** Foot sliding (m/s, the lowest foot point's speed within 4 cm of the floor; footSkating.ts lowFootSliding), the same two. */
  sliding: number;
  slidingBeforeLock: number;
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
