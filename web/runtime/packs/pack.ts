// A model pack (`python -m training.own … --out OUT`: training/own/pack.py for --kind locomotion, dance_pack.py for
// --kind dance) as the page takes it: <id>.onnx, <id>.json (the shipped generator's or acLSTM's JSON fields plus
// `pack`), card.md and pose_change.png, from dropped files, a folder, a .zip or a URL. `readPack` checks the JSON with
// its kind's own parser and makes the manifest entry (blob URLs for its files); the model itself is checked by
// loading it in its worker (ui/packInput.ts), so an ONNX whose inputs and outputs disagree with the JSON is refused
// before the pickers list it.

import type { ModelInfo } from '../../model/manifest';
import { parseGeneratorInfo } from '../../model/generatorInfo';
import { parseDanceInfo } from '../aclstm/danceModel';
import { descriptor as dance } from '../aclstm/descriptor';
import { descriptor as generator } from '../generator/descriptor';
import { MAX_SOURCE_BYTES } from '../import/motionSource';
import { readZip } from './zip';

/** A pack's refusal: a short message naming the problem (the shipped models stay). */
export class PackError extends Error {
  override readonly name = 'PackError';
}

/** One file of a pack, by its name (the folder or zip path left off). */
export interface PackFile {
  name: string;
  bytes: Uint8Array;
}

/** A pack ready to register: its manifest entry (files as blob URLs) and what its card shows. */
export interface Pack {
  info: ModelInfo;
  card: { text: string; thumbnail?: string };
  /** The blob URLs it made, revoked when the pack is refused. */
  urls: string[];
}

const baseName = (path: string): string => path.split('/').pop() ?? path;

/** The kinds a pack may hold, each with its JSON's parser: a locomotion generator or a dance model. */
const PACK_KINDS: Record<string, { parse: (raw: unknown, name: string) => unknown; what: string }> = {
  [generator.kind]: { parse: parseGeneratorInfo, what: 'a locomotion pack' },
  [dance.kind]: { parse: parseDanceInfo, what: 'a dance pack' },
};

/** The files of a pack from dropped or picked files: a .zip is opened, anything else taken as it is. */
export async function packFiles(files: readonly { name: string; bytes: Uint8Array }[]): Promise<PackFile[]> {
  const total = files.reduce((n, f) => n + f.bytes.length, 0);
  if (total > MAX_SOURCE_BYTES) throw new PackError(`the pack is ${(total / 1048576).toFixed(1)} MB, over the ${MAX_SOURCE_BYTES / 1048576} MB limit`);
  const out: PackFile[] = [];
  for (const f of files) {
    if (!/\.zip$/i.test(f.name)) {
      out.push({ name: baseName(f.name), bytes: f.bytes });
      continue;
    }
    const inner = await readZip(f.bytes, baseName(f.name)).catch((err: unknown) => {
      throw new PackError(err instanceof Error ? err.message : String(err));
    });
    const unpacked = inner.reduce((n, e) => n + e.bytes.length, 0);
    if (unpacked > MAX_SOURCE_BYTES) throw new PackError(`${baseName(f.name)} unpacks to ${(unpacked / 1048576).toFixed(1)} MB, over the ${MAX_SOURCE_BYTES / 1048576} MB limit`);
    for (const e of inner) if (!baseName(e.path).startsWith('.') && !e.path.startsWith('__MACOSX/')) out.push({ name: baseName(e.path), bytes: e.bytes });
  }
  return out;
}

/** Whether dropped files look like a pack rather than a motion or a character: a .zip, or an .onnx with a .json. */
export function looksLikePack(names: readonly string[]): boolean {
  return names.some((n) => /\.zip$/i.test(n)) || (names.some((n) => /\.onnx$/i.test(n)) && names.some((n) => /\.json$/i.test(n)));
}

function blobUrl(bytes: Uint8Array, type: string, urls: string[]): string {
  const url = URL.createObjectURL(new Blob([bytes as Uint8Array<ArrayBuffer>], { type }));
  urls.push(url);
  return url;
}

/**
 * Checks a pack's files (its JSON with the generator's parser; the ONNX named in it is present) and makes its
 * manifest entry, labelled as the user's. `taken`: ids already listed (a pack may not replace a model).
 */
