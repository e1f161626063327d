// `allowed-origins` holds for where the `src` fetch ends after redirects, not only for the URL asked for (issue 43 #9).
import { describe, expect, it } from 'vitest';
import { fetchMotionSource } from '../../web/runtime/import/motionSource';

const PAGE = 'https://site.example/demo/';

/** A fetch answering `text` as if redirected to `finalUrl` (what Response.url says after redirects). */
function redirectedTo(finalUrl: string, text = 'HIERARCHY'): typeof fetch {
  return async () => {
    const response = new Response(text);
    Object.defineProperty(response, 'url', { value: finalUrl });
    return response;
  };
}

describe('a redirected src', () => {
  it('is refused when it ends on an origin that is neither the page\'s nor allowed, naming that origin', async () => {
    await expect(fetchMotionSource('clips/a.bvh', PAGE, [], redirectedTo('https://evil.example:8443/x.bvh'))).rejects.toThrow(
      /^"https:\/\/site\.example\/demo\/clips\/a\.bvh" was redirected to https:\/\/evil\.example:8443, which is not this page's origin or in allowed-origins; the file was not read$/,
    );
    await expect(fetchMotionSource('https://cdn.example/a.bvh', PAGE, ['https://cdn.example'], redirectedTo('http://cdn.example/a.bvh'))).rejects.toThrow(/redirected to http:\/\/cdn\.example,/);
  });

  it('is read when it ends on the page\'s origin or an allowed one', async () => {
    expect(await fetchMotionSource('https://cdn.example/a.bvh', PAGE, ['https://cdn.example'], redirectedTo('https://site.example/b.bvh'))).toBe('HIERARCHY');
    expect(await fetchMotionSource('clips/a.bvh', PAGE, ['https://cdn.example'], redirectedTo('https://cdn.example/b.bvh'))).toBe('HIERARCHY');
    expect(await fetchMotionSource('clips/a.bvh', PAGE, [], redirectedTo(''))).toBe('HIERARCHY'); // no final URL known: the one asked for
  });
});
