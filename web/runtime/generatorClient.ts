// Main-thread handle on the generator worker: promise methods, requests matched to replies by id.
import type { Motion } from '../motion/types';
import {
  WORKER_ERROR_ID,
  type BenchmarkResult,
  type GeneratedChunk,
  type GenerateParams,
  type GeneratorReply,
  type GeneratorRequest,
  type InitResult,
  type ParityResult,
  type ReplyMap,
  type StepInputs,
  type StreamInfo,
  type StreamParams,
} from './protocol';

export type { BenchmarkResult, GenerateParams, InitResult, ParityResult, StepInputs, StreamInfo, StreamParams };

/** Generated frames as a Motion, with the generator's extras. */
export type GeneratedMotion = Motion & {
  contacts: Uint8Array;
  /** frames × D feature rows in physical units. */
  features: Float32Array;
  rootHeading: Float32Array;
  seedIndex: number;
  /** Index of the first frame within its stream (0 for `generate`). */
  startFrame: number;
};

export interface GeneratorClientOptions {
  /** Defaults resolve against the page: models/generator.onnx and models/generator.json. */
  modelUrl?: string;
  infoUrl?: string;
  /** onnxruntime-web threads when the page is cross-origin isolated (default 2); without isolation always 1. */
  threads?: number;
  /** Gives up on the worker (rejecting `init` and later calls) if `init` has no answer by then: a stalled download or wasm. */
  initTimeoutMs?: number;
}

interface Pending {
  resolve: (value: unknown) => void;
  reject: (error: Error) => void;
  timer?: ReturnType<typeof setTimeout>;
}

type RequestType = GeneratorRequest['type'];
type Body<T extends RequestType> = Omit<Extract<GeneratorRequest, { type: T }>, 'type'>;

export class GeneratorClient {
  private worker: Worker | undefined;
  private readonly pending = new Map<number, Pending>();
  private nextId = 1;
  private failure: Error | undefined;
  private skeleton: { fps: number; joints: string[]; parents: number[] } | undefined;
  private readonly modelUrl: string;
  private readonly infoUrl: string;
  private readonly initTimeoutMs: number;
  private readonly threads: number | undefined;

  constructor(options: GeneratorClientOptions = {}) {
    // The worker resolves relative URLs against its own script URL, so make them absolute here.
    this.modelUrl = new URL(options.modelUrl ?? 'models/generator.onnx', document.baseURI).href;
    this.infoUrl = new URL(options.infoUrl ?? 'models/generator.json', document.baseURI).href;
    this.initTimeoutMs = options.initTimeoutMs ?? 60_000;
    this.threads = options.threads;
    this.worker = new Worker(new URL('./generator.worker.ts', import.meta.url), { type: 'module', name: 'generator' });
    this.worker.addEventListener('message', (event: MessageEvent<GeneratorReply>) => this.onReply(event.data));
    this.worker.addEventListener('error', (event) => {
      event.preventDefault();
      this.fail(new Error(`generator worker failed: ${event.message || 'could not load or run the worker script'}`));
    });
    this.worker.addEventListener('messageerror', () => this.fail(new Error('generator worker sent a message that could not be read')));
  }

  /** Loads the model; resolves with the thread count and load time. Call before anything else. */
  async init(): Promise<InitResult> {
    const result = await this.request('init', { modelUrl: this.modelUrl, infoUrl: this.infoUrl, threads: this.threads }, this.initTimeoutMs);
    this.skeleton = { fps: result.fps, joints: result.joints, parents: result.parents };
    return result;
  }

  /** `frames` new frames from a seed state; the same parameters always give bit-identical output. */
  async generate(params: GenerateParams): Promise<GeneratedMotion> {
    return this.toMotion(await this.request('generate', { ...params }));
  }

  /** Starts (or replaces) the endless stream; frames come from `pull`. */
  startStream(params: StreamParams): Promise<StreamInfo> {
    return this.request('startStream', { ...params });
  }

  /** The stream's next `frames` frames, continuing its state and root trajectory. */
  async pull(frames: number): Promise<GeneratedMotion> {
    return this.toMotion(await this.request('pull', { frames }));
  }

  /** Back to the start of the stream, with the parameters it was started with. */
  restart(): Promise<StreamInfo> {
    return this.request('restart', {});
  }

  /** Times `steps` raw session calls at `batch` streams. */
  benchmark(batch: number, steps: number): Promise<BenchmarkResult> {
    return this.request('benchmark', { batch, steps });
  }

  /**
   * One raw ONNX step. Without inputs it uses the first and last seed states at batch 2, the inputs of
   * tests/fixtures/generator_reference.json's `step`.
   */
  parity(inputs?: StepInputs): Promise<ParityResult> {
    return this.request('parity', inputs ? { inputs } : {});
  }

  /** Stops the worker; pending and later calls reject. */
  dispose(): void {
    this.fail(new Error('the generator client was disposed'));
  }

  private toMotion(chunk: GeneratedChunk): GeneratedMotion {
    if (!this.skeleton) throw new Error('generator: init has not completed');
    return {
      fps: this.skeleton.fps,
      frames: chunk.frames,
      joints: this.skeleton.joints,
      parents: this.skeleton.parents,
      positions: chunk.positions,
      contacts: chunk.contacts,
      features: chunk.features,
      rootHeading: chunk.rootHeading,
      seedIndex: chunk.seedIndex,
      startFrame: chunk.startFrame,
    };
  }

  private request<T extends RequestType>(type: T, body: Body<T>, timeoutMs?: number): Promise<ReplyMap[T]> {
    if (this.failure || !this.worker) return Promise.reject(this.failure ?? new Error('generator worker is not running'));
    const id = this.nextId++;
    return new Promise<ReplyMap[T]>((resolve, reject) => {
      const entry: Pending = { resolve: resolve as (value: unknown) => void, reject };
      if (timeoutMs !== undefined) {
        // A worker that stalls would hold every later request in its queue too: give up on it entirely.
        entry.timer = setTimeout(() => this.fail(new Error(`generator ${type}: no answer from the worker within ${timeoutMs / 1000} s`)), timeoutMs);
      }
      this.pending.set(id, entry);
      this.worker!.postMessage({ id, type, ...body });
    });
  }

  private onReply(message: GeneratorReply): void {
    if (message.id === WORKER_ERROR_ID) {
      if (!message.ok) this.fail(new Error(message.error));
      return;
    }
    const entry = this.pending.get(message.id);
    if (!entry) return;
    this.pending.delete(message.id);
    clearTimeout(entry.timer);
    if (message.ok) entry.resolve(message.result);
    else entry.reject(new Error(`generator ${message.error}`));
  }

  /** Rejects everything pending, stops the worker and makes later calls reject with the same error. */
  private fail(error: Error): void {
    this.failure ??= error;
    for (const entry of this.pending.values()) {
      clearTimeout(entry.timer);
      entry.reject(error);
    }
    this.pending.clear();
    this.worker?.terminate();
    this.worker = undefined;
  }
}
