// The clip's name from the element's `src` (issue 43 #6): a `%` that is no escape keeps the name as written
// instead of failing with "URI malformed".
import { describe, expect, it } from 'vitest';
import { MAX_SOURCE_NAME, sourceName } from '../../web/runtime/import/motionSource';

describe('sourceName', () => {
  it('keeps a stray % as written', () => {
    expect(sourceName('/clips/a%zz.bvh')).toBe('a%zz');
    expect(sourceName('clips/100%.bvh')).toBe('100%');
    expect(sourceName('%E0%A4%A.bvh')).toBe('%E0%A4%A');
  });

  it('decodes valid escapes and drops the query, fragment and extension', () => {
    expect(sourceName('clips/caf%C3%A9.bvh?v=2#x')).toBe('café');
    expect(sourceName('https://site.example/walk.BVH')).toBe('walk');
    expect(sourceName('walk.bvh.gz')).toBe('walk');
    expect(sourceName('a%2Fb.bvh')).toBe('a/b');
  });

  it('names a clip without a file name "motion", and a very long one short', () => {
    expect(sourceName('https://site.example/')).toBe('motion');
    expect(sourceName('.bvh')).toBe('motion');
    const long = sourceName(`/clips/${'b'.repeat(100_000)}end.bvh`);
    expect(long.length).toBe(MAX_SOURCE_NAME);
    expect(long.endsWith('bend')).toBe(true);
  });
});
