// The page's one generator: a GeneratorClient (worker + onnxruntime-web) created on first use, shared by
// `playground.generate` and the Random walk mode. Shows a loading indicator while the model loads.

import { GeneratorClient, type InitResult } from '../runtime/generatorClient';

/**
 * onnxruntime-web threads: `?threads=N` in the page URL, else min(2, cores) when cross-origin isolated,
 * else 1. (On a 2-core machine 1 thread measured 2–3× faster than 2 under load: override to compare.)
 */
export function pageThreads(): number {
  const param = new URLSearchParams(location.search).get('threads');
  if (param !== null) {
    const n = Number(param);
    if (Number.isInteger(n) && n >= 1 && n <= 64) return n;
  }
  return globalThis.crossOriginIsolated ? Math.min(2, navigator.hardwareConcurrency || 1) : 1;
}

export interface LoadedGenerator {
  client: GeneratorClient;
  info: InitResult;
}

export class GeneratorHost {
  private loading: Promise<LoadedGenerator> | null = null;
  private busy = 0;

  constructor(private readonly indicator: HTMLElement | null) {}

  /** The loaded generator; loads it (once) on first call. A failed load is retried on the next call. */
  load(): Promise<LoadedGenerator> {
    if (!this.loading) {
      const client = new GeneratorClient({ threads: pageThreads() });
      this.setBusy(+1);
      const loading = client.init().then(
        (info) => ({ client, info }),
        (e: unknown) => {
          client.dispose();
          if (this.loading === loading) this.loading = null;
          throw e;
        },
      );
      loading.then(() => this.setBusy(-1), () => this.setBusy(-1));
      this.loading = loading;
    }
    return this.loading;
  }

  /** Forgets a generator whose worker failed, so the next `load` starts a fresh one. */
  reset(client?: GeneratorClient): void {
    if (!this.loading) return;
    const loading = this.loading;
    void loading.then(({ client: c }) => {
      if (client && c !== client) return;
      if (this.loading === loading) this.loading = null;
      c.dispose();
    }, () => undefined);
  }

  private setBusy(delta: number): void {
    this.busy += delta;
    if (!this.indicator) return;
    this.indicator.hidden = this.busy <= 0;
  }
}