export function readPack(files: readonly PackFile[], taken: readonly string[]): Pack {
  const jsons = files.filter((f) => /\.json$/i.test(f.name));
  if (jsons.length === 0) throw new PackError('no model JSON in the pack (expected <id>.json beside <id>.onnx)');
  const parsed = jsons.map((f) => ({ f, raw: parseJson(f) }));
  const withPack = parsed.filter((p) => typeof p.raw === 'object' && p.raw !== null && 'pack' in p.raw);
  const chosen = withPack[0] ?? (parsed.length === 1 ? parsed[0] : undefined);
  if (!chosen) throw new PackError(`none of ${jsons.map((j) => j.name).join(', ')} is a pack's JSON (no "pack" field)`);
  const raw = chosen.raw as Record<string, unknown>;
  const kind = typeof raw.kind === 'string' && Object.hasOwn(PACK_KINDS, raw.kind) ? PACK_KINDS[raw.kind] : undefined;
  if (!kind) {
    const kinds = Object.entries(PACK_KINDS).map(([k, v]) => `"${k}" (${v.what})`).join(' or ');
    const got = raw.kind === undefined ? 'it has none' : `got ${JSON.stringify(raw.kind)?.slice(0, 40)}`;
    throw new PackError(`${chosen.f.name}: kind must be ${kinds}; ${got}`);
  }
  try {
    kind.parse(raw, chosen.f.name);
  } catch (err) {
    throw new PackError(short(err instanceof Error ? err.message : String(err)));
  }
  const id = raw.id;
  if (typeof id !== 'string' || !/^[A-Za-z0-9][\w.-]{0,63}$/.test(id)) throw new PackError(`${chosen.f.name}: id must be a short name of letters, digits, - _ or ., got ${JSON.stringify(id)?.slice(0, 40)}`);
  if (taken.includes(id)) throw new PackError(`a model "${id}" is already listed: rename the pack (--out) to load it too`);
  const onnxName = typeof raw.file === 'string' ? baseName(raw.file) : `${id}.onnx`;
  const onnx = files.find((f) => f.name === onnxName);
  if (!onnx) throw new PackError(`the pack has no ${onnxName} (named by ${chosen.f.name})`);
  const pack = (raw.pack ?? {}) as { card?: unknown; thumbnail?: unknown; data_folder?: unknown; data_minutes?: unknown; licence?: unknown; commercial?: unknown };
  const cardName = typeof pack.card === 'string' ? baseName(pack.card) : 'card.md';
  const thumbName = typeof pack.thumbnail === 'string' ? baseName(pack.thumbnail) : 'pose_change.png';
  const card = files.find((f) => f.name === cardName);
  const thumb = files.find((f) => f.name === thumbName);
  const urls: string[] = [];
  const info: ModelInfo = {
    id,
    kind: raw.kind as string,
    skeleton: 'cmu-canonical',
    fps: raw.fps as number,
    ...(Array.isArray(raw.styles) ? { styles: raw.styles as string[] } : {}),
    bytes: onnx.bytes.length,
    files: { model: blobUrl(onnx.bytes, 'application/octet-stream', urls), info: blobUrl(chosen.f.bytes, 'application/json', urls) },
    label: `${id} (your model)`,
    data: typeof pack.data_folder === 'string' ? `your folder ${pack.data_folder}${typeof pack.data_minutes === 'number' ? ` (${pack.data_minutes.toFixed(1)} minutes)` : ''}` : 'your own motion',
    licence: typeof pack.licence === 'string' && pack.licence.trim() ? pack.licence.slice(0, 200) : "your data's own terms",
    // Trained with --non-commercial (e.g. on the Bandai Namco set): labelled so in the pickers.
    ...(pack.commercial === false ? { commercial: false } : {}),
  };
  return {
    info,
    card: { text: card ? new TextDecoder().decode(card.bytes) : '(the pack has no card.md)', ...(thumb ? { thumbnail: blobUrl(thumb.bytes, 'image/png', urls) } : {}) },
    urls,
  };
}

function parseJson(f: PackFile): unknown {
  try {
    return JSON.parse(new TextDecoder().decode(f.bytes));
  } catch (err) {
    throw new PackError(`${f.name} is not valid JSON (${short(err instanceof Error ? err.message : String(err), 120)})`);
  }
}

/** A message cut to fit the page's 300-character limit. */
export function short(message: string, max = 280): string {
  return message.length > max ? `${message.slice(0, max - 1)}…` : message;
}
