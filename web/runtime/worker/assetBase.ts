// Where the shipped models (models/…) are fetched from: next to the <motion-playground> module
// (web/motion-playground.ts sets it), so a built folder copied to any static host finds them from
// any page; else against the page.

let base: string | null = null;

/** Model files resolve against `url` from now on. */
export function setAssetBase(url: string): void {
  base = new URL(url, document.baseURI).href;
}

/** A model file's URL (relative ones resolve against the asset base). */
export function assetUrl(url: string): string {
  return new URL(url, base ?? document.baseURI).href;
}
