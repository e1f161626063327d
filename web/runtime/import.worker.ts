/// <reference lib="webworker" />
// Parses imported motion capture off the page thread: dropped or picked files (read, gunzipped, parsed:
// motionFiles.ts) and playground.importMotion's text. Requests run one at a time, in order, so files
// dropped one after another are shown in that order and an .asf dropped first is remembered for the
// .amc after it. A result's typed arrays are transferred to the page, not copied.
import { importMotion } from '../motion/io';
import { MotionFormatError, type Motion } from '../motion/types';
import type { ImportError, ImportReply, ImportRequest, ImportResult } from './importProtocol';
import { FileImporter } from './motionFiles';

declare const self: DedicatedWorkerGlobalScope;

const importer = new FileImporter();
let queue: Promise<void> = Promise.resolve();

function reply(message: ImportReply, transfer: Transferable[] = []): void {
  self.postMessage(message, transfer);
}

/** An error as the reply carries it (structured cloning would drop a MotionFormatError's name, format and line). */
function importError(e: unknown): ImportError {
  if (!(e instanceof Error)) return { name: 'Error', message: String(e) };
  const error: ImportError = { name: e.name, message: e.message || e.name };
  if (e instanceof MotionFormatError) {
    error.format = e.format;
    if (e.line !== undefined) error.line = e.line;
  }
  return error;
}

/** The buffers of a result's motion: its positions and contacts. */
function buffersOf(result: ImportResult): Transferable[] {
  const motion: Motion | null = 'positions' in result ? result : result.kind === 'motion' ? result.motion : null;
  if (!motion) return [];
  return [...new Set([motion.positions.buffer, motion.contacts?.buffer].filter((b): b is ArrayBuffer => b instanceof ArrayBuffer))];
}

async function handle(request: ImportRequest): Promise<void> {
  const { id } = request;
  try {
    const result: ImportResult =
      request.type === 'files'
        ? await importer.importFiles(request.files, (progress) => reply({ id, progress }))
        : importMotion(request.text, request.format, request.asfText);
    reply({ id, ok: true, result }, buffersOf(result));
  } catch (e) {
    reply({ id, ok: false, error: importError(e) });
  }
}

self.addEventListener('message', (event: MessageEvent<ImportRequest>) => {
  const request = event.data;
  queue = queue.then(() => handle(request));
});
