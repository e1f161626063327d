// Dropped or picked motion-capture files, read and imported in the import worker (import.worker.ts):
// gzip by magic number or .gz suffix, kind by extension or content, the .amc's skeleton chosen among the
// files given (or remembered from an earlier drop), then parsed with motion/io importMotion.
import { importMotion } from '../../motion/io';
import { splitLines } from '../../motion/text';
import type { Motion } from '../../motion/types';
import { throwIfCancelled } from '../worker/cancellation';

export type FileKind = 'bvh' | 'amc' | 'asf';

export interface TextFile {
  /** File name without a trailing .gz. */
  name: string;
  kind: FileKind | null;
  text: string;
}

/** Largest file read (after decompression); bigger ones are refused before parsing. */
export const MAX_FILE_BYTES = 256 * 1024 * 1024;
const MIB = 1024 * 1024;

/** How far an import has got: reading (or decompressing) a file, with the share of its bytes read; then parsing it. */
export interface ImportProgress {
  stage: 'read' | 'decompress' | 'parse';
  /** The file's name as given. */
  file: string;
  /** read and decompress: 0…1 of the file's (compressed) bytes. */
  fraction?: number;
}

export type ProgressListener = (progress: ImportProgress) => void;

/** What a drop or pick of files gave: a motion to show, or only a skeleton (.asf) kept for a later .amc. */
export type FileImportOutcome = { kind: 'motion'; motion: Motion; name: string; ignored: string[] } | { kind: 'skeleton'; name: string };

function isGzip(bytes: Uint8Array): boolean {
  return bytes.length >= 2 && bytes[0] === 0x1f && bytes[1] === 0x8b;
}

export function kindFromName(name: string): FileKind | null {
  const m = /\.(bvh|amc|asf)$/i.exec(name.replace(/\.gz$/i, ''));
  return m ? (m[1].toLowerCase() as FileKind) : null;
}

/** Guesses the kind from the first non-comment lines (broken as the parsers break them) when the name does not tell. */
export function kindFromText(text: string): FileKind | null {
  const head = splitLines(text.slice(0, 4096)).map((l) => l.trim()).filter((l) => l && !l.startsWith('#'));
  const first = head[0] ?? '';
  if (/^HIERARCHY\b/i.test(first)) return 'bvh';
  if (head.some((l) => /^:(FULLY-SPECIFIED|DEGREES|RADIANS)\b/i.test(l)) && !head.some((l) => /^:(root|bonedata)\b/i.test(l))) return 'amc';
  if (head.some((l) => /^:(version|root|bonedata|units)\b/i.test(l))) return 'asf';
  return null;
}

/** Base name without directory or extension ("16_11.amc" → "16_11"). */
export function baseName(name: string): string {
  return name.replace(/^.*[\\/]/, '').replace(/\.gz$/i, '').replace(/\.[^.]*$/, '');
}

/**
 * A file's text, gunzipped when it is gzip, read as a stream: `onProgress` hears the share of the file's
 * bytes read (stage "decompress" for gzip), and a gzip file stops as soon as it decompresses past
 * MAX_FILE_BYTES. When `signal` aborts, reading stops at the next chunk with a CancelledError.
 */
