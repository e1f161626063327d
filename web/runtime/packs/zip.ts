// A small .zip reader for model packs: the central directory's entries, stored (method 0) or deflated (method 8,
// inflated with the browser's DecompressionStream('deflate-raw')). No ZIP64, no encryption, no multi-disk
// archives: a pack is a handful of small files, and anything else is refused with a message naming it.

export class ZipError extends Error {
  override readonly name = 'ZipError';
}

/** One file of the archive: its path inside it and its bytes. */
export interface ZipFile {
  path: string;
  bytes: Uint8Array;
}

const END_OF_DIRECTORY = 0x06054b50;
const DIRECTORY_ENTRY = 0x02014b50;
const LOCAL_HEADER = 0x04034b50;
/** The end record is 22 bytes plus a comment of at most 65,535. */
const END_SEARCH = 22 + 0xffff;

/** Every file (not folder) in the zip `bytes`, in directory order; throws a ZipError on anything it cannot read. */
export async function readZip(bytes: Uint8Array, name = 'the zip'): Promise<ZipFile[]> {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const fail = (message: string): never => {
    throw new ZipError(`${name}: ${message}`);
  };
  let end = -1;
  for (let i = bytes.length - 22; i >= Math.max(0, bytes.length - END_SEARCH); i--) {
    if (view.getUint32(i, true) === END_OF_DIRECTORY) {
      end = i;
      break;
    }
  }
  if (end < 0) fail('not a zip file (no end of central directory)');
  const count = view.getUint16(end + 10, true);
  const dirSize = view.getUint32(end + 12, true);
  const dirOffset = view.getUint32(end + 16, true);
  if (count === 0xffff || dirOffset === 0xffffffff) fail('ZIP64 archives are not supported');
  if (dirOffset + dirSize > end) fail('its central directory lies outside the file');
  const files: ZipFile[] = [];
  let at = dirOffset;
  for (let k = 0; k < count; k++) {
    if (at + 46 > end || view.getUint32(at, true) !== DIRECTORY_ENTRY) fail(`central directory entry ${k} is damaged`);
    const flags = view.getUint16(at + 8, true);
    const method = view.getUint16(at + 10, true);
    const packed = view.getUint32(at + 20, true);
    const size = view.getUint32(at + 24, true);
    const nameLength = view.getUint16(at + 28, true);
    const extraLength = view.getUint16(at + 30, true);
    const commentLength = view.getUint16(at + 32, true);
    const local = view.getUint32(at + 42, true);
    const path = new TextDecoder().decode(bytes.subarray(at + 46, at + 46 + nameLength));
    at += 46 + nameLength + extraLength + commentLength;
    if (path.endsWith('/')) continue; // a folder
    if (flags & 1) fail(`${path} is encrypted`);
    if (local + 30 > bytes.length || view.getUint32(local, true) !== LOCAL_HEADER) fail(`${path}: its local header is damaged`);
    const start = local + 30 + view.getUint16(local + 26, true) + view.getUint16(local + 28, true);
    if (start + packed > bytes.length) fail(`${path} runs past the end of the file`);
    const data = bytes.subarray(start, start + packed);
    let out: Uint8Array;
    if (method === 0) out = data;
    else if (method === 8) out = await inflateRaw(data).catch((err: unknown) => fail(`${path} could not be inflated (${err instanceof Error ? err.message : String(err)})`));
    else out = fail(`${path} uses compression method ${method} (only stored and deflate are read)`);
    if (out.length !== size) fail(`${path} inflated to ${out.length} bytes, its directory says ${size}`);
    files.push({ path, bytes: out });
  }
  return files;
}

async function inflateRaw(data: Uint8Array): Promise<Uint8Array> {
  const stream = new Blob([data as Uint8Array<ArrayBuffer>]).stream().pipeThrough(new DecompressionStream('deflate-raw'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}
