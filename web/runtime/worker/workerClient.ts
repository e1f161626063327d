// Main-thread side of a model worker, shared by GeneratorClient and DanceClient: requests carry an id
// and are matched to replies by it (in any order), an error reply rejects its request with the worker's
// message, a request whose signal aborts rejects at once with a CancelledError (name "AbortError") and
// is cancelled in the worker, a crashed or stalled worker rejects everything pending and every later
// call, and dispose stops the worker.
import type { Motion } from '../../motion/types';
import { CANCELLED_ERROR_NAME, CancelledError } from './cancellation';
import { WORKER_ERROR_ID, type BenchmarkResult, type CancelMessage, type WorkerMessage } from './protocol';
import { assetUrl } from './assetBase';
import { answerDownload, sharedDownload, type DownloadRequest } from './sharedDownloads';
import { ortWasmHref } from './ortFiles';

/**
 * The worker itself failed (it crashed, could not load, stalled past a timeout, or was disposed): this
 * client is done, and a new one is needed. A request the worker refused rejects with RequestRefusedError
 * instead, and the client goes on working. Both keep the name "Error" that the public API's errors have
 * (docs/api.md): tell them apart with instanceof.
 */
export class WorkerFailedError extends Error {}

/** The worker answered a request with an error (bad input, a model that cannot do it): the worker is fine. */
export class RequestRefusedError extends Error {}

/** Options of any request: `signal` cancels it (cancellation.ts). */
export interface RequestOptions {
  signal?: AbortSignal;
}

/** Options of a long request that reports progress: `onProgress` hears the share done (0…1). */
export interface ProgressOptions extends RequestOptions {
  onProgress?: (fraction: number) => void;
}

interface Pending {
  resolve: (value: unknown) => void;
  reject: (error: Error) => void;
  /** Clears the timeout and stops listening to the signal. */
  settle: () => void;
  onProgress?: (fraction: number) => void;
}

/** `label` prefixes messages ("generator" → "generator worker failed: …"). */
export class WorkerClient {
  private worker: Worker | undefined;
  private readonly pending = new Map<number, Pending>();
  private nextId = 1;
  private failure: Error | undefined;

  /** `worker` must be created by the subclass with a literal `new URL('../x.worker.ts', import.meta.url)` (Vite bundles it). */
  constructor(worker: Worker, protected readonly label: string) {
    this.worker = worker;
    worker.addEventListener('message', (event: MessageEvent<WorkerMessage | DownloadRequest>) => this.onReply(event.data));
    worker.addEventListener('error', (event) => {
      event.preventDefault();
      this.fail(new WorkerFailedError(`${label} worker failed: ${event.message || 'could not load or run the worker script'}`));
    });
    worker.addEventListener('messageerror', () => this.fail(new WorkerFailedError(`${label} worker sent a message that could not be read`)));
  }

  /** Stops the worker; pending and later calls reject. */
  dispose(): void {
    this.fail(new WorkerFailedError(`the ${this.label} client was disposed`));
  }

  /**
   * Sends one request; `timeoutMs` gives up on the whole worker if it has not answered by then;
   * `onProgress` hears the worker's progress reports for it. When `signal` aborts (or has already), the
   * request rejects at once with a CancelledError ("<label> <type>: cancelled") and the worker is told
   * to cancel it; its reply, if one still comes, is dropped.
   */
  protected request<T>(type: string, body: object, options: ProgressOptions & { timeoutMs?: number } = {}): Promise<T> {
    if (this.failure || !this.worker) return Promise.reject(this.failure ?? new WorkerFailedError(`${this.label} worker is not running`));
    const { signal, onProgress, timeoutMs } = options;
    const cancelled = () => new CancelledError(`${this.label} ${type}: cancelled`, { cause: signal?.reason });
    if (signal?.aborted) return Promise.reject(cancelled());
    const id = this.nextId++;
    return new Promise<T>((resolve, reject) => {
      // A worker that stalls would hold every later request in its queue too: give up on it entirely.
      const timer = timeoutMs === undefined ? undefined : setTimeout(() => this.fail(new WorkerFailedError(`${this.label} ${type}: no answer from the worker within ${timeoutMs / 1000} s`)), timeoutMs);
      const onAbort = () => {
        if (!this.pending.delete(id)) return;
        entry.settle();
        this.worker?.postMessage({ type: 'cancel', request: id } satisfies CancelMessage);
        reject(cancelled());
      };
      const entry: Pending = {
        resolve: resolve as (value: unknown) => void,
        reject,
        onProgress,
        settle: () => {
          clearTimeout(timer);
          signal?.removeEventListener('abort', onAbort);
        },
      };
      signal?.addEventListener('abort', onAbort, { once: true });
      this.pending.set(id, entry);
      this.worker!.postMessage({ id, type, ...body });
    });
  }

