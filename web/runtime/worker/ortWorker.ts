/// <reference lib="webworker" />
// What every model worker shares: onnxruntime-web's wasm setup (threads when cross-origin isolated,
// else 1), fetching a model's JSON and ONNX bytes, creating the session, and the model requests served
// by the request loop (requestLoop.ts: one request at a time, in order, each answered by exactly one
// reply carrying its id, cancellable).
import * as ort from 'onnxruntime-web/wasm';
import { ortGlueHref, ortWasmHref } from './ortFiles';
import { WORKER_ERROR_ID, type ModelRequest } from './protocol';
import type { DownloadReply, DownloadRequest } from './sharedDownloads';
import { describe, serveRequests, type Progress } from './requestLoop';

declare const self: DedicatedWorkerGlobalScope;

export { describe, ort };

/** Thread count onnxruntime settled on when it loaded its wasm (it cannot change afterwards). */
let runtimeThreads: number | undefined;

function absolute(url: string): string {
  return new URL(url, self.location.href).href;
}

/**
 * Sets onnxruntime-web up on first use: `requestedThreads` when the page is cross-origin isolated
 * (default 2), else 1. Later calls cannot change it (the wasm is loaded once per worker).
 */
async function configureRuntime(requestedThreads?: number): Promise<void> {
  if (requestedThreads !== undefined && !(Number.isInteger(requestedThreads) && requestedThreads >= 1)) {
    throw new Error(`threads must be a positive integer, got ${requestedThreads}`);
  }
  if (runtimeThreads !== undefined || ort.env.wasm.wasmBinary) return;
  ort.env.wasm.numThreads = self.crossOriginIsolated ? (requestedThreads ?? 2) : 1;
  ort.env.wasm.simd = true;
  ort.env.wasm.proxy = false; // already off the main thread
  // The wasm (the largest download) comes through the page too, shared by every worker.
  ort.env.wasm.wasmBinary = await fetchBytes(ortWasmHref(), 'onnxruntime wasm');
  ort.env.wasm.wasmPaths = { mjs: ortGlueHref() };
}

/** Downloads asked of the page and not yet answered (sharedDownloads.ts). */
const downloadsWaiting = new Map<number, { resolve: (bytes: ArrayBuffer) => void; reject: (error: Error) => void }>();
let nextDownload = 1;
self.addEventListener('message', (event: MessageEvent<DownloadReply | { type?: unknown }>) => {
  const reply = event.data;
  if (reply?.type !== 'downloaded') return;
  const { download } = reply as DownloadReply;
  const waiting = downloadsWaiting.get(download);
  downloadsWaiting.delete(download);
  if ('bytes' in reply) waiting?.resolve(reply.bytes as ArrayBuffer);
  else waiting?.reject(new Error((reply as { error: string }).error));
});

/**
 * The bytes at `url`, fetched by the page (once for every worker and element on it that asks for the same
 * file: sharedDownloads.ts). `what` names the file in messages ("generator model <url>: HTTP 404 …").
 */
async function fetchBytes(url: string, what: string): Promise<Uint8Array> {
  const href = absolute(url);
  const download = nextDownload++;
  const bytes = new Promise<ArrayBuffer>((resolve, reject) => downloadsWaiting.set(download, { resolve, reject }));
  self.postMessage({ type: 'download', download, url: href } satisfies DownloadRequest);
  try {
    return new Uint8Array(await bytes);
  } catch (err) {
    throw new Error(`${what} ${url}: ${describe(err)}`);
  }
}

/** A wasm session on fetched ONNX bytes; `modelUrl` names the file in messages. */
async function createSession(bytes: Uint8Array, modelUrl: string): Promise<ort.InferenceSession> {
  try {
    return await ort.InferenceSession.create(bytes, { executionProviders: ['wasm'], graphOptimizationLevel: 'all' });
  } catch (err) {
    throw new Error(`could not create an onnxruntime-web session for ${modelUrl}: ${describe(err)}`);
  }
}

/** Fetches an ONNX file and creates its session on the runtime already set up (a second model in a worker). */
export async function loadExtraSession(modelUrl: string, what: string): Promise<ort.InferenceSession> {
  return createSession(await fetchBytes(modelUrl, what), modelUrl);
}

/**
 * Fetches a model's description (`loadInfo`) and ONNX bytes in parallel, sets the runtime up and
 * creates a session. `what` names the model in messages ("generator model").
 */
async function loadSession<Info>(
  modelUrl: string,
  infoUrl: string,
  loadInfo: (url: string) => Promise<Info>,
  what: string,
  requestedThreads?: number,
): Promise<{ session: ort.InferenceSession; info: Info; threads: number }> {
  const [info, bytes] = await Promise.all([loadInfo(infoUrl), fetchBytes(modelUrl, what), configureRuntime(requestedThreads)]);
  const session = await createSession(bytes, modelUrl);
  runtimeThreads ??= ort.env.wasm.numThreads ?? 1; // onnxruntime lowers it to 1 where threads are unavailable
  return { session, info, threads: runtimeThreads };
}

