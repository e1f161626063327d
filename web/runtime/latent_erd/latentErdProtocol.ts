// Messages between LatentErdClient (main thread) and latentErd.worker.ts. Every request carries an id; the
// worker answers each with exactly one WorkerReply carrying the same id (see protocol.ts). Besides the
// requests every model worker serves (init, generate, startStream / pull / restart, benchmark, parity) it
// serves the latent ERD's control requests: followPath, controlStart / controlPull (Steer mode) and
// simulateControl.
import type { Gait } from '../../optimizer/pathFollower';
import type { FittedModelInit, FollowPathRequest, FollowPathStatsReply } from '../worker/protocol';

export interface LatentStreamParams {
  /** Picks the seed state: seed mod the number of seeds (of the gait's category when `gait` is given). */
  seed: number;
  /** Seeds of this category only ("walk" or "run"). */
  gait?: Gait;
  /**
   * Per-frame control, frames × 3 flattened ([forward m/s, sideways m/s, turn rad/s] each). Left out: the
   * smooth random control randomControl(seed, …) of web/motion/control.ts, for as long as the stream runs.
   */
  control?: ArrayLike<number>;
  /**
   * Whether the look-ahead sees the control's next steps (default true) or guesses the current step's
   * control repeated (streaming.py run_stream known_future=False: the parity fixture's stream).
   */
  knownFuture?: boolean;
  /** Lock planted feet (default true). */
  footLock?: boolean;
}

export interface LatentGenerateParams extends LatentStreamParams {
  frames: number;
}

/** The ERD step's inputs, flattened: z (B×latent), control (B×control_dim), h and c (layers×B×hidden). */
export interface LatentStepInputs {
  batch: number;
  z: ArrayLike<number>;
  control: ArrayLike<number>;
  h: ArrayLike<number>;
  c: ArrayLike<number>;
}

export interface LatentStepOutputs {
  z_next: Float32Array;
  h_out: Float32Array;
  c_out: Float32Array;
}

/** Parity inputs: an ERD step, and/or one decoder call on `steps` physical latent steps (batch 1). */
export interface LatentParityInputs {
  step?: LatentStepInputs;
  decode?: { latent: ArrayLike<number>; steps: number };
}

export interface LatentParityResult {
  step?: LatentStepOutputs;
  /** The decoder's normalised rows, 4 × (steps − 2 × radius) × rows.dim. */
  decode?: Float32Array;
}

export interface LatentSeedInfo {
  name: string;
  category: string;
}

export interface LatentErdInitResult extends FittedModelInit {
  pooling: number;
  radius: number;
  lookahead: number;
  seeds: LatentSeedInfo[];
  controlRange?: Record<'forward' | 'sideways' | 'turn', [number, number]>;
}

export interface LatentStreamInfo {
  seedIndex: number;
  seedName: string;
}

/** A run of emitted frames. */
export interface LatentChunk {
  frames: number;
  /** frames × rows.dim physical rows (positions in the root facing frame, control, contacts). */
  rows: Float32Array;
  /** frames × joints × 3: the decoded points in the world, bone lengths as predicted. */
  predicted: Float32Array;
  /** frames × joints × 3: fitted to the skeleton (exact bone lengths), then foot-locked unless footLock is false. */
  positions: Float32Array;
  /** frames × 2: decoded contact channel > 0.5. */
  contacts: Uint8Array;
  /** frames × 3: x, z, heading of each frame's root (the root the decoded control channels move). */
  roots: Float64Array;
  /** Heading per frame (rad, wrapped to [−π, π)). */
  rootHeading: Float32Array;
  /** frames × 3: the control each frame was emitted for. */
  control: Float32Array;
  seedIndex: number;
  /** Index of this chunk's first frame in its stream (0 for `generate`). */
  startFrame: number;
  /** ERD step calls (each step and its look-ahead) and decoder calls made for these frames. */
  erdCalls: number;
  decodeCalls: number;
  /** Milliseconds the chunk took. */
  computeMs: number;
}

export interface LatentFollowPathParams extends FollowPathRequest {
  /** Forward speed asked for (m/s); default 1.2 for walk, 2.8 for run. */
  speed?: number;
}

export interface LatentFollowPathChunk extends LatentChunk {
  /** As the generator's: windows are latent steps, particleSteps ERD step calls. */
  stats: FollowPathStatsReply;
  /** The path as followed (resampled, and smoothed for strokes): x, z pairs. */
  path: Float32Array;
}

export interface LatentControlStartParams {
  seed: number;
  gait: Gait;
}

export interface LatentControlTarget {
  speed: number;
  heading: number;
}

export interface LatentControlChunk extends LatentChunk {
  /** Per frame: achieved speed (m/s, the root's mean over the last half second) and facing heading (rad, (−π, π]). */
  speed: Float32Array;
  heading: Float32Array;
}

export interface LatentSimulateControlParams {
  seconds: number;
  schedule: { t: number; speed: number; heading: number }[];
  seed: number;
  gait?: Gait;
  footLock?: boolean;
}

export interface LatentSimulatedControlChunk extends LatentControlChunk {
  targetSpeed: Float32Array;
  targetHeading: Float32Array;
  /** Per frame: its latent step's compute time divided by the step's frames (ms per frame). */
  computeMsPerFrame: Float32Array;
  /** Per latent step: milliseconds and frames. */
  batchMs: Float32Array;
  batchFrames: Uint8Array;
}
