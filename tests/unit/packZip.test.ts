// The pack zip reader (web/runtime/packs/zip.ts) on archives written here: stored and deflated entries, folders,
// and the refusals (not a zip, unsupported method, damaged entry, size mismatch).
import { deflateRawSync } from 'node:zlib';
import { describe, expect, it } from 'vitest';
import { readZip, ZipError } from '../../web/runtime/packs/zip';

interface Entry {
  path: string;
  data: Uint8Array;
  method?: 0 | 8 | 12;
  /** Overrides the uncompressed size written in the directory. */
  size?: number;
}

/** A minimal zip (no CRC checked by the reader, so 0 is written). */
function makeZip(entries: Entry[]): Uint8Array {
  const locals: Uint8Array[] = [];
  const dir: Uint8Array[] = [];
  let offset = 0;
  for (const e of entries) {
    const name = new TextEncoder().encode(e.path);
    const method = e.method ?? 0;
    const packed = method === 8 ? new Uint8Array(deflateRawSync(e.data)) : e.data;
    const local = new Uint8Array(30 + name.length + packed.length);
    const lv = new DataView(local.buffer);
    lv.setUint32(0, 0x04034b50, true);
    lv.setUint16(8, method, true);
    lv.setUint32(18, packed.length, true);
    lv.setUint32(22, e.size ?? e.data.length, true);
    lv.setUint16(26, name.length, true);
    local.set(name, 30);
    local.set(packed, 30 + name.length);
    const d = new Uint8Array(46 + name.length);
    const dv = new DataView(d.buffer);
    dv.setUint32(0, 0x02014b50, true);
    dv.setUint16(10, method, true);
    dv.setUint32(20, packed.length, true);
    dv.setUint32(24, e.size ?? e.data.length, true);
    dv.setUint16(28, name.length, true);
    dv.setUint32(42, offset, true);
    d.set(name, 46);
    locals.push(local);
    dir.push(d);
    offset += local.length;
  }
  const dirSize = dir.reduce((n, d) => n + d.length, 0);
  const end = new Uint8Array(22);
  const ev = new DataView(end.buffer);
  ev.setUint32(0, 0x06054b50, true);
  ev.setUint16(8, entries.length, true);
  ev.setUint16(10, entries.length, true);
  ev.setUint32(12, dirSize, true);
  ev.setUint32(16, offset, true);
  const out = new Uint8Array(offset + dirSize + 22);
  let at = 0;
  for (const part of [...locals, ...dir, end]) {
    out.set(part, at);
    at += part.length;
  }
  return out;
}

const text = (s: string) => new TextEncoder().encode(s);

describe('readZip', () => {
  it('reads stored and deflated files and skips folders', async () => {
    const big = text('walk '.repeat(2000));
    const files = await readZip(makeZip([
      { path: 'my-walks/', data: new Uint8Array() },
      { path: 'my-walks/card.md', data: text('# my walks\n') },
      { path: 'my-walks/my-walks.json', data: big, method: 8 },
    ]));
    expect(files.map((f) => f.path)).toEqual(['my-walks/card.md', 'my-walks/my-walks.json']);
    expect(new TextDecoder().decode(files[0].bytes)).toBe('# my walks\n');
    expect(files[1].bytes).toEqual(big);
  });

  it('refuses what it cannot read, naming the file', async () => {
    await expect(readZip(text('not a zip at all, just text'), 'pack.zip')).rejects.toThrow(/^pack\.zip: not a zip file/);
    await expect(readZip(makeZip([{ path: 'a.onnx', data: text('x'), method: 12 }]))).rejects.toThrow(/a\.onnx uses compression method 12/);
    await expect(readZip(makeZip([{ path: 'a.json', data: text('abc'), size: 5 }]))).rejects.toThrow(/a\.json inflated to 3 bytes, its directory says 5/);
    const damaged = makeZip([{ path: 'a.json', data: text('abc') }]);
    damaged[0] = 0; // the local header's signature
    await expect(readZip(damaged)).rejects.toBeInstanceOf(ZipError);
    const corrupt = makeZip([{ path: 'b.json', data: text('hello hello hello'), method: 8 }]);
    corrupt.fill(0xff, 30 + 'b.json'.length, 30 + 'b.json'.length + 4);
    await expect(readZip(corrupt)).rejects.toThrow(/b\.json could not be inflated/);
  });
});
