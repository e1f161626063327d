// Messages between ImportClient (page thread) and import.worker.ts (served by requestLoop.ts). Every request
// carries an id; the worker answers it with any number of progress messages and then exactly one reply with
// the same id. An error reply carries the error's name and message, and a MotionFormatError's format and
// line, so it stays one on the page. A CancelMessage (protocol.ts) cancels a request: dropped if queued
// (answered with an AbortError error), or, while a File is read, stopped at its next chunk.
import type { Motion, MotionFormat } from '../../motion/types';
import type { FileImportOutcome, ImportProgress } from './motionFiles';

export type ImportRequestBody =
  /** Dropped or picked files (File objects cross to the worker without copying their contents). */
  | { type: 'files'; files: File[] }
  /** playground.importMotion's text. */
  | { type: 'text'; text: string; format: 'bvh' | 'amc'; asfText?: string };

export type ImportRequest = ImportRequestBody & { id: number };

export type ImportResult = FileImportOutcome | Motion;

/** A failed request's error as it crosses to the page: `format` (and `line`, when known) only for a MotionFormatError. */
export interface ImportError {
  name: string;
  message: string;
  format?: MotionFormat;
  line?: number;
}

export type ImportReply =
  | { id: number; ok: true; result: ImportResult }
  | { id: number; ok: false; error: ImportError }
  | { id: number; progress: ImportProgress };