/**
 * What a model worker runs: a step-loop core over one session (GeneratorCore, DanceCore). Methods given
 * a `signal` pass a checkpoint (cancellation.ts) before each model step and stop there once it aborts.
 */
export interface ModelCore<Stream, StreamParams> {
  /** One step on fixed inputs: a model whose sizes disagree with its JSON fails at load time. */
  check(): Promise<void>;
  release(): Promise<void>;
  /** The `init` reply. */
  describe(loadMs: number): unknown;
  generate(params: StreamParams & { frames: number }, signal?: AbortSignal): Promise<unknown>;
  createStream(params: StreamParams, signal?: AbortSignal): Stream | Promise<Stream>;
  streamInfo(stream: Stream): unknown;
  advance(stream: Stream, frames: number, signal?: AbortSignal): Promise<unknown>;
  benchmark(batch: number, steps: number): Promise<unknown>;
  parity(inputs: never): Promise<unknown>;
}

/**
 * A model's own requests by type (the generator's path following and control, clean-up, …): each handler gets
 * the request as its client sent it, typed by the handler, the loaded core, and the endless stream when one is
 * running (`stream.value`; `stream.params`: what `restart` starts again with, which a handler may replace).
 */
export type ModelRequests<Core> = Record<string, (request: never, core: Core, progress: Progress, signal: AbortSignal, stream: { value: unknown; params: unknown } | undefined) => Promise<unknown>>;

export interface ModelWorker<Info, Stream, P, Core extends ModelCore<Stream, P> = ModelCore<Stream, P>> {
  /** Names the model in messages: "generator" → "generator worker: …", "the generator model is not loaded". */
  name: string;
  loadInfo(url: string): Promise<Info>;
  makeCore(session: ort.InferenceSession, info: Info, threads: number): Core;
  /** The stream parameters of a generate or startStream request. */
  streamParams(request: P): P;
  /** Requests of this model only, by type. */
  requests?: ModelRequests<Core>;
}

/**
 * Serves one model in this worker: `init` loads it (replacing any earlier one), `generate` makes a
 * motion in one go, `startStream` / `pull` / `restart` drive one endless stream, `benchmark` and
 * `parity` time and check raw steps. `generate`, `startStream` and `restart` stop where they are when
 * cancelled (a cancelled start leaves no stream); a `pull` that has started runs whole, so the stream
 * always stands where its last reply left it (a cancelled pull still queued never runs).
 */
export function serveModel<Info, Stream, P, StepInputs, Core extends ModelCore<Stream, P>>(spec: ModelWorker<Info, Stream, P, Core>): void {
  let core: Core | undefined;
  let stream: { value: Stream; params: P } | undefined;
  const requireCore = () => core ?? fail(`the ${spec.name} model is not loaded: send init first`);
  const requireStream = () => stream ?? fail('no stream: send startStream first');
  const fail = (message: string): never => {
    throw new Error(message);
  };
  const start = async (c: ModelCore<Stream, P>, params: P, signal: AbortSignal) => {
    stream = undefined; // a failed or cancelled start leaves no stale stream behind
    stream = { value: await c.createStream(params, signal), params };
    return c.streamInfo(stream.value);
  };

  async function init(modelUrl: string, infoUrl: string, threads?: number): Promise<unknown> {
    const started = performance.now();
    const loaded = await loadSession(modelUrl, infoUrl, (url) => spec.loadInfo(url), `${spec.name} model`, threads);
    await core?.release();
    core = undefined;
    stream = undefined;
    try {
      const made = spec.makeCore(loaded.session, loaded.info, loaded.threads);
      await made.check();
      core = made;
    } catch (err) {
      await loaded.session.release();
      throw new Error(`${modelUrl} with ${infoUrl}: ${describe(err)}`);
    }
    return core.describe(performance.now() - started);
  }

  self.addEventListener('unhandledrejection', (event) => {
    self.postMessage({ id: WORKER_ERROR_ID, ok: false, error: `${spec.name} worker: ${describe(event.reason)}` });
  });
  serveRequests<ModelRequest<P, StepInputs>>(self, async (request, progress, signal) => {
    switch (request.type) {
      case 'init':
        return init(request.modelUrl, request.infoUrl, request.threads);
      case 'generate':
        return requireCore().generate({ ...spec.streamParams(request), frames: request.frames }, signal);
      case 'startStream':
        return start(requireCore(), spec.streamParams(request), signal);
      case 'pull':
        return requireCore().advance(requireStream().value, request.frames);
      case 'restart':
        return start(requireCore(), requireStream().params, signal);
      case 'benchmark':
        return requireCore().benchmark(request.batch, request.steps);
      case 'parity':
        return requireCore().parity(request.inputs as never);
      default: {
        const type = (request as { type?: unknown }).type;
        const handler = typeof type === 'string' && Object.hasOwn(spec.requests ?? {}, type) ? spec.requests![type] : undefined;
        if (!handler) throw new Error(`unknown request type "${type}"`);
        // The handler's type says what its client sends with this type (the protocol files).
        return handler(request as never, requireCore(), progress, signal, stream);
      }
    }
  });
}
