// The page's one generator: a GeneratorClient (worker + onnxruntime-web) created on first use, shared by
// `playground.generate` and the Random walk mode. Shows a loading indicator while the model loads.

import { GeneratorClient, type InitResult } from '../runtime/generatorClient';

/**
 * onnxruntime-web threads: `?threads=N` in the page URL; else, when cross-origin isolated, half the cores
 * (at most 4) so the worker's threads leave the page's own thread a core; else 1. On this project's
 * 2-core test machine that means 1: two threads measured 2× slower there (npm run bench), because the
 * second thread fights the renderer for the same cores.
 */
export function pageThreads(): number {
  const param = new URLSearchParams(location.search).get('threads');
  if (param !== null) {
    const n = Number(param);
    if (Number.isInteger(n) && n >= 1 && n <= 64) return n;
  }
  if (!globalThis.crossOriginIsolated) return 1;
  return Math.max(1, Math.min(4, Math.floor((navigator.hardwareConcurrency || 1) / 2)));
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
