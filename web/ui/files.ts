// Reading dropped or picked files: gzip by magic number or .gz suffix, kind by extension or content.

export type FileKind = 'bvh' | 'amc' | 'asf';

export interface TextFile {
  /** File name without a trailing .gz. */
  name: string;
  kind: FileKind | null;
  text: string;
}

/** Largest file read (after decompression); bigger ones are refused before parsing. */
export const MAX_FILE_BYTES = 256 * 1024 * 1024;

function isGzip(bytes: Uint8Array): boolean {
  return bytes.length >= 2 && bytes[0] === 0x1f && bytes[1] === 0x8b;
}

async function gunzip(bytes: Uint8Array, name: string): Promise<Uint8Array> {
  if (typeof DecompressionStream === 'undefined') throw new Error(`${name}: this browser cannot decompress gzip files`);
  try {
    const stream = new Blob([bytes as BlobPart]).stream().pipeThrough(new DecompressionStream('gzip'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  } catch {
    throw new Error(`${name}: not a valid gzip file (decompression failed)`);
  }
}

export function kindFromName(name: string): FileKind | null {
  const m = /\.(bvh|amc|asf)$/i.exec(name.replace(/\.gz$/i, ''));
  return m ? (m[1].toLowerCase() as FileKind) : null;
}

/** Guesses the kind from the first non-comment line when the name does not tell. */
export function kindFromText(text: string): FileKind | null {
  const head = text.slice(0, 4096).split(/\r\n|\n|\r/).map((l) => l.trim()).filter((l) => l && !l.startsWith('#'));
  const first = head[0] ?? '';
  if (/^HIERARCHY\b/i.test(first)) return 'bvh';
  if (head.some((l) => /^:(FULLY-SPECIFIED|DEGREES|RADIANS)\b/i.test(l)) && !head.some((l) => /^:(root|bonedata)\b/i.test(l))) return 'amc';
  if (head.some((l) => /^:(version|root|bonedata|units)\b/i.test(l))) return 'asf';
  return null;
}

export async function readTextFile(file: File): Promise<TextFile> {
  if (file.size > MAX_FILE_BYTES) throw new Error(`${file.name}: file too large (${(file.size / 1e6).toFixed(0)} MB)`);
  let bytes: Uint8Array = new Uint8Array(await file.arrayBuffer());
  const gz = isGzip(bytes) || /\.gz$/i.test(file.name);
  if (gz) bytes = await gunzip(bytes, file.name);
  if (bytes.length > MAX_FILE_BYTES) throw new Error(`${file.name}: file too large once decompressed`);
  const text = new TextDecoder('utf-8').decode(bytes);
  const name = file.name.replace(/\.gz$/i, '');
  return { name, kind: kindFromName(name) ?? kindFromText(text), text };
}

/** Base name without directory or extension ("16_11.amc" → "16_11"). */
export function baseName(name: string): string {
  return name.replace(/^.*[\\/]/, '').replace(/\.gz$/i, '').replace(/\.[^.]*$/, '');
}
