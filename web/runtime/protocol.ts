// Messages between GeneratorClient (main thread) and generator.worker.ts. Every request carries an id;
// the worker answers each with exactly one reply carrying the same id (WorkerReply, also used by the
// dance worker: danceProtocol.ts).

export interface GenerateParams {
  frames: number;
  /** PRNG seed (used as an unsigned 32-bit integer). */
  seed: number;
  /** Sampling temperature τ ≥ 0: 0 = always the heaviest component's mean, 1 = the trained distribution. */
  temperature: number;
  /** Which seed state of generator.json to start from; default seed mod the number of seed states. */
  seedIndex?: number;
}

export type StreamParams = Omit<GenerateParams, 'frames'>;

/** The ONNX step's inputs, flattened: x (B×D), h and c (layers×B×H). */
export interface StepInputs {
  batch: number;
  x: ArrayLike<number>;
  h: ArrayLike<number>;
  c: ArrayLike<number>;
}

export interface StepOutputs {
  weights: Float32Array;
  mu: Float32Array;
  sigma: Float32Array;
  h_out: Float32Array;
  c_out: Float32Array;
}

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

/** A worker's answer to one request (the same shape for every model worker). */
export type WorkerReply = { id: number; ok: true; result: unknown } | { id: number; ok: false; error: string };
export type GeneratorReply = WorkerReply;

/** Id of replies that are about the worker as a whole (an uncaught error), not one request. */
export const WORKER_ERROR_ID = -1;
