// Fetching the <motion-playground> element's `src` (and its `character` file, fetchSourceBytes): only from the page's own origin or an allowed
// list, over http(s), at most MAX_SOURCE_BYTES, gunzipped when gzipped. Errors say why, briefly, quoting the URL
// short (MAX_URL_QUOTE characters): a `src` may be any length.

import { quoteInput } from '../../motion/text';

/** Longest stretch of a URL an error message quotes. */
export const MAX_URL_QUOTE = 120;

/** A URL as a message quotes it: in quotes, cut after MAX_URL_QUOTE characters. */
function quoteUrl(url: string): string {
  return quoteInput(url, MAX_URL_QUOTE);
}

/** Bytes in a mebibyte: the limit is 32 MiB (33.6 million bytes; "33 MB" before, where the docs said 32). */
const MIB = 1024 * 1024;
export const MAX_SOURCE_BYTES = 32 * 1024 * 1024;

/** An origin as the allowed list compares it ("https://example.org"); null for text that is not one. */
function originOf(text: string): string | null {
  try {
    const u = new URL(text);
    return u.protocol === 'http:' || u.protocol === 'https:' ? u.origin : null;
  } catch {
    return null;
  }
}

/** Checks `src` against the rules; returns the absolute URL to fetch. */
export function checkSourceUrl(src: string, pageHref: string, allowed: readonly string[]): URL {
  let url: URL;
  try {
    url = new URL(src, pageHref);
  } catch {
    throw new Error(`${quoteUrl(src)} is not a URL`);
  }
  if (url.protocol !== 'http:' && url.protocol !== 'https:') throw new Error(`only http(s) URLs are fetched, not ${url.protocol}`);
  if (!originAllowed(url.origin, pageHref, allowed)) {
    throw new Error(`${url.origin} is not this page's origin or in allowed-origins; the file was not fetched`);
  }
  return url;
}

/** Whether a file may come from `origin`: the page's own, or one in the allowed list. */
function originAllowed(origin: string, pageHref: string, allowed: readonly string[]): boolean {
  return origin === new URL(pageHref).origin || allowed.map(originOf).includes(origin);
}

/** How long the `src` fetch may take, from the request to the last byte, before it fails with an error. */
export const SOURCE_TIMEOUT_MS = 30_000;

/**
 * The text of the BVH at `src`, checked and size-limited. A redirect must end on an allowed origin too (the
 * final URL is checked by the same rule, so an open redirect on an allowed site reaches no other), and the
 * whole fetch fails after `timeoutMs` (SOURCE_TIMEOUT_MS) without an answer.
 */
export async function fetchMotionSource(src: string, pageHref: string, allowed: readonly string[], fetchFn: typeof fetch = fetch, timeoutMs = SOURCE_TIMEOUT_MS): Promise<string> {
  return fetchWithin(src, pageHref, allowed, timeoutMs, async (url, signal) => {
    const bytes = await fetchChecked(url, pageHref, allowed, fetchFn, signal);
    const gzipped = bytes.length > 2 && bytes[0] === 0x1f && bytes[1] === 0x8b;
    if (!gzipped) return new TextDecoder().decode(bytes);
    const unzipped = new Response(new Blob([bytes as BlobPart]).stream().pipeThrough(new DecompressionStream('gzip')));
    return new TextDecoder().decode(await readLimited(unzipped, quoteUrl(url.href)));
  });
}

/**
 * The bytes at `src` as they are (no gunzip), under the same rules as fetchMotionSource: allowed origins, the final
 * URL after redirects checked, MAX_SOURCE_BYTES, the `timeoutMs` deadline. (The `character` attribute's file.)
 */
export function fetchSourceBytes(src: string, pageHref: string, allowed: readonly string[], fetchFn: typeof fetch = fetch, timeoutMs = SOURCE_TIMEOUT_MS): Promise<Uint8Array> {
  return fetchWithin(src, pageHref, allowed, timeoutMs, (url, signal) => fetchChecked(url, pageHref, allowed, fetchFn, signal));
}

