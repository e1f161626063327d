// Small helpers the page's ui files share: looking up index.html's elements, making elements, slider
// fills, reading seed fields, the text of a caught error for the page's messages, and offering a text as a download.

/** The element with this id in index.html (a missing one is a bug in the page, so it throws). */
export function $<T extends HTMLElement = HTMLElement>(id: string): T {
  const el = document.getElementById(id);
  if (!el) throw new Error(`missing #${id} in index.html`);
  return el as T;
}

/** A new element with a class and, optionally, its text. */
export function element<K extends keyof HTMLElementTagNameMap>(tag: K, className: string, text?: string): HTMLElementTagNameMap[K] {
  const el = document.createElement(tag);
  el.className = className;
  if (text !== undefined) el.textContent = text;
  return el;
}

/** How far a range slider's track is filled (0…1): style.css draws the accent colour up to `--p`. */
export function setSliderFill(slider: HTMLElement, fraction: number): void {
  slider.style.setProperty('--p', `${fraction * 100}%`);
}

/** A seed field's value as the models take it: a whole number 0…2³² − 1 (anything else reads as 0). */
export function readSeed(input: HTMLInputElement): number {
  const seed = Math.floor(Number(input.value));
  if (!Number.isFinite(seed) || seed < 0) return 0;
  return Math.min(seed, 0xffffffff);
}

/** The text of a caught error (its message, else its name), for messages shown to the user. */
export function errorMessage(e: unknown): string {
  if (e instanceof Error) return e.message || e.name;
  return String(e);
}

/** Offers a text as a file download. */
export function downloadText(fileName: string, text: string, mime = 'text/plain'): void {
  const url = URL.createObjectURL(new Blob([text], { type: mime }));
  const a = document.createElement('a');
  a.href = url;
  a.download = fileName;
  a.style.display = 'none';
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}
