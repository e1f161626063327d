// Reading dropped or picked files (web/runtime/import/motionFiles.ts): the kind from the name or the contents, gzip.
import { gzipSync } from 'node:zlib';
import { describe, expect, it } from 'vitest';
import { baseName, FileImporter, kindFromName, kindFromText, MAX_FILE_BYTES, readTextFile, type ImportProgress } from '../../web/runtime/import/motionFiles';
import { readCorpus } from './corpus';

describe('file kinds', () => {
  it('from names, with or without .gz', () => {
    expect(kindFromName('walk.BVH')).toBe('bvh');
    expect(kindFromName('16_11.amc.gz')).toBe('amc');
    expect(kindFromName('16.asf')).toBe('asf');
    expect(kindFromName('notes.txt')).toBeNull();
  });

  it('from contents when the name does not tell', () => {
    expect(kindFromText('HIERARCHY\nROOT Hips')).toBe('bvh');
    expect(kindFromText('#!OML:ASF x\n:FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0')).toBe('amc');
    expect(kindFromText('# comment\n:version 1.10\n:name VICON\n:units\n')).toBe('asf');
    expect(kindFromText('hello')).toBeNull();
  });

  it('from contents whose lines end in U+2028 or U+2029, as the parsers read them', () => {
    for (const separator of ['\u2028', '\u2029']) {
      expect(kindFromText(['# exported', 'HIERARCHY', 'ROOT Hips'].join(separator))).toBe('bvh');
      expect(kindFromText(['# comment', ':version 1.10', ':units'].join(separator))).toBe('asf');
    }
  });

  it('base names drop the folder, .gz and the extension', () => {
    expect(baseName('dir/16_11.amc.gz')).toBe('16_11');
  });
});

describe('readTextFile', () => {
  const BVH = 'HIERARCHY\nROOT Hips\n';

  it('reads plain text, and gzip by its magic number or by a .gz name', async () => {
    expect(await readTextFile(new File([BVH], 'walk.bvh'))).toEqual({ name: 'walk.bvh', kind: 'bvh', text: BVH });
    expect(await readTextFile(new File([gzipSync(BVH)], 'unnamed'))).toEqual({ name: 'unnamed', kind: 'bvh', text: BVH });
    expect(await readTextFile(new File([gzipSync(BVH)], 'walk.bvh.gz'))).toEqual({ name: 'walk.bvh', kind: 'bvh', text: BVH });
  });

  it('refuses a file over 256 MiB, before or once decompressed, naming the limit', async () => {
    const huge = Object.defineProperty(new File([BVH], 'huge.bvh'), 'size', { value: 300 * 2 ** 20 });
    await expect(readTextFile(huge)).rejects.toThrow(/^huge\.bvh: file too large \(300\.0 MiB; at most 256 MiB\)$/);
    const bomb = new File([gzipSync(Buffer.alloc(MAX_FILE_BYTES + 1, 'x'))], 'bomb.bvh.gz'); // about 260 KB of gzip
    await expect(readTextFile(bomb)).rejects.toThrow(/^bomb\.bvh\.gz: file too large once decompressed \(more than 256 MiB\)$/);
  });

  it('refuses a .gz file that is not gzip', async () => {
    await expect(readTextFile(new File(['not gzip at all'], 'bad.amc.gz'))).rejects.toThrow(/^bad\.amc\.gz: not a valid gzip file/);
  });
});

describe('readTextFile progress', () => {
  const text = 'HIERARCHY\n' + 'x'.repeat(300_000);

  it('reports the share of the bytes read, rising to 1; a gzip file reports it as decompressing', async () => {
    for (const [file, stage] of [
      [new File([text], 'big.bvh'), 'read'],
      [new File([gzipSync(text)], 'big.bvh.gz'), 'decompress'],
    ] as const) {
      const seen: ImportProgress[] = [];
      expect((await readTextFile(file, (p) => seen.push(p))).text).toBe(text);
      expect(seen.length).toBeGreaterThan(0);
      expect(seen.every((p) => p.stage === stage && p.file === file.name)).toBe(true);
      const fractions = seen.map((p) => p.fraction!);
      expect(fractions).toEqual([...fractions].sort((a, b) => a - b));
      expect(fractions.at(-1)).toBe(1);
    }
  });
});

describe('FileImporter', () => {
  const bvh = readCorpus('cmu/bvh/07_04.bvh.gz');
  const asf = readCorpus('cmu/asf/16.asf');
  const amc = readCorpus('cmu/amc/16_11.amc.gz');

  it('imports a .bvh, reporting the read and parse stages', async () => {
    const stages: string[] = [];
    const r = await new FileImporter().importFiles([new File([bvh], '07_04.bvh')], (p) => stages.push(p.stage));
    expect(r.kind).toBe('motion');
    if (r.kind !== 'motion') return;
    expect(r.name).toBe('07_04.bvh');
    expect(r.motion.frames).toBe(450);
    expect(r.motion.contacts?.length).toBe(900);
    expect(r.ignored).toEqual([]);
    expect(stages[0]).toBe('read');
    expect(stages.at(-1)).toBe('parse');
  });

  it('remembers an .asf given alone for the .amc given next', async () => {
    const importer = new FileImporter();
    await expect(importer.importFiles([new File([amc], '16_11.amc')])).rejects.toThrow(/^16_11\.amc needs its skeleton/);
    expect(await importer.importFiles([new File([asf], '16.asf')])).toEqual({ kind: 'skeleton', name: '16.asf' });
    const r = await importer.importFiles([new File([amc], '16_11.amc'), new File(['hello'], 'notes.txt')]);
    expect(r.kind === 'motion' && [r.motion.frames, r.motion.joints[0], r.ignored]).toEqual([534, 'root', ['notes.txt']]);
  });

  it('says which file could not be imported, and refuses files of no known kind', async () => {
    const importer = new FileImporter();
    await expect(importer.importFiles([new File([bvh.slice(0, 2000)], 'broken.bvh')])).rejects.toThrow(/^Could not import broken\.bvh: BVH line \d+: /);
    await expect(importer.importFiles([new File(['hello'], 'notes.txt')])).rejects.toThrow(/^Unsupported file "notes\.txt": drop a \.bvh/);
  });
});
