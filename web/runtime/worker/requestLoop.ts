// A model worker's message loop, apart from onnxruntime so unit tests can run it over a MessageChannel:
// requests run one at a time, in order, each answered by exactly one reply carrying its id; a cancel
// message drops a queued request without running it, or aborts the running one's signal. The import
// worker (import.worker.ts) is served by it too, with its own error replies and progress reports.
import { CANCELLED_ERROR_NAME, CancelledError, isCancelled, nextTask } from './cancellation';
import type { CancelMessage, WorkerReply } from './protocol';

/** Reports the share done of the request being handled (0…1). */
export type Progress = (fraction: number) => void;

/** Where requests arrive and replies go: the worker's global scope, or a MessagePort in tests. */
export interface RequestPort {
  addEventListener(type: 'message', listener: (event: MessageEvent) => void): void;
  postMessage(message: object, transfer: Transferable[]): void;
}

/**
 * What an error reply carries besides its id and `ok: false`: by default WorkerReply's
 * `error: "<type>: <message>"` (and `name: "AbortError"` when `cancelled`: its signal aborted).
 */
export type FailureReply<Request> = (request: Request, err: unknown, cancelled: boolean) => object;

function workerFailure(request: { type: string }, err: unknown, cancelled: boolean): Omit<Extract<WorkerReply, { ok: false }>, 'id' | 'ok'> {
  return cancelled ? { error: `${request.type}: cancelled`, name: CANCELLED_ERROR_NAME } : { error: `${request.type}: ${describe(err)}` };
}

export function describe(err: unknown): string {
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

type Queued<Request> = { id: number; request: Request; cancel: AbortController };

/**
 * Serves requests from `port` with `handle`, one at a time, in order. Each gets exactly one reply with
 * its id: its result, or an error reply (`failure`; by default `<type>: <message>`) if `handle` throws.
 * `handle` gets the request's signal: a cancelled request (CancelMessage) that has not started is
 * answered with an AbortError reply and never handled (before starting each request the loop reads the
 * messages already sent, so a cancel sent while an earlier request ran synchronously is seen); one that
 * is running has its signal aborted, and is answered with an AbortError reply if it stops for it
 * (cancellation.ts checkpoint), or as usual if it finishes anyway. `progress` reports (a share done, 0…1,
 * unless `Report` says otherwise) go out as `{ id, progress }`.
 */
export function serveRequests<Request extends { type: string }, Report = number>(
  port: RequestPort,
  handle: (request: Request, progress: (report: Report) => void, signal: AbortSignal) => Promise<unknown>,
  failure: FailureReply<Request> = workerFailure,
): void {
  const reply = (message: object, transfer: Transferable[] = []) => port.postMessage(message, transfer);
  const failed = (q: Queued<Request>, err: unknown, cancelled: boolean) => reply({ id: q.id, ok: false, ...failure(q.request, err, cancelled) });
  const cancelledReply = (q: Queued<Request>) => failed(q, new CancelledError('cancelled'), true);
  const queue: Queued<Request>[] = [];
  let running: Queued<Request> | undefined;
  let serving = false;

  async function runQueue(): Promise<void> {
    serving = true;
    for (;;) {
      await nextTask(); // reads cancels sent meanwhile, so a cancelled request is dropped, not started
      const q = queue.shift();
      if (!q) break;
      running = q;
      try {
        const result = await handle(q.request, (report) => reply({ id: q.id, progress: report }), q.cancel.signal);
        reply({ id: q.id, ok: true, result }, transferables(result));
      } catch (err) {
        failed(q, err, isCancelled(err) && q.cancel.signal.aborted);
      }
      running = undefined;
    }
    serving = false;
  }

  port.addEventListener('message', (event: MessageEvent<({ id: number } & Request) | CancelMessage>) => {
    const message = event.data;
    if ((message as { type?: unknown }).type === 'downloaded') return; // a file the page fetched (ortWorker.ts), not a request
    if (message.type === 'cancel') {
      const { request } = message as CancelMessage;
      if (running?.id === request) {
        running.cancel.abort(new CancelledError('cancelled'));
        return;
      }
      const at = queue.findIndex((q) => q.id === request);
      if (at >= 0) cancelledReply(queue.splice(at, 1)[0]);
      return;
    }
    const { id } = message as { id: number } & Request;
    queue.push({ id, request: message as Request, cancel: new AbortController() });
    if (!serving) void runQueue();
  });
}
