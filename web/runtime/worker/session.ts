// What the model cores (generatorCore.ts, danceCore.ts) share around an onnxruntime session: checking
// its input and output names, normalisation, float32 feeds, reading outputs with clear errors, and
// timing raw calls.
import type { InferenceSession, Tensor, TensorConstructor } from 'onnxruntime-web';
import { checkpoint } from './cancellation';
import type { BenchmarkResult } from './protocol';

/** Throws unless the session has every input and output the model's JSON names. */
function checkSessionNames(session: InferenceSession, inputs: readonly string[], outputs: readonly string[]): void {
  const missing = [
    ...inputs.filter((n) => !session.inputNames.includes(n)).map((n) => `input "${n}"`),
    ...outputs.filter((n) => !session.outputNames.includes(n)).map((n) => `output "${n}"`),
  ];
  if (missing.length) {
    throw new Error(`the model lacks ${missing.join(', ')} (it has inputs [${session.inputNames}], outputs [${session.outputNames}])`);
  }
}

/** A float32 (or, with `int64`, int64) output of `size` values; `files` names the pair to blame on a size mismatch ("generator.json match generator.onnx"). */
function readOutput(out: InferenceSession.OnnxValueMapType, name: string, size: number, files: string): Float32Array;
function readOutput(out: InferenceSession.OnnxValueMapType, name: string, size: number, files: string, int64: true): BigInt64Array;
function readOutput(out: InferenceSession.OnnxValueMapType, name: string, size: number, files: string, int64 = false): Float32Array | BigInt64Array {
  const tensor = out[name] as Tensor | undefined;
  if (!tensor) throw new Error(`the model gave no output "${name}"`);
  if (int64 ? !(tensor.data instanceof BigInt64Array) : !(tensor.data instanceof Float32Array)) {
    throw new Error(`model output "${name}" is ${tensor.type}, expected ${int64 ? 'int64' : 'float32'}`);
  }
  const data = tensor.data as Float32Array | BigInt64Array;
  if (data.length !== size) {
    throw new Error(`model output "${name}" has ${data.length} values (dims ${tensor.dims.join('×')}), expected ${size}; does ${files}?`);
  }
  return data;
}

/** Reads a call's outputs by name and size: float32, or int64 with `.int64` (a sampler's counters). */
export interface OutputReader {
  (name: string, size: number): Float32Array;
  int64(name: string, size: number): BigInt64Array;
}

export const MAX_BENCHMARK_BATCH = 4096;
export const MAX_FRAMES_PER_REQUEST = 100_000;

/** Throws unless `frames` is a frame count one generate or pull request may ask for. */
export function checkFrameCount(frames: number): void {
  if (!Number.isInteger(frames) || frames < 1 || frames > MAX_FRAMES_PER_REQUEST) {
    throw new Error(`frames must be an integer from 1 to ${MAX_FRAMES_PER_REQUEST}, got ${frames}`);
  }
}

/**
 * Checks batch and steps, then `setup()` builds the inputs and returns one call (which may feed its
 * state forward) of `stepsPerCall` steps; 3 warm-up calls, then enough timed ones for `steps` steps.
 */
export async function timeSteps(
  batch: number,
  steps: number,
  threads: number,
  setup: () => () => Promise<void>,
  stepsPerCall = 1,
): Promise<BenchmarkResult> {
  if (!Number.isInteger(batch) || batch < 1 || batch > MAX_BENCHMARK_BATCH) throw new Error(`batch must be an integer from 1 to ${MAX_BENCHMARK_BATCH}, got ${batch}`);
  if (!Number.isInteger(steps) || steps < 1) throw new Error(`steps must be a positive integer, got ${steps}`);
  const step = setup();
  for (let i = 0; i < 3; i++) await step(); // warm-up
  const calls = Math.ceil(steps / stepsPerCall);
  const started = performance.now();
  for (let i = 0; i < calls; i++) await step();
  const ms = performance.now() - started;
  const stepsPerSecond = (calls * stepsPerCall * 1000) / ms;
  return { batch, steps: calls * stepsPerCall, threads, stepsPerSecond, msPerCall: ms / calls, particleStepsPerSecond: stepsPerSecond * batch };
}

interface SessionModelInfo {
  id?: string;
  file: string;
  onnx: { inputs: string[]; outputs: string[] };
  normalisation: { mean: number[]; std: number[] };
}

/** Base of the model cores: one session, the model's JSON, its normalisation. */
export abstract class SessionCore<Info extends SessionModelInfo> {
  readonly info: Info;
  readonly threads: number;
  /** Feature normalisation: normalised = (physical − mean) / std. */
  readonly mean: Float32Array;
  readonly std: Float32Array;
  private readonly session: InferenceSession;
  private readonly Tensor: TensorConstructor;

  /** `Tensor` must come from the same onnxruntime module as the session. */
  constructor(session: InferenceSession, info: Info, Tensor: TensorConstructor, threads: number) {
    checkSessionNames(session, info.onnx.inputs, info.onnx.outputs);
    this.session = session;
    this.info = info;
    this.Tensor = Tensor;
    this.threads = threads;
    this.mean = Float32Array.from(info.normalisation.mean);
    this.std = Float32Array.from(info.normalisation.std);
  }

  release(): Promise<void> {
    return this.session.release();
  }

  /**
   * One session call on float32 (or int64: a BigInt64Array) feeds (`name: [data, dims]`); returns a reader for outputs of known
   * size (float32; int64 with `read.int64`), which names the files to blame when a size disagrees with the JSON. With `signal`, passes a
   * checkpoint first (cancellation.ts): throws CancelledError instead of running once it has aborted.
   */
  protected async run(feeds: Record<string, [Float32Array | BigInt64Array, number[]]>, signal?: AbortSignal): Promise<OutputReader> {
    const look = signal && checkpoint(signal);
    if (look) await look;
    const tensors: Record<string, Tensor> = {};
    for (const [name, [data, dims]] of Object.entries(feeds)) {
      tensors[name] = data instanceof BigInt64Array ? new this.Tensor('int64', data, dims) : new this.Tensor('float32', data, dims);
    }
    const out = await this.session.run(tensors);
    const files = `${this.info.id ?? 'the model'}.json match ${this.info.file}`;
    const read = (name: string, size: number) => readOutput(out, name, size, files);
    return Object.assign(read, { int64: (name: string, size: number) => readOutput(out, name, size, files, true) });
  }
}
