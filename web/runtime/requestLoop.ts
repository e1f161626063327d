// A model worker's message loop, apart from onnxruntime so unit tests can run it over a MessageChannel:
// requests run one at a time, in order, each answered by exactly one reply carrying its id; a cancel
// message drops a queued request without running it, or aborts the running one's signal.
import { CANCELLED_ERROR_NAME, CancelledError, isCancelled } from './cancellation';
import type { CancelMessage, WorkerMessage } from './protocol';

/** Reports the share done of the request being handled (0…1). */
export type Progress = (fraction: number) => void;

/** Where requests arrive and replies go: the worker's global scope, or a MessagePort in tests. */
export interface RequestPort {
  addEventListener(type: 'message', listener: (event: MessageEvent) => void): void;
  postMessage(message: WorkerMessage, transfer: Transferable[]): void;
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
 * its id: its result, or an error reply (`<type>: <message>`) if `handle` throws. `handle` gets the
 * request's signal: a cancelled request (CancelMessage) that has not started is answered with an
 * AbortError reply and never handled; one that is running has its signal aborted, and is answered with an
 * AbortError reply if it stops for it (cancellation.ts checkpoint), or as usual if it finishes anyway.
 */
export function serveRequests<Request extends { type: string }>(port: RequestPort, handle: (request: Request, progress: Progress, signal: AbortSignal) => Promise<unknown>): void {
  const reply = (message: WorkerMessage, transfer: Transferable[] = []) => port.postMessage(message, transfer);
  const cancelledReply = (q: Queued<Request>) => reply({ id: q.id, ok: false, error: `${q.request.type}: cancelled`, name: CANCELLED_ERROR_NAME });
  const queue: Queued<Request>[] = [];
  let running: Queued<Request> | undefined;

  async function runQueue(): Promise<void> {
    while (queue.length) {
      const q = (running = queue.shift()!);
      try {
        const result = await handle(q.request, (fraction) => reply({ id: q.id, progress: fraction }), q.cancel.signal);
        reply({ id: q.id, ok: true, result }, transferables(result));
      } catch (err) {
        if (isCancelled(err) && q.cancel.signal.aborted) cancelledReply(q);
        else reply({ id: q.id, ok: false, error: `${q.request.type}: ${describe(err)}` });
      }
    }
    running = undefined;
  }

  port.addEventListener('message', (event: MessageEvent<({ id: number } & Request) | CancelMessage>) => {
    const message = event.data;
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
    if (!running) void runQueue();
  });
}
