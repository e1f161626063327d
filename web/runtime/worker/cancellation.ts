// Cancelling requests: the error a cancelled request rejects with (named "AbortError", as fetch names an
// aborted request), and the checkpoint a long request in a worker passes between model steps, where it
// lets the worker read its messages (a cancel among them) and stops if it was cancelled.

export const CANCELLED_ERROR_NAME = 'AbortError';

/** A request that was cancelled (its AbortSignal aborted, or a newer request replaced it). */
export class CancelledError extends Error {
  override name = CANCELLED_ERROR_NAME;
}

export function isCancelled(error: unknown): boolean {
  return error instanceof Error && error.name === CANCELLED_ERROR_NAME;
}

/**
 * Work (ms) between two looks at the worker's messages: a cancel is seen within about this long (plus
 * one model step) of arriving, and a look (one message round trip) costs far less than this.
 */
const WORK_BETWEEN_LOOKS_MS = 20;
let lastLook = 0;

/** Resolves after the event loop has run the tasks already queued (a message-channel round trip, not a timer). */
export function nextTask(): Promise<void> {
  return new Promise((resolve) => {
    const channel = new MessageChannel();
    channel.port1.onmessage = () => {
      channel.port1.close();
      resolve();
    };
    channel.port2.postMessage(null);
  });
}

export function throwIfCancelled(signal: AbortSignal): void {
  if (signal.aborted) throw new CancelledError('cancelled');
}

/**
 * Called by a cancellable request before each model step: throws a CancelledError if `signal` has
 * aborted; every WORK_BETWEEN_LOOKS_MS of work it first yields to the worker's event loop (so the message
 * loop can mark the request cancelled) and returns a promise to await. Between looks it returns nothing,
 * so a step pays no extra turn of the microtask queue.
 */
export function checkpoint(signal: AbortSignal): Promise<void> | undefined {
  if (performance.now() - lastLook < WORK_BETWEEN_LOOKS_MS) {
    throwIfCancelled(signal);
    return undefined;
  }
  return nextTask().then(() => {
    lastLook = performance.now();
    throwIfCancelled(signal);
  });
}

/**
 * Runs `work`, rejecting with a CancelledError as soon as `signal` aborts (at once if it already has)
 * instead of waiting for the work to notice.
 */
export function unlessAborted<T>(signal: AbortSignal | undefined, work: () => Promise<T>): Promise<T> {
  if (!signal) return work();
  if (signal.aborted) return Promise.reject(new CancelledError('cancelled', { cause: signal.reason }));
  return new Promise<T>((resolve, reject) => {
    const onAbort = () => reject(new CancelledError('cancelled', { cause: signal.reason }));
    signal.addEventListener('abort', onAbort, { once: true });
    new Promise<T>((run) => run(work()))
      .then(resolve, reject)
      .finally(() => signal.removeEventListener('abort', onAbort));
  });
}
