// Test helper: reads files from the read-only corpus at ../shared/mocap (relative to the repo root).
import { existsSync, readFileSync } from 'node:fs';
import { gunzipSync } from 'node:zlib';
import { fileURLToPath } from 'node:url';

export const REPO_ROOT = fileURLToPath(new URL('../../', import.meta.url));
export const CORPUS_ROOT = fileURLToPath(new URL('../../../shared/mocap/', import.meta.url));

/** Text of a corpus file given relative to ../shared/mocap; .gz files are decompressed. */
export function readCorpus(relativePath: string): string {
  const bytes = readFileSync(CORPUS_ROOT + relativePath);
  return (relativePath.endsWith('.gz') ? gunzipSync(bytes) : bytes).toString('utf8');
}

export function repoFileExists(relativePath: string): boolean {
  return existsSync(REPO_ROOT + relativePath);
}

export function readRepoFile(relativePath: string): string {
  return readFileSync(REPO_ROOT + relativePath, 'utf8');
}
