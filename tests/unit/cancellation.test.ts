// Cancelling requests. The client/worker protocol: the real WorkerClient talks over a MessageChannel to
// the real request loop (web/runtime/worker/requestLoop.ts) serving scripted requests: a request cancelled while
// queued never runs, a running one stops at its next checkpoint, both reject with an AbortError, and the
// next request runs normally. The model cores on the shipped models (onnxruntime-web's Node build): a
// request cancelled part-way rejects, and the streams it ran beside (a refined stream, the live control
// stream) continue exactly as if it had never run.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CANCELLED_ERROR_NAME, CancelledError, checkpoint } from '../../web/runtime/worker/cancellation';
import { DanceCore } from '../../web/runtime/aclstm/danceCore';
import { parseDanceInfo } from '../../web/runtime/aclstm/danceModel';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { OptimizerRequests } from '../../web/runtime/generator/optimizerRequests';
import type { GeneratedChunk } from '../../web/runtime/generator/protocol';
import type { WorkerMessage } from '../../web/runtime/worker/protocol';
import { RefinerCore } from '../../web/runtime/refiner/refinerCore';
import { parseRefinerInfo } from '../../web/runtime/refiner/refinerModel';
import { serveRequests } from '../../web/runtime/worker/requestLoop';
import { WorkerClient, type ProgressOptions } from '../../web/runtime/worker/workerClient';
import { readRepoFile } from './corpus';
import { bytes, ort, shippedSession } from './shippedModel';

/** A WorkerClient whose worker is one end of a MessageChannel; the request loop serves the other. */
class ChannelClient extends WorkerClient {
  call<T>(type: string, body: object = {}, options: ProgressOptions = {}): Promise<T> {
    return this.request<T>(type, body, options);
  }
}

type TestRequest = { type: 'hold' | 'spin' | 'echo' | 'fail'; value?: number };

/**
 * The scripted worker: `hold` waits until the test lets it go; `spin` reports progress once, then
 * passes checkpoints until cancelled; `echo` returns its value; `fail` throws. `handled` lists what ran.
 */
function connect() {
  const { port1, port2 } = new MessageChannel();
  const handled: string[] = [];
  let letGo = () => {};
  const holding = new Promise<void>((resolve) => (letGo = resolve));
  serveRequests<TestRequest>(port1, async (request, progress, signal) => {
    handled.push(request.value === undefined ? request.type : `${request.type} ${request.value}`);
    switch (request.type) {
      case 'hold':
        await holding;
        return 'held';
      case 'spin':
        progress(0);
        try {
          for (;;) await checkpoint(signal);
        } finally {
          handled.push(`spin stopped (aborted: ${signal.aborted})`);
        }
      case 'echo':
        return request.value;
      case 'fail':
        throw new Error('boom');
    }
  });
  // What the worker answered, seen beside the client (which drops replies to requests it cancelled).
  const replies: WorkerMessage[] = [];
  const waiters: { match: (m: WorkerMessage) => boolean; resolve: (m: WorkerMessage) => void }[] = [];
  port2.addEventListener('message', (event: MessageEvent<WorkerMessage>) => {
    replies.push(event.data);
    for (const w of waiters.filter((w) => w.match(event.data))) w.resolve(event.data);
  });
  /** The worker's reply to request `id` (the client numbers requests 1, 2, …). */
  const replyTo = (id: number) =>
    new Promise<WorkerMessage>((resolve) => {
      const match = (m: WorkerMessage) => m.id === id && 'ok' in m;
      const seen = replies.find(match);
      if (seen) resolve(seen);
      else waiters.push({ match, resolve });
    });
  const worker = Object.assign(port2, { terminate: () => port2.close() }) as unknown as Worker;
  return { client: new ChannelClient(worker, 'test'), handled, letGo, replyTo, close: () => port2.close() };
}

/** The rejection of `promise` (fails the test if it resolves). */
async function rejection(promise: Promise<unknown>): Promise<Error> {
  try {
    await promise;
  } catch (e) {
    return e as Error;
  }
  throw new Error('expected the request to reject');
}

