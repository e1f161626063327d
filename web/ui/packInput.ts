// Loading a user's model pack (runtime/packs/pack.ts) into the page: from dropped files (a folder, its .zip, or
// its files), a URL of the pack's .json (its .onnx, card.md and pose_change.png beside it; `?models=`, the
// element's `models` attribute, playground.loadModels) under the same origin and size rules as `src`. The model
// is loaded once in its own worker to check it (the worker runs one step on the JSON's sizes: an ONNX of the
// wrong shape fails there) before the registry lists it; a refused pack leaves the shipped models as they were.

import { fetchSourceBytes } from '../runtime/import/motionSource';
import { PackError, packFiles, readPack, short, type PackFile } from '../runtime/packs/pack';
import { Registry } from '../runtime/registry';
import type { ModelInfo } from '../model/manifest';

/** What loadModels takes: the URL of a pack's .json, its files (or a .zip among them), or one .zip. */
export type PackSource = string | readonly File[] | Blob;

/** The page's side: the models listed so far, adding one, and the rules URLs are fetched under. */
export interface PackHost {
  registryIds(): string[];
  addModel(info: ModelInfo, card: { text: string; thumbnail?: string }): void;
  pageHref(): string;
  allowedOrigins(): readonly string[];
}

/** Loads a pack and registers its model; resolves to the model's id, or rejects with a PackError (≤ 300 chars). */
export async function loadPack(source: PackSource, host: PackHost): Promise<string> {
  const files = await gather(source, host);
  const pack = readPack(await packFiles(files), host.registryIds());
  try {
    await checkModel(pack.info);
  } catch (err) {
    for (const url of pack.urls) URL.revokeObjectURL(url);
    throw new PackError(short(`the pack's model does not load: ${err instanceof Error ? err.message : String(err)}`));
  }
  host.addModel(pack.info, pack.card);
  return pack.info.id;
}

/** Loads the model in a worker of its own (the worker checks the ONNX against the JSON with one step), then stops it. */
async function checkModel(info: ModelInfo): Promise<void> {
  const model = new Registry([info]).find(info.id);
  if (!model) throw new Error(`no model of kind "${info.kind}"`);
  const client = model.descriptor.createClient(info, 1);
  try {
    await client.init();
  } finally {
    client.dispose();
  }
}

async function gather(source: PackSource, host: PackHost): Promise<PackFile[]> {
  if (typeof source === 'string') return fetchPack(source, host);
  const list = typeof Blob !== 'undefined' && source instanceof Blob ? [source] : (source as readonly File[]);
  if (!Array.isArray(list) || list.length === 0) throw new PackError('loadModels takes a URL of a pack\'s .json, its files, or its .zip');
  return Promise.all(
    list.map(async (f, i) => {
      if (!(f instanceof Blob)) throw new PackError(`loadModels: item ${i} is not a File or Blob`);
      const name = (f as File).name || (f.type === 'application/zip' || list.length === 1 ? 'pack.zip' : `file${i}`);
      if (f.size > 32 * 1024 * 1024) throw new PackError(`${name} is over the 32 MB limit`);
      return { name, bytes: new Uint8Array(await f.arrayBuffer()) };
    }),
  );
}

/** The pack at `url` (its .json, or a .zip): the .onnx named in the JSON beside it, and its card and plot if there. */
async function fetchPack(url: string, host: PackHost): Promise<PackFile[]> {
  const get = (u: string) => fetchSourceBytes(u, host.pageHref(), host.allowedOrigins());
  const name = (u: string) => u.replace(/[?#].*$/s, '').split('/').pop() || 'pack';
  const bytes = await get(url);
  if (/\.zip$/i.test(name(url))) return [{ name: name(url), bytes }];
  let raw: { id?: unknown; file?: unknown; pack?: { card?: unknown; thumbnail?: unknown } };
  try {
    raw = JSON.parse(new TextDecoder().decode(bytes)) as typeof raw;
  } catch {
    throw new PackError(`${short(name(url), 80)} is not valid JSON`);
  }
  const base = new URL(url, host.pageHref());
  const beside = (file: unknown, fallback: string) => new URL(typeof file === 'string' ? file : fallback, base).href;
  const onnxUrl = beside(raw?.file, `${String(raw?.id)}.onnx`);
  const files: PackFile[] = [{ name: name(url), bytes }, { name: name(onnxUrl), bytes: await get(onnxUrl) }];
  for (const extra of [beside(raw?.pack?.card, 'card.md'), beside(raw?.pack?.thumbnail, 'pose_change.png')]) {
    const got = await get(extra).catch(() => null); // the card is optional
    if (got) files.push({ name: name(extra), bytes: got });
  }
  return files;
}

/** The files of a drop, folders walked (DataTransferItem.webkitGetAsEntry), or null when none is a folder. */
export async function droppedFolderFiles(items: DataTransferItemList): Promise<File[] | null> {
  const entries = [...items].map((i) => i.webkitGetAsEntry?.()).filter((e): e is FileSystemEntry => !!e);
  if (!entries.some((e) => e.isDirectory)) return null;
  const files: File[] = [];
  const walk = async (entry: FileSystemEntry): Promise<void> => {
    if (entry.isFile) {
      files.push(await new Promise<File>((resolve, reject) => (entry as FileSystemFileEntry).file(resolve, reject)));
      return;
    }
    const reader = (entry as FileSystemDirectoryEntry).createReader();
    for (;;) {
      const batch = await new Promise<FileSystemEntry[]>((resolve, reject) => reader.readEntries(resolve, reject));
      if (batch.length === 0) break;
      for (const e of batch) await walk(e);
    }
  };
  for (const e of entries) await walk(e);
  return files;
}

/** Shows a pack's card: its text and its pose-change plot, in a dialog inside `root`. */
export function showCard(root: ShadowRoot | Document, parent: HTMLElement, id: string, card: { text: string; thumbnail?: string }): void {
  let dialog = root.querySelector<HTMLDialogElement>('dialog.pack-card');
  if (!dialog) {
    dialog = document.createElement('dialog');
    dialog.className = 'pack-card';
    dialog.style.cssText = 'max-width:min(90vw,720px);max-height:85vh;overflow:auto;font:13px system-ui;';
    parent.append(dialog);
  }
  const title = document.createElement('h3');
  title.textContent = `${id} (your model)`;
  const text = document.createElement('pre');
  text.style.whiteSpace = 'pre-wrap';
  text.textContent = card.text;
  const close = document.createElement('button');
  close.textContent = 'Close';
  close.addEventListener('click', () => dialog.close());
  const parts: HTMLElement[] = [title, text];
  if (card.thumbnail) {
    const img = document.createElement('img');
    img.src = card.thumbnail;
    img.alt = 'pose change per second of a 10,000-frame run';
    img.style.maxWidth = '100%';
    parts.push(img);
  }
  dialog.replaceChildren(...parts, close);
  dialog.showModal();
}
