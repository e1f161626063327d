// The page's side of the import worker (import.worker.ts): motion files and texts are parsed there, so a
// large import leaves the page thread free; the parsed Motion's arrays come back transferred. The worker
// starts on first use; one that fails rejects what it was doing, and the next call starts a fresh one.
import { MotionFormatError, type Motion } from '../motion/types';
import type { ImportError, ImportReply, ImportRequest, ImportRequestBody, ImportResult } from './importProtocol';
import type { FileImportOutcome, ProgressListener } from './motionFiles';

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
}

export class ImportClient {
  private worker: Worker | null = null;
  private readonly pending = new Map<number, Pending>();
  private nextId = 1;

  /** Imports dropped or picked files (see motionFiles.ts FileImporter); `onProgress` hears the read and parse stages. */
  importFiles(files: File[], onProgress?: ProgressListener): Promise<FileImportOutcome> {
    return this.request({ type: 'files', files }, onProgress) as Promise<FileImportOutcome>;
  }

  /** motion/io importMotion in the worker: rejects with the parser's error (a MotionFormatError with its format, line and message). */
  importText(text: string, format: 'bvh' | 'amc', asfText?: string): Promise<Motion> {
    return this.request({ type: 'text', text, format, ...(asfText === undefined ? {} : { asfText }) }) as Promise<Motion>;
  }

  /** Stops the worker; what it was doing rejects. */
  dispose(): void {
    this.fail(new Error('the import worker was stopped'));
  }

  private request(body: ImportRequestBody, onProgress?: ProgressListener): Promise<ImportResult> {
    const worker = (this.worker ??= this.start());
    const id = this.nextId++;
    return new Promise<ImportResult>((resolve, reject) => {
      this.pending.set(id, { resolve, reject, onProgress });
      const request: ImportRequest = { id, ...body };
      try {
        worker.postMessage(request);
      } catch (e) {
        this.pending.delete(id);
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
    if (message.ok) {
      entry.resolve(message.result);
      return;
    }
    entry.reject(rebuiltError(message.error));
  }

  /** Rejects everything pending and stops the worker; the next request starts a new one. */
  private fail(error: Error): void {
    for (const entry of this.pending.values()) entry.reject(error);
    this.pending.clear();
    this.worker?.terminate();
    this.worker = null;
  }
}
