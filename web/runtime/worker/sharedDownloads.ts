// Model files fetched once per page. Workers do not fetch ONNX files or the onnxruntime wasm themselves:
// they ask the page (a `download` message, ortWorker.ts), and the page answers every worker that asks for
// the same URL from one fetch, so several <motion-playground> elements, or several workers of one element,
// share each download. A failed fetch is forgotten, so a later ask tries again.

/** Worker → page: fetch `url` for me. */
export interface DownloadRequest {
  type: 'download';
  download: number;
  url: string;
}

/** Page → worker: the bytes of a `download`, or why there are none. */
export type DownloadReply = { type: 'downloaded'; download: number; bytes: ArrayBuffer } | { type: 'downloaded'; download: number; error: string };

const downloads = new Map<string, Promise<ArrayBuffer>>();

/** The bytes at `url`, fetched once for the page; rejects with a short reason ("HTTP 404 Not Found"). */
export function sharedDownload(url: string): Promise<ArrayBuffer> {
  const known = downloads.get(url);
  if (known) return known;
  const started = fetchBytes(url);
  downloads.set(url, started);
  started.catch(() => downloads.delete(url));
  return started;
}

async function fetchBytes(url: string): Promise<ArrayBuffer> {
  let response: Response;
  try {
    response = await fetch(url);
  } catch (err) {
    throw new Error(`could not fetch (${err instanceof Error ? err.message : String(err)})`);
  }
  if (!response.ok) throw new Error(`HTTP ${response.status} ${response.statusText}`);
  // Dev servers answer unknown paths with the app's index.html; say so rather than "protobuf parsing failed".
  if (response.headers.get('content-type')?.includes('text/html')) throw new Error('got an HTML page, not a model file (wrong URL?)');
  return response.arrayBuffer();
}

/** Answers a worker's `download` message (the bytes are copied to it; the page keeps its own). */
export function answerDownload(worker: Worker, request: DownloadRequest): void {
  sharedDownload(request.url).then(
    (bytes) => worker.postMessage({ type: 'downloaded', download: request.download, bytes } satisfies DownloadReply),
    (err: unknown) => worker.postMessage({ type: 'downloaded', download: request.download, error: err instanceof Error ? err.message : String(err) } satisfies DownloadReply),
  );
}
