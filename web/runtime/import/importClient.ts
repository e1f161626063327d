// The page's side of the import worker (import.worker.ts): motion files and texts are parsed there, so a
// large import leaves the page thread free; the parsed Motion's arrays come back transferred. The worker
// starts on first use; one that fails rejects what it was doing, and the next call starts a fresh one.
// A request whose signal aborts rejects at once with a CancelledError (name "AbortError") and is
// cancelled in the worker (requestLoop.ts); its reply, if one still comes, is dropped.
import { MotionFormatError, type Motion } from '../../motion/types';
import { CancelledError } from '../worker/cancellation';
import type { ImportError, ImportReply, ImportRequest, ImportRequestBody, ImportResult } from './importProtocol';
import type { FileImportOutcome, ProgressListener } from './motionFiles';
import type { CancelMessage } from '../worker/protocol';
import type { RequestOptions } from '../worker/workerClient';

/** The worker's error rebuilt on the page: a MotionFormatError again (format and line kept) when it was one, else an Error of its name. */
function rebuiltError({ name, message, format, line }: ImportError): Error {
  if (format !== undefined) {
    const error = new MotionFormatError(format, '', line);
    error.message = message; // the worker's message as it was, "BVH line 187: …"
    return error;
  }
  const error = new Error(message);
  error.name = name;
  return error;
}

interface Pending {
  resolve: (result: ImportResult) => void;
  reject: (error: Error) => void;
  onProgress?: ProgressListener;
  /** Stops listening to the request's signal. */
  settle: () => void;
}

export class ImportClient {
  private worker: Worker | null = null;
  private readonly pending = new Map<number, Pending>();
  private nextId = 1;

  /**
   * Imports dropped or picked files (see motionFiles.ts FileImporter); `onProgress` hears the read and
   * parse stages. `signal` cancels it: reading stops at the next chunk; a parse under way runs to its end.
   */
  importFiles(files: File[], onProgress?: ProgressListener, options: RequestOptions = {}): Promise<FileImportOutcome> {
    return this.request({ type: 'files', files }, { ...options, onProgress }) as Promise<FileImportOutcome>;
  }

  /**
   * motion/io importMotion in the worker: rejects with the parser's error (a MotionFormatError with its
   * format, line and message). `signal` cancels it: dropped if still queued, its result dropped if parsing.
   */
  importText(text: string, format: 'bvh' | 'amc', asfText?: string, options: RequestOptions = {}): Promise<Motion> {
    return this.request({ type: 'text', text, format, ...(asfText === undefined ? {} : { asfText }) }, options) as Promise<Motion>;
  }

  /** Stops the worker; what it was doing rejects. */
  dispose(): void {
    this.fail(new Error('the import worker was stopped'));
  }

  private request(body: ImportRequestBody, { signal, onProgress }: RequestOptions & { onProgress?: ProgressListener }): Promise<ImportResult> {
    const cancelled = () => new CancelledError(`import ${body.type}: cancelled`, { cause: signal?.reason });
    if (signal?.aborted) return Promise.reject(cancelled());
    const worker = (this.worker ??= this.start());
    const id = this.nextId++;
    return new Promise<ImportResult>((resolve, reject) => {
      const onAbort = () => {
        if (!this.pending.delete(id)) return;
        this.worker?.postMessage({ type: 'cancel', request: id } satisfies CancelMessage);
        reject(cancelled());
      };
      const settle = () => signal?.removeEventListener('abort', onAbort);
      this.pending.set(id, { resolve, reject, onProgress, settle });
      signal?.addEventListener('abort', onAbort, { once: true });
      const request: ImportRequest = { id, ...body };
      try {
        worker.postMessage(request);
      } catch (e) {
        this.pending.delete(id);
        settle();
        reject(e instanceof Error ? e : new Error(String(e)));
      }
    });
  }

  private start(): Worker {
    const worker = new Worker(new URL('./import.worker.ts', import.meta.url), { type: 'module', name: 'import' });
    worker.addEventListener('message', (event: MessageEvent<ImportReply>) => this.onReply(event.data));
    worker.addEventListener('error', (event) => {
      event.preventDefault();
      this.fail(new Error(`import worker failed: ${event.message || 'could not load or run the worker script'}`));
    });
    worker.addEventListener('messageerror', () => this.fail(new Error('import worker sent a message that could not be read')));
    return worker;
  }

  private onReply(message: ImportReply): void {
    const entry = this.pending.get(message.id);
    if (!entry) return;
    if ('progress' in message) {
      entry.onProgress?.(message.progress);
      return;
    }
    this.pending.delete(message.id);
    entry.settle();
    if (message.ok) {
      entry.resolve(message.result);
      return;
    }
    entry.reject(rebuiltError(message.error));
  }

  /** Rejects everything pending and stops the worker; the next request starts a new one. */
  private fail(error: Error): void {
    for (const entry of this.pending.values()) {
      entry.settle();
      entry.reject(error);
    }
    this.pending.clear();
    this.worker?.terminate();
    this.worker = null;
  }
}