export async function readTextFile(file: File, onProgress?: ProgressListener, signal?: AbortSignal): Promise<TextFile> {
  if (file.size > MAX_FILE_BYTES) throw new Error(`${file.name}: file too large (${(file.size / MIB).toFixed(1)} MiB; at most ${MAX_FILE_BYTES / MIB} MiB)`);
  const gz = isGzip(new Uint8Array(await file.slice(0, 2).arrayBuffer())) || /\.gz$/i.test(file.name);
  if (gz && typeof DecompressionStream === 'undefined') throw new Error(`${file.name}: this browser cannot decompress gzip files`);
  const stage = gz ? 'decompress' : 'read';
  let read = 0, reported = -1;
  const counted = file.stream().pipeThrough(
    new TransformStream<Uint8Array, Uint8Array>({
      transform(chunk, controller) {
        read += chunk.length;
        const fraction = file.size ? read / file.size : 1;
        if (fraction - reported >= 0.01) {
          reported = fraction;
          onProgress?.({ stage, file: file.name, fraction });
        }
        controller.enqueue(chunk);
      },
    }),
  );
  const bytes = gz ? counted.pipeThrough(new DecompressionStream('gzip') as ReadableWritablePair<Uint8Array, Uint8Array>) : counted;
  const reader = bytes.getReader();
  const decoder = new TextDecoder('utf-8');
  const parts: string[] = [];
  let size = 0;
  for (;;) {
    let chunk: ReadableStreamReadResult<Uint8Array>;
    try {
      chunk = await reader.read();
    } catch {
      throw new Error(gz ? `${file.name}: not a valid gzip file (decompression failed)` : `${file.name}: the file could not be read`);
    }
    if (chunk.done) break;
    size += chunk.value.length;
    try {
      if (signal) throwIfCancelled(signal);
      if (size > MAX_FILE_BYTES) throw new Error(`${file.name}: file too large once decompressed (more than ${MAX_FILE_BYTES / MIB} MiB)`);
    } catch (e) {
      void reader.cancel();
      throw e;
    }
    parts.push(decoder.decode(chunk.value, { stream: true }));
  }
  parts.push(decoder.decode());
  const text = parts.join('');
  const name = file.name.replace(/\.gz$/i, '');
  return { name, kind: kindFromName(name) ?? kindFromText(text), text };
}

/**
 * Imports dropped or picked files: one .bvh, or an .amc with its .asf (given together, or the .asf in an
 * earlier call: the last skeleton given is remembered). Failures throw an Error whose message is meant
 * for the page as it is. `signal` stops the reading (readTextFile) and, once all is read, the import
 * before its parse; a cancelled import leaves the remembered skeleton as it was.
 */
export class FileImporter {
  private lastAsf: TextFile | null = null;

  async importFiles(files: File[], onProgress?: ProgressListener, signal?: AbortSignal): Promise<FileImportOutcome> {
    const read: TextFile[] = [];
    for (const f of files) read.push(await readTextFile(f, onProgress, signal));
    if (signal) throwIfCancelled(signal);
    const unknown = read.filter((f) => f.kind === null);
    const asfs = read.filter((f) => f.kind === 'asf');
    const motions = read.filter((f) => f.kind === 'bvh' || f.kind === 'amc');
    if (unknown.length && !motions.length && !asfs.length) {
      throw new Error(`Unsupported file ${unknown.map((f) => `"${f.name}"`).join(', ')}: drop a .bvh, or an .asf with an .amc (gzipped .gz files are fine).`);
    }
    if (!motions.length) {
      this.lastAsf = asfs[asfs.length - 1];
      return { kind: 'skeleton', name: this.lastAsf.name };
    }
    const file = motions[0];
    let asf: TextFile | null = null;
    if (file.kind === 'amc') {
      // Prefer the subject's skeleton by CMU naming (16_11.amc ↔ 16.asf), else the last one given.
      const subject = baseName(file.name).split('_')[0];
      asf = asfs.find((a) => baseName(a.name) === subject) ?? asfs[asfs.length - 1] ?? this.lastAsf;
      if (!asf) throw new Error(`${file.name} needs its skeleton: drop the subject's .asf file together with the .amc (or before it).`);
    }
    if (asfs.length) this.lastAsf = asf && asfs.includes(asf) ? asf : asfs[asfs.length - 1];
    onProgress?.({ stage: 'parse', file: file.name });
    let motion: Motion;
    try {
      motion = importMotion(file.text, file.kind as 'bvh' | 'amc', asf?.text);
    } catch (e) {
      throw new Error(`Could not import ${file.name}${asf ? ` (skeleton ${asf.name})` : ''}: ${e instanceof Error ? e.message || e.name : String(e)}`, { cause: e });
    }
    const ignored = [...motions.slice(1), ...unknown].map((f) => f.name);
    return { kind: 'motion', motion, name: file.name, ignored };
  }
}