  private onReply(data: WorkerMessage | DownloadRequest): void {
    if ('type' in data && data.type === 'download') {
      if (this.worker) answerDownload(this.worker, data);
      return;
    }
    const message = data as WorkerMessage;
    if ('progress' in message) {
      this.pending.get(message.id)?.onProgress?.(message.progress);
      return;
    }
    if (message.id === WORKER_ERROR_ID) {
      if (!message.ok) this.fail(new WorkerFailedError(message.error));
      return;
    }
    const entry = this.pending.get(message.id);
    if (!entry) return;
    this.pending.delete(message.id);
    entry.settle();
    if (message.ok) entry.resolve(message.result);
    else entry.reject(message.name === CANCELLED_ERROR_NAME ? new CancelledError(`${this.label} ${message.error}`) : new RequestRefusedError(`${this.label} ${message.error}`));
  }

  /** Rejects everything pending, stops the worker and makes later calls reject with the same error. */
  private fail(error: Error): void {
    this.failure ??= error;
    for (const entry of this.pending.values()) {
      entry.settle();
      entry.reject(error);
    }
    this.pending.clear();
    this.worker?.terminate();
    this.worker = undefined;
  }
}

/** What a model's `init` reply tells about its output motions. */
export interface ModelSkeleton {
  fps: number;
  joints: string[];
  parents: number[];
}

/**
 * A model client's options: its files (left out: models/<id>.onnx and models/<id>.json, resolved against the
 * page), onnxruntime-web threads when the page is cross-origin isolated (default 2; without isolation always 1),
 * and how long `init` may take before the worker is given up (default 60 s: a stalled download or wasm).
 */
export interface ModelFileOptions {
  modelUrl?: string;
  infoUrl?: string;
  threads?: number;
  initTimeoutMs?: number;
}

/** The options ModelClient takes for model `id`'s files, with the defaults filled in. */
export function modelFiles(id: string, options: ModelFileOptions): ModelClientOptions {
  return {
    threads: options.threads,
    initTimeoutMs: options.initTimeoutMs,
    modelUrl: options.modelUrl ?? `models/${id}.onnx`,
    infoUrl: options.infoUrl ?? `models/${id}.json`,
  };
}

export interface ModelClientOptions {
  /** Model file URLs (resolved against the page). */
  modelUrl: string;
  infoUrl: string;
  /** onnxruntime-web threads when the page is cross-origin isolated (default 2); without isolation always 1. */
  threads?: number;
  /** Gives up on the worker (rejecting `init` and later calls) if `init` has no answer by then (default 60 s). */
  initTimeoutMs?: number;
}

/**
 * A model worker served by ortWorker.ts `serveModel`: load, generate in one go, an endless stream,
 * raw-step timing and parity. `P` are the stream parameters; subclasses turn chunks into Motions.
 */
export abstract class ModelClient<P extends object, Init extends ModelSkeleton, Chunk extends { frames: number; positions: Float32Array }, Info, Parity, Inputs, M> extends WorkerClient {
  /** The `init` result, once loaded. */
  protected loaded: Init | undefined;
  protected readonly urls: { modelUrl: string; infoUrl: string };
  private readonly initTimeoutMs: number;
  private readonly threads: number | undefined;

