// Messages between VaeLstmClient (main thread) and vaeLstm.worker.ts. Every request carries an id; the worker
// answers each with exactly one WorkerReply carrying the same id (see protocol.ts). The VAE-LSTM makes whole
// motions (generate, followPath), so it serves no stream: startStream answers with an error saying so.
import type { VaeLstmGraph } from '../../model/vaeLstmInfo';
import type { LatentFollowPathParams } from '../latent_erd/latentErdProtocol';
import type { FittedModelInit, FollowPathStatsReply } from '../worker/protocol';

export interface VaeLstmGenerateParams {
  frames: number;
  /** Picks z1 (Rng draws of N(0, 1)) and, without `control`, the random control. */
  seed: number;
  /** Per-frame control, ≥ frames × 3 flattened ([forward m/s, sideways m/s, turn rad/s] each). Left out: randomControl(seed, …). */
  control?: ArrayLike<number>;
  /** Lock planted feet (default true). */
  footLock?: boolean;
  /** Add the stride's sway a drawn path lacks to the control the model reads (default true; vaeLstmStride.ts). */
  stride?: boolean;
}

export interface VaeLstmInitResult extends FittedModelInit {
  latent: number;
  pooling: number;
  chunkSteps: number;
  window: number;
}

/** A whole generated motion. */
export interface VaeLstmChunk {
  frames: number;
  /** frames × rows.dim physical decoded rows (positions in the root facing frame, decoded control, contacts). */
  rows: Float32Array;
  /** frames × joints × 3: the decoded points in the world, bone lengths as predicted. */
  predicted: Float32Array;
  /** frames × joints × 3: fitted to the skeleton, before the foot lock. */
  fitted: Float32Array;
  /** frames × joints × 3: fitted, then foot-locked unless footLock is false. */
  positions: Float32Array;
  /** frames × 2: the labels the feet were locked with (without the lock: the decoded channels > 0.5). */
  contacts: Uint8Array;
  /** frames × 2: the decoded contact channels > 0.5. */
  decodedContacts: Uint8Array;
  /** frames × 3: x, z, heading of each frame's root (moved by the control asked for). */
  roots: Float64Array;
  rootHeading: Float32Array;
  /** frames × 3: the control the motion was made for. */
  control: Float32Array;
  /** The latent sample the motion hangs on (its first step's, when there is one per step). */
  z1: Float32Array;
  seed: number;
  /** Cell chunk calls made. */
  cellCalls: number;
  computeMs: number;
}

export type VaeLstmFollowPathParams = LatentFollowPathParams;

export interface VaeLstmFollowPathChunk extends VaeLstmChunk {
  /** As the other followers': windows are steps of 4 frames, particleSteps cell steps. */
  stats: FollowPathStatsReply;
  /** The path as followed (resampled, and smoothed for strokes): x, z pairs. */
  path: Float32Array;
}

/** Parity inputs: one call of any of the graphs (flattened data with dims), and/or a whole generation from z1. */
export interface VaeLstmParityInputs {
  graphs?: Partial<Record<VaeLstmGraph, Record<string, { dims: number[]; data: ArrayLike<number> }>>>;
  generate?: { control: ArrayLike<number>; z1: ArrayLike<number>; zs?: ArrayLike<number> };
}

export type VaeLstmParityResult = Partial<Record<VaeLstmGraph, Record<string, Float32Array>>> & {
  /** The generation's physical rows (frames × dim). */
  rows?: Float64Array;
};
