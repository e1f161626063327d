/// <reference lib="webworker" />
// Parses imported motion capture off the page thread: dropped or picked files (read, gunzipped, parsed:
// motionFiles.ts) and playground.importMotion's text. Requests run one at a time, in order, so files
// dropped one after another are shown in that order and an .asf dropped first is remembered for the
// .amc after it. A result's typed arrays are transferred to the page, not copied. The request loop is the
// model workers' (requestLoop.ts): a cancelled request that has not started is dropped; a File being read
// stops at its next chunk; a parse, once started, runs to its end (the page drops its result).
import { importMotion } from '../../motion/io';
import { MotionFormatError } from '../../motion/types';
import type { ImportError, ImportRequest } from './importProtocol';
import { FileImporter, type ImportProgress } from './motionFiles';
import { serveRequests } from '../worker/requestLoop';

declare const self: DedicatedWorkerGlobalScope;

const importer = new FileImporter();

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

serveRequests<ImportRequest, ImportProgress>(
  self,
  async (request, progress, signal) =>
    request.type === 'files' ? importer.importFiles(request.files, progress, signal) : importMotion(request.text, request.format, request.asfText),
  (_request, e) => ({ error: importError(e) }),
);