describe('the request loop and WorkerClient', () => {
  it('drops a request cancelled while queued without running it; the one before and the one after run normally', async () => {
    const w = connect();
    const held = w.client.call<string>('hold'); // id 1: keeps the worker busy
    const cancel = new AbortController();
    const queued = w.client.call<number>('echo', { value: 1 }, { signal: cancel.signal }); // id 2
    cancel.abort();
    const error = await rejection(queued);
    expect(error).toBeInstanceOf(CancelledError);
    expect(error.name).toBe(CANCELLED_ERROR_NAME);
    expect(error.name).toBe('AbortError');
    expect(error.message).toBe('test echo: cancelled');
    // The worker answers the dropped request itself, before the one it is busy with has finished.
    expect(await w.replyTo(2)).toEqual({ id: 2, ok: false, error: 'echo: cancelled', name: 'AbortError' });
    w.letGo();
    expect(await held).toBe('held');
    expect(await w.client.call<number>('echo', { value: 3 })).toBe(3);
    expect(w.handled).toEqual(['hold', 'echo 3']);
    w.close();
  });

  it('drops a request cancelled while queued behind one that runs without pausing (as a parse does)', async () => {
    const w = connect();
    const first = w.client.call<number>('echo', { value: 1 }); // id 1: runs in one go, never passing a checkpoint
    const cancel = new AbortController();
    const queued = w.client.call<number>('echo', { value: 2 }, { signal: cancel.signal }); // id 2
    cancel.abort(); // the cancel reaches the worker after both requests
    expect((await rejection(queued)).name).toBe('AbortError');
    expect(await first).toBe(1);
    expect(await w.replyTo(2)).toEqual({ id: 2, ok: false, error: 'echo: cancelled', name: 'AbortError' });
    expect(await w.client.call<number>('echo', { value: 3 })).toBe(3);
    expect(w.handled).toEqual(['echo 1', 'echo 3']);
    w.close();
  });

  it('stops a running request at its next checkpoint; the next request runs normally', async () => {
    const w = connect();
    const cancel = new AbortController();
    let started!: () => void;
    const running = new Promise<void>((resolve) => (started = resolve));
    const spin = w.client.call('spin', {}, { signal: cancel.signal, onProgress: () => started() }); // id 1
    await running; // the worker is inside the request
    cancel.abort();
    const error = await rejection(spin);
    expect(error.name).toBe('AbortError');
    expect(error.message).toBe('test spin: cancelled');
    expect(await w.replyTo(1)).toEqual({ id: 1, ok: false, error: 'spin: cancelled', name: 'AbortError' });
    expect(w.handled).toEqual(['spin', 'spin stopped (aborted: true)']);
    expect(await w.client.call<number>('echo', { value: 7 })).toBe(7);
    w.close();
  });

  it('rejects at once on a signal that has already aborted, sending nothing', async () => {
    const w = connect();
    const error = await rejection(w.client.call('echo', { value: 1 }, { signal: AbortSignal.abort() }));
    expect(error.name).toBe('AbortError');
    expect(await w.client.call<number>('echo', { value: 2 })).toBe(2);
    expect(w.handled).toEqual(['echo 2']);
    w.close();
  });

  it('keeps a failure an ordinary Error, not an AbortError', async () => {
    const w = connect();
    const error = await rejection(w.client.call('fail', {}, { signal: new AbortController().signal }));
    expect(error.name).toBe('Error');
    expect(error.message).toBe('test fail: boom');
    w.close();
  });
});

/** A signal that reads as not aborted `looks` times, then as aborted: cancels at a known model step. */
function abortsAfter(looks: number): AbortSignal {
  let seen = 0;
  return {
    get aborted() {
      return ++seen > looks;
    },
  } as AbortSignal;
}

const generatorInfo = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json');
const refinerInfo = parseRefinerInfo(JSON.parse(readRepoFile('public/models/refiner.json')), 'public/models/refiner.json');
const danceInfo = parseDanceInfo(JSON.parse(readRepoFile('public/models/aclstm.json')), 'public/models/aclstm.json');

const chunkBytes = (c: GeneratedChunk) => [bytes(c.positions), bytes(c.contacts), bytes(c.refined!.positions), bytes(c.refined!.contacts)];

describe('model cores cancelled part-way', () => {
  let generator: GeneratorCore;
  let dance: DanceCore;

  beforeAll(async () => {
    const refiner = new RefinerCore(await shippedSession(refinerInfo.file), refinerInfo, generatorInfo, ort.Tensor);
    generator = new GeneratorCore(await shippedSession(generatorInfo.file), generatorInfo, ort.Tensor, 1, { loadRefiner: async () => refiner });
    dance = new DanceCore(await shippedSession(danceInfo.file), danceInfo, ort.Tensor);
  });
  afterAll(async () => {
    await generator?.release();
    await dance?.release();
  });

  it('a generate cancelled between two pulls of a refined stream leaves the stream and its refiner state as they were', async () => {
    const params = { seed: 5, temperature: 0.5, refine: true };
    const whole = generator.createStream(params);
    const reference = [await generator.advance(whole, 20), await generator.advance(whole, 20)];

    const stream = generator.createStream(params);
    const first = await generator.advance(stream, 20);
    const error = await rejection(generator.generate({ ...params, frames: 200 }, abortsAfter(30)));
    expect(error.name).toBe('AbortError');
    const second = await generator.advance(stream, 20);
    expect([chunkBytes(first), chunkBytes(second)]).toEqual(reference.map(chunkBytes));
  });

  it('a dance cancelled while warming up on its seed motion makes no stream; the next dance is the same as ever', async () => {
    const params = { style: 'salsa', seed: 1, frames: 15 };
    const reference = await dance.generate(params);
    const error = await rejection(dance.createStream(params, abortsAfter(3)));
    expect(error.name).toBe('AbortError');
    expect(bytes((await dance.generate(params)).positions)).toEqual(bytes(reference.positions));
  });

  it('simulateControl and followPath cancelled part-way leave the live control stream as it was', async () => {
    const requests = new OptimizerRequests(generator);
    const target = { speed: 1.2, heading: 0.3, frames: 6 };
    requests.controlStart({ seed: 2, gait: 'walk' });
    const reference = [await requests.controlPull(target), await requests.controlPull(target)];

    requests.controlStart({ seed: 2, gait: 'walk' });
    const first = await requests.controlPull(target);
    const progress: number[] = [];
    const simulation = { seconds: 2, schedule: [{ t: 0, speed: 1, heading: 0 }], seed: 4 };
    // A batch of 6 frames takes 2 rounds of 12 steps: cancelled in its third batch.
    const simulated = await rejection(requests.simulate(simulation, (f) => progress.push(f), abortsAfter(60)));
    expect(simulated.name).toBe('AbortError');
    expect(progress.length).toBe(2);
    const followed = await rejection(requests.followPath({ points: [[0, 0], [0, 3]], gait: 'walk', seed: 1 }, () => {}, abortsAfter(10)));
    expect(followed.name).toBe('AbortError');
    const second = await requests.controlPull(target);
    expect([first, second].map((c) => bytes(c.positions))).toEqual(reference.map((c) => bytes(c.positions)));
  });
});
