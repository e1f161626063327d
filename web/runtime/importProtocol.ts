// Messages between ImportClient (page thread) and import.worker.ts. Every request carries an id; the worker
// answers it with any number of progress messages and then exactly one reply with the same id. An error
// reply carries the error's name and message, so a MotionFormatError stays one on the page.
import type { Motion } from '../motion/types';
import type { FileImportOutcome, ImportProgress } from './motionFiles';

export type ImportRequestBody =
  /** Dropped or picked files (File objects cross to the worker without copying their contents). */
  | { type: 'files'; files: File[] }
  /** playground.importMotion's text. */
  | { type: 'text'; text: string; format: 'bvh' | 'amc'; asfText?: string };

export type ImportRequest = ImportRequestBody & { id: number };

export type ImportResult = FileImportOutcome | Motion;

export type ImportReply =
  | { id: number; ok: true; result: ImportResult }
  | { id: number; ok: false; error: { name: string; message: string } }
  | { id: number; progress: ImportProgress };
