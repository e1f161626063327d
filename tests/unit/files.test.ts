// Reading dropped or picked files (web/ui/files.ts): the kind from the name or the contents, gzip.
import { gzipSync } from 'node:zlib';
import { describe, expect, it } from 'vitest';
import { baseName, kindFromName, kindFromText, readTextFile } from '../../web/ui/files';

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

  it('refuses a .gz file that is not gzip', async () => {
    await expect(readTextFile(new File(['not gzip at all'], 'bad.amc.gz'))).rejects.toThrow(/^bad\.amc\.gz: not a valid gzip file/);
  });
});
