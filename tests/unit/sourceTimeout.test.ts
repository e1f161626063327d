// The element's `src` fetch gives up after SOURCE_TIMEOUT_MS (30 s) without an answer (issue 43 #7), whether the
// fetch heeds its abort signal or not, and a fetch that answers in time is not cut short.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { fetchMotionSource, SOURCE_TIMEOUT_MS } from '../../web/runtime/import/motionSource';

const PAGE = 'https://site.example/demo/';

describe('the src fetch times out', () => {
  beforeEach(() => vi.useFakeTimers());
  afterEach(() => vi.useRealTimers());

  it('waits 30 s for an answer', () => {
    expect(SOURCE_TIMEOUT_MS).toBe(30_000);
  });

  for (const heeds of [true, false]) {
    it(`fails after 30 s when nothing answers (a fetch that ${heeds ? 'heeds' : 'ignores'} its signal)`, async () => {
      let signal: AbortSignal | undefined;
      const never: typeof fetch = (_url, init) => {
        signal = init?.signal ?? undefined;
        return new Promise((_resolve, reject) => {
          if (heeds) signal?.addEventListener('abort', () => reject(new DOMException('aborted', 'AbortError')));
        });
      };
      let outcome: string | null = null;
      void fetchMotionSource('clips/a.bvh', PAGE, [], never).then(() => (outcome = 'resolved'), (e: Error) => (outcome = e.message));
      await vi.advanceTimersByTimeAsync(SOURCE_TIMEOUT_MS - 1);
      expect(outcome).toBeNull();
      await vi.advanceTimersByTimeAsync(1);
      expect(outcome).toBe('"https://site.example/demo/clips/a.bvh": no answer within 30 s');
      expect(signal?.aborted).toBe(true);
    });
  }

  it('times the body too: headers in time and then nothing fails as well', async () => {
    const stalled: typeof fetch = async (_url, init) => {
      const body = new ReadableStream({
        start(controller) {
          controller.enqueue(new TextEncoder().encode('HIERARCHY\n'));
          init?.signal?.addEventListener('abort', () => controller.error(init.signal!.reason));
        },
      });
      return new Response(body);
    };
    const result = fetchMotionSource('a.bvh', PAGE, [], stalled).catch((e: Error) => e.message);
    await vi.advanceTimersByTimeAsync(SOURCE_TIMEOUT_MS);
    expect(await result).toMatch(/no answer within 30 s$/);
  });

  it('leaves no timer behind once answered, and takes a shorter limit when given one', async () => {
    expect(await fetchMotionSource('a.bvh', PAGE, [], async () => new Response('HIERARCHY'))).toBe('HIERARCHY');
    expect(vi.getTimerCount()).toBe(0);
    const result = fetchMotionSource('a.bvh', PAGE, [], () => new Promise(() => undefined), 500).catch((e: Error) => e.message);
    await vi.advanceTimersByTimeAsync(500);
    expect(await result).toMatch(/no answer within 0.5 s$/);
  });
});
