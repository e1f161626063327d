// One client per model, shared by the API and the modes (web/ui/modelHost.ts): loaded once, and started
// afresh only after its worker failed, never after a request it refused or one that was cancelled.
import { describe, expect, it } from 'vitest';
import { BusyIndicator, ModelHost, withClient } from '../../web/ui/modelHost';
import { CancelledError } from '../../web/runtime/worker/cancellation';
import { RequestRefusedError, WorkerFailedError } from '../../web/runtime/worker/workerClient';

/** A stand-in for a model's client: counts how many were made and which were disposed. */
function fakeClients() {
  const made: { id: number; disposed: boolean }[] = [];
  const host = new ModelHost(() => {
    const client = { id: made.length, disposed: false, init: async () => ({ fps: 30 }), dispose: () => void (client.disposed = true) };
    made.push(client);
    return client;
  }, new BusyIndicator(null));
  return { host, made };
}

const settle = () => new Promise((r) => setTimeout(r, 0));

describe('withClient', () => {
  it('shares one client across uses', async () => {
    const { host, made } = fakeClients();
    expect(await withClient(host, async (c) => c.id)).toBe(0);
    expect(await withClient(host, async (c) => c.id)).toBe(0);
    expect(made).toHaveLength(1);
  });

  it('keeps the client after a refused or cancelled request', async () => {
    const { host, made } = fakeClients();
    await expect(withClient(host, () => Promise.reject(new RequestRefusedError('generator followPath: points must be …')))).rejects.toThrow(/points/);
    await expect(withClient(host, () => Promise.reject(new CancelledError('generator generate: cancelled')))).rejects.toThrow(/cancelled/);
    await expect(withClient(host, () => Promise.reject(new Error('a check of the caller')))).rejects.toThrow(/caller/);
    await settle();
    expect(made.map((c) => c.disposed)).toEqual([false]);
    expect(await withClient(host, async (c) => c.id)).toBe(0);
  });

  it('starts a new client after the worker failed, and disposes the failed one', async () => {
    const { host, made } = fakeClients();
    await expect(withClient(host, () => Promise.reject(new WorkerFailedError('generator worker failed: out of memory')))).rejects.toThrow(/out of memory/);
    await settle();
    expect(made[0].disposed).toBe(true);
    expect(await withClient(host, async (c) => c.id)).toBe(1);
  });
});
