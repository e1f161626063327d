// Issue 43 #12: the `src` size limit reads the same in its errors and in docs/api.md (32 MiB, the real limit; the
// errors said "33 MB" where the docs said 32 MB).
import { describe, expect, it } from 'vitest';
import { fetchMotionSource, MAX_SOURCE_BYTES } from '../../web/runtime/import/motionSource';
import { readRepoFile } from './corpus';

const page = 'https://example.org/index.html';
const LIMIT = `${MAX_SOURCE_BYTES / 2 ** 20} MiB`;

async function failure(response: Response): Promise<string> {
  try {
    await fetchMotionSource('a.bvh', page, [], async () => response);
  } catch (e) {
    return (e as Error).message;
  }
  return 'no error';
}

describe('the src size limit', () => {
  it('is 32 MiB in both size errors and in docs/api.md', async () => {
    expect(LIMIT).toBe('32 MiB');
    const declared = new Response('x', { headers: { 'content-length': String(40 * 2 ** 20) } });
    expect(await failure(declared)).toMatch(/is 40\.0 MiB; the limit is 32 MiB$/);
    expect(await failure(new Response(new Uint8Array(MAX_SOURCE_BYTES + 1)))).toMatch(/larger than the 32 MiB limit$/);
    const docs = readRepoFile('docs/api.md');
    expect(docs).toContain(`at most ${LIMIT}`);
    expect(docs).not.toMatch(/at most 3[23] MB/);
  });
});