/** Runs `read` on the checked URL of `src`, failing after `timeoutMs` (its signal aborts then). */
async function fetchWithin<T>(src: string, pageHref: string, allowed: readonly string[], timeoutMs: number, read: (url: URL, signal: AbortSignal) => Promise<T>): Promise<T> {
  const url = checkSourceUrl(src, pageHref, allowed);
  const controller = new AbortController();
  let timer: ReturnType<typeof setTimeout> | undefined;
  const deadline = new Promise<never>((_, reject) => {
    timer = setTimeout(() => {
      const late = new Error(`${quoteUrl(url.href)}: no answer within ${timeoutMs / 1000} s`);
      reject(late); // first, so the fetch failing as it is aborted is not what is said
      controller.abort(late);
    }, timeoutMs);
  });
  try {
    // Raced as well as aborted: a fetch that ignores its signal cannot hold the element either.
    return await Promise.race([read(url, controller.signal), deadline]);
  } finally {
    clearTimeout(timer);
  }
}

/** The response's bytes, checked (final origin, HTTP status, size). */
async function fetchChecked(url: URL, pageHref: string, allowed: readonly string[], fetchFn: typeof fetch, signal: AbortSignal): Promise<Uint8Array> {
  let response: Response;
  try {
    response = await fetchFn(url.href, { credentials: 'same-origin', signal });
  } catch (e) {
    throw new Error(`could not fetch ${quoteUrl(url.href)} (${e instanceof Error ? e.message : String(e)})`);
  }
  if (response.url) {
    // Where the redirects (if any) ended: the file is read only from an allowed origin.
    const final = originOf(response.url);
    if (final === null || !originAllowed(final, pageHref, allowed)) {
      response.body?.cancel().catch(() => undefined);
      throw new Error(`${quoteUrl(url.href)} was redirected to ${final ?? quoteUrl(response.url)}, which is not this page's origin or in allowed-origins; the file was not read`);
    }
  }
  if (!response.ok) throw new Error(`${quoteUrl(url.href)}: HTTP ${response.status}`);
  const declared = Number(response.headers.get('content-length'));
  if (declared > MAX_SOURCE_BYTES) throw new Error(`${quoteUrl(url.href)} is ${(declared / MIB).toFixed(1)} MiB; the limit is ${MAX_SOURCE_BYTES / MIB} MiB`);
  return readLimited(response, quoteUrl(url.href));
}

async function readLimited(response: Response, what: string): Promise<Uint8Array> {
  if (!response.body) return new Uint8Array(await response.arrayBuffer());
  const reader = response.body.getReader();
  const parts: Uint8Array[] = [];
  let total = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    total += value.length;
    if (total > MAX_SOURCE_BYTES) {
      await reader.cancel();
      throw new Error(`${what} is larger than the ${MAX_SOURCE_BYTES / MIB} MiB limit`);
    }
    parts.push(value);
  }
  const out = new Uint8Array(total);
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  return out;
}

/** Longest name a `src` gives its clip (MAX_SOURCE_NAME characters, cut in the middle). */
export const MAX_SOURCE_NAME = 120;

/**
 * The clip's name from its `src`: the last path segment, without query, fragment or .bvh(.gz), percent-decoded
 * where that is valid (`caf%C3%A9.bvh` is "café"; a stray `%` as in `a%zz.bvh` stays as written), "motion"
 * when nothing is left.
 */
export function sourceName(src: string): string {
  const file = src.replace(/[?#].*$/s, '').split('/').pop() ?? '';
  let name: string;
  try {
    name = decodeURIComponent(file);
  } catch {
    name = file; // not a valid escape: the name as written
  }
  name = name.replace(/\.bvh(\.gz)?$/i, '');
  if (name.length > MAX_SOURCE_NAME) name = `${name.slice(0, MAX_SOURCE_NAME - 41)}…${name.slice(-40)}`;
  return name || 'motion';
}
