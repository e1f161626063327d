// The page's model clients (a worker + onnxruntime-web each), created on first use and shared by
// the API and the modes. A loading indicator shows while any model loads.

import { WorkerFailedError } from '../runtime/worker/workerClient';

/**
 * onnxruntime-web threads for a page whose URL query is `search`, on `cores` cores: `?threads=N` (an
 * integer ≥ 1; anything else is ignored) capped at the core count, since threads beyond it only take
 * turns on the same cores (64 on 2 cores made everything 4× slower); else, when cross-origin isolated,
 * half the cores (at most 4) so the worker's threads leave the page's own thread a core; else 1. On this
 * project's 2-core test machine that means 1: two threads measured 2× slower there (npm run bench),
 * because the second thread fights the renderer for the same cores.
 */
export function threadCount(search: string, cores: number, isolated: boolean): number {
  const param = new URLSearchParams(search).get('threads');
  if (param !== null) {
    const n = Number(param);
    if (Number.isInteger(n) && n >= 1) return Math.min(n, cores);
  }
  if (!isolated) return 1;
  return Math.max(1, Math.min(4, Math.floor(cores / 2)));
}

/** The thread count for this page (threadCount of its URL, core count and isolation). */
export function pageThreads(): number {
  return threadCount(location.search, Math.max(1, navigator.hardwareConcurrency || 1), globalThis.crossOriginIsolated);
}

/** The "Loading model…" indicator: shown while at least one load is running. */
export class BusyIndicator {
  private busy = 0;

  constructor(private readonly element: HTMLElement | null) {}

  add(delta: number): void {
    this.busy += delta;
    if (this.element) this.element.hidden = this.busy <= 0;
  }
}

interface Client<Info> {
  init(): Promise<Info>;
  dispose(): void;
}

export interface LoadedModel<C, Info> {
  client: C;
  info: Info;
}

/** One model's client, loaded once on first use; a failed load is retried on the next call. */
export class ModelHost<C extends Client<Info>, Info> {
  private loading: Promise<LoadedModel<C, Info>> | null = null;
  /** Every client made and not yet disposed (one, unless a failed one is being replaced). */
  private readonly clients = new Set<C>();
  private disposed = false;

  constructor(private readonly make: () => C, private readonly indicator: BusyIndicator) {}

  load(): Promise<LoadedModel<C, Info>> {
    if (this.disposed) return Promise.reject(new WorkerFailedError('the model was unloaded (its element was taken off the page)'));
    if (!this.loading) {
      const client = this.make();
      this.clients.add(client);
      this.indicator.add(+1);
      const loading = client.init().then(
        (info) => ({ client, info }),
        (e: unknown) => {
          this.clients.delete(client);
          client.dispose();
          if (this.loading === loading) this.loading = null;
          throw e;
        },
      );
      loading.then(() => this.indicator.add(-1), () => this.indicator.add(-1));
      this.loading = loading;
    }
    return this.loading;
  }

  /** Stops every worker it started (a load under way rejects); later loads reject. */
  dispose(): void {
    this.disposed = true;
    this.loading = null;
    for (const client of [...this.clients]) client.dispose();
  }

  /** Forgets a client whose worker failed, so the next `load` starts a fresh one. */
  reset(client?: C): void {
    if (!this.loading) return;
    const loading = this.loading;
    void loading.then(({ client: c }) => {
      if (client && c !== client) return;
      if (this.loading === loading) this.loading = null;
      this.clients.delete(c);
      c.dispose();
    }, () => undefined);
  }
}

/**
 * Runs `use` with the host's client (loaded on first use). A worker that failed (WorkerFailedError) is forgotten,
 * so the next use starts a new one; a request it refused, or a cancelled one, leaves it for the next use.
 */
export async function withClient<C extends Client<Info>, Info, T>(host: ModelHost<C, Info>, use: (client: C) => Promise<T>): Promise<T> {
  const { client } = await host.load();
  try {
    return await use(client);
  } catch (e) {
    if (e instanceof WorkerFailedError) host.reset(client);
    throw e;
  }
}
