// GeneratorClient's message handling against a scripted stand-in for the worker: replies matched by
// id in any order, error replies, a crashed worker, an init that never answers, dispose.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { GeneratorClient } from '../../web/runtime/generator/generatorClient';
import type { GeneratedChunk, GeneratorReply, InitResult } from '../../web/runtime/generator/protocol';

class FakeWorker extends EventTarget {
  static last: FakeWorker;
  readonly sent: ({ id: number; type: string } & Record<string, unknown>)[] = [];
  terminated = false;
  constructor(readonly url: URL, readonly options: WorkerOptions) {
    super();
    FakeWorker.last = this;
  }
  postMessage(message: FakeWorker['sent'][number]): void {
    this.sent.push(message);
  }
  terminate(): void {
    this.terminated = true;
  }
  reply(message: GeneratorReply): void {
    this.dispatchEvent(new MessageEvent('message', { data: message }));
  }
  crash(message: string): void {
    this.dispatchEvent(Object.assign(new Event('error', { cancelable: true }), { message }));
  }
}

const INIT: InitResult = { ok: true, threads: 1, loadMs: 5, fps: 30, joints: ['Hips', 'Spine'], parents: [-1, 0], dim: 12, seeds: ['walk'] };

function chunk(frames: number): GeneratedChunk {
  return {
    frames,
    features: new Float32Array(frames * 12),
    positions: new Float32Array(frames * 2 * 3).fill(frames),
    contacts: new Uint8Array(frames * 2),
    rootHeading: new Float32Array(frames),
    seedIndex: 0,
    startFrame: 0,
  };
}

async function readyClient(): Promise<{ client: GeneratorClient; worker: FakeWorker }> {
  const client = new GeneratorClient({ modelUrl: 'm.onnx', infoUrl: 'm.json' });
  const worker = FakeWorker.last;
  const init = client.init();
  worker.reply({ id: worker.sent[0].id, ok: true, result: INIT });
  await init;
  return { client, worker };
}

/** URLs the page fetched (the prefetch of init): answered 404, except a refiner.json naming its file. */
let fetched: string[] = [];

beforeEach(() => {
  vi.stubGlobal('Worker', FakeWorker);
  vi.stubGlobal('document', { baseURI: 'http://localhost/app/' });
  fetched = [];
  vi.stubGlobal('fetch', (url: string) => {
    fetched.push(String(url));
    if (String(url).endsWith('/refiner.json')) return Promise.resolve(new Response(JSON.stringify({ file: 'r.onnx' }), { headers: { 'content-type': 'application/json' } }));
    return Promise.resolve(new Response('', { status: 404 }));
  });
});

afterEach(() => {
  vi.unstubAllGlobals();
  vi.useRealTimers();
});

describe('GeneratorClient', () => {
  it('starts a module worker and sends absolute model URLs', async () => {
    const { worker } = await readyClient();
    expect(worker.options.type).toBe('module');
    expect(String(worker.url)).toMatch(/generator\.worker\.ts$/);
    expect(worker.sent[0]).toMatchObject({ type: 'init', modelUrl: 'http://localhost/app/m.onnx', infoUrl: 'http://localhost/app/m.json' });
  });

  it('matches replies to requests by id, in any order, and returns Motions', async () => {
    const { client, worker } = await readyClient();
    const first = client.generate({ frames: 3, seed: 1, temperature: 1 });
    const second = client.pull(5);
    const [a, b] = worker.sent.slice(1);
    expect(a).toMatchObject({ type: 'generate', frames: 3, seed: 1, temperature: 1 });
    expect(b).toMatchObject({ type: 'pull', frames: 5 });
    worker.reply({ id: b.id, ok: true, result: chunk(5) });
    worker.reply({ id: a.id, ok: true, result: chunk(3) });
    const [m1, m2] = await Promise.all([first, second]);
    expect(m1.frames).toBe(3);
    expect(m2.frames).toBe(5);
    expect(m1).toMatchObject({ fps: 30, joints: INIT.joints, parents: INIT.parents });
    expect(m1.positions[0]).toBe(3);
  });

  it('rejects with the worker’s error text', async () => {
    const { client, worker } = await readyClient();
    const request = client.benchmark(0, 1);
    worker.reply({ id: worker.sent[1].id, ok: false, error: 'benchmark: batch must be an integer from 1 to 4096, got 0' });
    await expect(request).rejects.toThrow('generator benchmark: batch must be an integer');
  });

  it('rejects everything pending, and later calls, when the worker crashes', async () => {
    const { client, worker } = await readyClient();
    const pending = [client.parity(), client.startStream({ seed: 1, temperature: 1 })];
    worker.crash('Uncaught SyntaxError');
    for (const p of pending) await expect(p).rejects.toThrow(/generator worker failed: Uncaught SyntaxError/);
    await expect(client.restart()).rejects.toThrow(/generator worker failed/);
    expect(worker.terminated).toBe(true);
  });

  it('gives up on an init that never answers', async () => {
    vi.useFakeTimers();
    const client = new GeneratorClient({ initTimeoutMs: 1000 });
    const init = client.init();
    vi.advanceTimersByTime(1001);
    await expect(init).rejects.toThrow(/generator init: no answer from the worker within 1 s/);
    await expect(client.generate({ frames: 1, seed: 1, temperature: 1 })).rejects.toThrow(/no answer/);
    expect(FakeWorker.last.terminated).toBe(true);
  });

  it('dispose rejects pending calls and stops the worker', async () => {
    const { client, worker } = await readyClient();
    const pending = client.generate({ frames: 1, seed: 1, temperature: 1 });
    client.dispose();
    await expect(pending).rejects.toThrow(/disposed/);
    await expect(client.pull(1)).rejects.toThrow(/disposed/);
    expect(worker.terminated).toBe(true);
  });
});

describe('GeneratorClient prefetch', () => {
  it('starts fetching the onnxruntime wasm, the model and the refiner before the worker asks for them', async () => {
    const client = new GeneratorClient({ modelUrl: 'models/g.onnx', infoUrl: 'models/g.json' });
    const worker = FakeWorker.last;
    const init = client.init();
    expect(worker.sent.map((m) => m.type)).toEqual(['init']);
    await vi.waitFor(() => expect(fetched).toContain('http://localhost/app/models/r.onnx'));
    expect(fetched).toContain('http://localhost/app/models/g.onnx');
    expect(fetched).toContain('http://localhost/app/models/refiner.json');
    expect(fetched.some((u) => /ort-wasm-simd-threaded.*\.wasm$/.test(u))).toBe(true);
    worker.reply({ id: worker.sent[0].id, ok: true, result: INIT });
    await init;
    client.dispose();
  });
});