  constructor(worker: Worker, label: string, options: ModelClientOptions) {
    super(worker, label);
    this.urls = { modelUrl: pageUrl(options.modelUrl), infoUrl: pageUrl(options.infoUrl) };
    this.initTimeoutMs = options.initTimeoutMs ?? 60_000;
    this.threads = options.threads;
  }

  /** What `init` resolved with (it throws before `init` has completed). */
  get initResult(): Init {
    if (!this.loaded) throw new Error(`${this.label}: init has not completed`);
    return this.loaded;
  }

  /** Loads the model; resolves with what the worker reports about it. Call before anything else. */
  async init(): Promise<Init> {
    this.prefetch();
    this.loaded = await this.request<Init>('init', { ...this.urls, threads: this.threads }, { timeoutMs: this.initTimeoutMs });
    return this.loaded;
  }

  /**
   * Starts fetching what the worker will ask the page for as it loads (ortWorker.ts: the onnxruntime wasm and
   * the model), so the files are on their way while the worker script itself loads and starts. A failed fetch
   * is forgotten (sharedDownloads.ts): the worker's own ask tries again and reports the error.
   */
  protected prefetch(): void {
    for (const url of [ortWasmHref(), this.urls.modelUrl]) sharedDownload(url).catch(() => undefined);
  }

  /** `frames` new frames; the same parameters always give bit-identical output. Cancelled with `signal` (it stops between model steps). */
  async generate(params: P & { frames: number }, options: RequestOptions = {}): Promise<M> {
    return this.toMotion(await this.request<Chunk>('generate', { ...params }, options));
  }

  /** Starts (or replaces) the endless stream; frames come from `pull`. A cancelled start leaves no stream. */
  startStream(params: P, options: RequestOptions = {}): Promise<Info> {
    return this.request<Info>('startStream', { ...params }, options);
  }

  /**
   * The stream's next `frames` frames, continuing its state and root trajectory. Cancelled with `signal`
   * while queued it never runs; once running it runs whole (the stream moves on, the reply is dropped).
   */
  async pull(frames: number, options: RequestOptions = {}): Promise<M> {
    return this.toMotion(await this.request<Chunk>('pull', { frames }, options));
  }

  /** Back to the start of the stream, with the parameters it was started with. */
  restart(options: RequestOptions = {}): Promise<Info> {
    return this.request<Info>('restart', {}, options);
  }

  /** Times `steps` raw session calls at `batch` streams. */
  benchmark(batch: number, steps: number): Promise<BenchmarkResult> {
    return this.request<BenchmarkResult>('benchmark', { batch, steps });
  }

  protected parityRequest(inputs?: Inputs): Promise<Parity> {
    return this.request<Parity>('parity', inputs ? { inputs } : {});
  }

  protected abstract toMotion(chunk: Chunk): M;

  /** A chunk as a Motion with everything else the chunk carries, as it came (its extras: contacts, seed, …). */
  protected chunkMotion<T extends Chunk>(chunk: T): Motion & Omit<T, 'frames' | 'positions'> {
    const { frames: _frames, positions: _positions, ...extras } = chunk;
    return { ...this.motionOf(chunk), ...extras };
  }

  /** The Motion part of a chunk: the loaded model's rate and skeleton with the chunk's positions. */
  protected motionOf(chunk: Chunk): Motion {
    const info = this.loaded;
    if (!info) throw new Error(`${this.label}: init has not completed`);
    return { fps: info.fps, frames: chunk.frames, joints: info.joints, parents: info.parents, positions: chunk.positions };
  }
}

/**
 * Starts fetching the onnxruntime wasm that every model worker asks the page for, before any model is chosen (the
 * model list may still be loading); a failed fetch is forgotten and tried again when a worker asks.
 */
export function prefetchRuntime(): void {
  sharedDownload(ortWasmHref()).catch(() => undefined);
}

/** A model file URL resolved against the asset base (assetBase.ts; the worker would resolve relative URLs against its own script). */
export function pageUrl(url: string): string {
  return assetUrl(url);
}
