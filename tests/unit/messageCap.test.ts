// Messages the page shows or the element fires are at most MAX_MESSAGE (300) characters (issue 43 #5): capMessage
// keeps the start and the end of a longer one; the src fetch quotes its URL short.
import { describe, expect, it } from 'vitest';
import { capMessage, MAX_MESSAGE } from '../../web/motion/text';
import { fetchMotionSource } from '../../web/runtime/import/motionSource';

describe('capMessage', () => {
  it('leaves a short message as it is', () => {
    expect(capMessage('src: HTTP 404')).toBe('src: HTTP 404');
    expect(capMessage('x'.repeat(MAX_MESSAGE))).toBe('x'.repeat(MAX_MESSAGE));
  });

  it('cuts a long one to the limit, keeping its start and end around an ellipsis', () => {
    const long = `Could not import ${'n'.repeat(100_000)}.bvh: BVH line 1: expected HIERARCHY`;
    const cut = capMessage(long);
    expect(MAX_MESSAGE).toBe(300);
    expect(cut.length).toBe(300);
    expect(cut.startsWith('Could not import nnn')).toBe(true);
    expect(cut.endsWith('.bvh: BVH line 1: expected HIERARCHY')).toBe(true);
    expect(cut.split('…').length).toBe(2);
    expect(capMessage('abcdefghij', 5)).toBe('abc…j');
  });

  it('never splits a surrogate pair', () => {
    const cut = capMessage('😀'.repeat(1000));
    expect(cut.length).toBeLessThanOrEqual(300);
    expect(cut).not.toMatch(/[\ud800-\udbff](?![\udc00-\udfff])|(?<![\ud800-\udbff])[\udc00-\udfff]/);
  });
});

describe('the src fetch quotes its URL short', () => {
  it('says a long missing URL in a short message', async () => {
    const src = `/nope/${'b'.repeat(100_000)}.bvh`;
    const error = await fetchMotionSource(src, 'https://site.example/', [], async () => new Response('no', { status: 404 })).catch((e: Error) => e);
    expect((error as Error).message).toMatch(/^"https:\/\/site\.example\/nope\/bbbb+…": HTTP 404$/);
    expect((error as Error).message.length).toBeLessThan(150);
  });

  it('says a long URL that is not one in a short message', async () => {
    const error = await fetchMotionSource(`http://[${'x'.repeat(100_000)}`, 'https://site.example/', []).catch((e: Error) => e);
    expect((error as Error).message).toMatch(/^"http:\/\/\[xxx+…" is not a URL$/);
  });
});
