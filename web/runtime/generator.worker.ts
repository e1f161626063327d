/// <reference lib="webworker" />
// Runs the locomotion generator off the main thread with onnxruntime-web's wasm execution provider.
// Requests are handled one at a time, in order; each gets exactly one reply, an error reply if
// anything throws.
import * as ort from 'onnxruntime-web/wasm';
// The runtime's files, handed to onnxruntime explicitly so Vite serves them in dev and emits them in a
// build. The .mjs stays a file of its own (not bundled into this worker) because the threaded runtime
// starts its helper workers from the .mjs's own URL.
import ortWasmUrl from 'onnxruntime-web/ort-wasm-simd-threaded.wasm?url';
import ortGlueUrl from 'onnxruntime-web/ort-wasm-simd-threaded.mjs?url';
import { GeneratorCore, type GeneratorStream } from './generatorCore';
import { loadGeneratorInfo } from './generatorModel';
import { WORKER_ERROR_ID, type GeneratorReply, type GeneratorRequest, type InitResult } from './protocol';

declare const self: DedicatedWorkerGlobalScope;

let core: GeneratorCore | undefined;
let stream: GeneratorStream | undefined;
/** Thread count onnxruntime settled on when it loaded its wasm (it cannot change afterwards). */
let runtimeThreads: number | undefined;

function requireCore(): GeneratorCore {
  if (!core) throw new Error('the generator is not loaded: send init first');
  return core;
}

function requireStream(): GeneratorStream {
  if (!stream) throw new Error('no stream: send startStream first');
  return stream;
}

async function fetchBytes(url: string, what: string): Promise<Uint8Array> {
  let response: Response;
  try {
    response = await fetch(url);
  } catch (err) {
    throw new Error(`${what} ${url}: could not fetch (${describe(err)})`);
  }
  if (!response.ok) throw new Error(`${what} ${url}: HTTP ${response.status} ${response.statusText}`);
  // Dev servers answer unknown paths with the app's index.html; say so rather than "protobuf parsing failed".
  if (response.headers.get('content-type')?.includes('text/html')) throw new Error(`${what} ${url}: got an HTML page, not a model file (wrong URL?)`);
  return new Uint8Array(await response.arrayBuffer());
}

async function init(modelUrl: string, infoUrl: string, requestedThreads?: number): Promise<InitResult> {
  const started = performance.now();
  if (requestedThreads !== undefined && !(Number.isInteger(requestedThreads) && requestedThreads >= 1)) {
    throw new Error(`threads must be a positive integer, got ${requestedThreads}`);
  }
  if (runtimeThreads === undefined) {
    ort.env.wasm.numThreads = self.crossOriginIsolated ? (requestedThreads ?? 2) : 1;
    ort.env.wasm.simd = true;
    ort.env.wasm.proxy = false; // already off the main thread
    ort.env.wasm.wasmPaths = { wasm: absolute(ortWasmUrl), mjs: absolute(ortGlueUrl) };
  }

  const [info, bytes] = await Promise.all([loadGeneratorInfo(infoUrl), fetchBytes(modelUrl, 'generator model')]);
  await core?.release();
  core = undefined;
  stream = undefined;
  let session: ort.InferenceSession;
  try {
    session = await ort.InferenceSession.create(bytes, { executionProviders: ['wasm'], graphOptimizationLevel: 'all' });
  } catch (err) {
    throw new Error(`could not create an onnxruntime-web session for ${modelUrl}: ${describe(err)}`);
  }
  runtimeThreads ??= ort.env.wasm.numThreads ?? 1; // onnxruntime lowers it to 1 where threads are unavailable
  try {
    const loaded = new GeneratorCore(session, info, ort.Tensor, runtimeThreads);
    await loaded.check();
    core = loaded;
  } catch (err) {
    await session.release();
    throw new Error(`${modelUrl} with ${infoUrl}: ${describe(err)}`);
  }
  return {
    ok: true,
    threads: runtimeThreads,
    loadMs: performance.now() - started,
    fps: info.fps,
    joints: info.skeleton.joints,
    parents: info.skeleton.parents,
    dim: info.onnx.dim,
    seeds: info.seeds.map((s) => s.name),
  };
}

function absolute(url: string): string {
  return new URL(url, self.location.href).href;
}

async function handle(request: GeneratorRequest): Promise<unknown> {
  switch (request.type) {
    case 'init':
      return init(request.modelUrl, request.infoUrl, request.threads);
    case 'generate':
      return requireCore().generate({ frames: request.frames, seed: request.seed, temperature: request.temperature, seedIndex: request.seedIndex });
    case 'startStream': {
      const c = requireCore();
      stream = c.createStream({ seed: request.seed, temperature: request.temperature, seedIndex: request.seedIndex });
      return c.streamInfo(stream);
    }
    case 'pull':
      return requireCore().advance(requireStream(), request.frames);
    case 'restart': {
      const c = requireCore();
      stream = c.createStream(requireStream().params);
      return c.streamInfo(stream);
    }
    case 'benchmark':
      return requireCore().benchmark(request.batch, request.steps);
    case 'parity':
      return requireCore().parity(request.inputs);
    default:
      throw new Error(`unknown request type "${(request as { type?: unknown }).type}"`);
  }
}

function describe(err: unknown): string {
  if (err instanceof Error) return err.message || err.name;
  return typeof err === 'string' ? err : (JSON.stringify(err) ?? String(err));
}

/** ArrayBuffers in a result (up to two levels deep), handed over instead of copied. */
function transferables(result: unknown): Transferable[] {
  const found = new Set<ArrayBuffer>();
  const visit = (value: unknown, depth: number) => {
    if (ArrayBuffer.isView(value) && value.buffer instanceof ArrayBuffer) found.add(value.buffer);
    else if (value && typeof value === 'object' && depth < 2) Object.values(value).forEach((v) => visit(v, depth + 1));
  };
  visit(result, 0);
  return [...found];
}

function reply(message: GeneratorReply, transfer: Transferable[] = []): void {
  self.postMessage(message, transfer);
}

let queue: Promise<void> = Promise.resolve();

self.addEventListener('message', (event: MessageEvent<{ id: number } & GeneratorRequest>) => {
  const request = event.data;
  queue = queue.then(async () => {
    try {
      const result = await handle(request);
      reply({ id: request.id, ok: true, result }, transferables(result));
    } catch (err) {
      reply({ id: request.id, ok: false, error: `${request.type}: ${describe(err)}` });
    }
  });
});

self.addEventListener('unhandledrejection', (event) => {
  reply({ id: WORKER_ERROR_ID, ok: false, error: `generator worker: ${describe(event.reason)}` });
});
