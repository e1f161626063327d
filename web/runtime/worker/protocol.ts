// Messages every model worker shares with its client: requests carry an id and the worker answers each with
// exactly one reply carrying the same id (requestLoop.ts, workerClient.ts); what every `init` answers; timing;
// and the numbers of a walk along a path, which every path follower reports.

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

/** What every model worker's `init` answers: how it runs, and the skeleton of its frames. */
export interface ModelInit {
  ok: true;
  /** Threads onnxruntime-web runs with (by default 2 when the page is cross-origin isolated, else 1). */
  threads: number;
  /** Milliseconds to fetch and check the JSON and model and create the session. */
  loadMs: number;
  fps: number;
  joints: string[];
  parents: number[];
}

/** `init` of a model whose frames are fitted to a skeleton of its own (the dance models, the latent ERD, the VAE-LSTM). */
export interface FittedModelInit extends ModelInit {
  id: string;
  /** joints × 3 rest offsets (metres): the skeleton the fitted frames keep. */
  offsets: number[];
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

/** Id of replies that are about the worker as a whole (an uncaught error), not one request. */
export const WORKER_ERROR_ID = -1;

/** How well a walk follows its path, and its foot skating and sliding (docs/api.md FollowPathStats). */
export interface PathStats {
  /** Mean and largest distance from the root (on the ground) to the path over all frames, metres. */
  meanError: number;
  maxError: number;
  /** Share of the path's length the character covered (0…1). */
  arcProgress: number;
  /** Wall-clock milliseconds the optimisation took. */
  optimizeMs: number;
  /** Foot skating (m/s, mean planted-toe speed by the returned contacts) of the motion, and of the motion before the foot lock (by the model's own contact bits). */
  skating: number;
  skatingBeforeLock: number;
  /** Foot sliding (m/s): the lowest foot point's horizontal speed while within 4 cm of the floor (no contacts needed), the same two. */
  sliding: number;
  slidingBeforeLock: number;
}

/** What every path follower's worker is asked (each model adds what it reads beside: fitSigma or speed). */
export interface FollowPathRequest {
  /** [x, z] pairs, metres. */
  points: [number, number][];
  gait: 'walk' | 'run';
  /** Picks the seed state (the VAE-LSTM: z1; another seed, another motion for the same path). */
  seed: number;
  /** The points are a hand-drawn stroke: drop jitter and smooth before following. */
  stroke?: boolean;
  /** Clean planted feet with the foot lock (web/motion/footLock.ts; default true). The root is not moved. */
  footLock?: boolean;
}

/** A worker's stats of a walk: the public ones, and the work it took (windows optimised, model steps run). */
export interface FollowPathStatsReply extends PathStats {
  windows: number;
  particleSteps: number;
}
