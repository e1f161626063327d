// Small helpers the page's ui files share: looking up the template's elements, making elements, slider
// fills, reading seed fields, the text of a caught error for the page's messages, and offering a text as a download.

/**
 * Where the page's UI classes find their elements: the <motion-playground> element's shadow root, and
 * whether a key or file drop is this element's (several elements on one page each take their own).
 * Set while App builds its parts (buildIn); the classes look up every element they need then.
 */
export interface DomScope {
  root: ShadowRoot;
  /** The wrapper whose classes say the mode and state (style.css's `.app.walk-mode` …). */
  frame: HTMLElement;
  /** Whether a keyboard event is for this element: from inside it, or on the bare page when it owns the page. */
  ownsEvent(e: Event): boolean;
  /** Aborted when the element's playground is taken down: listeners put on window or document go with it. */
  signal?: AbortSignal;
}

let building: DomScope | null = null;

/** Runs `build` with `scope` as the place `$` looks (App's constructor). */
export function buildIn<T>(scope: DomScope, build: () => T): T {
  const outer = building;
  building = scope;
  try {
    return build();
  } finally {
    building = outer;
  }
}

/** The scope being built (a UI class keeps it when it needs to check events later). */
export function currentScope(): DomScope {
  if (!building) throw new Error('the page UI looks up its elements while it is built (inside buildIn)');
  return building;
}

/** The element with this id in the playground's template (a missing one is a bug in the page, so it throws). */
export function $<T extends HTMLElement = HTMLElement>(id: string): T {
  const el = currentScope().root.getElementById(id);
  if (!el) throw new Error(`missing #${id} in the playground's template (web/ui/playground.html)`);
  return el as T;
}

/** Every element matching `selector` in the scope being built. */
export function $all<T extends HTMLElement = HTMLElement>(selector: string): T[] {
  return [...currentScope().root.querySelectorAll<T>(selector)];
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
  downloadBlob(fileName, new Blob([text], { type: mime }));
}

/** Offers a blob (an image, a video, a binary export) as a file download. */
export function downloadBlob(fileName: string, blob: Blob): void {
  const url = URL.createObjectURL(blob);
  const a = document.createElement('a');
  a.href = url;
  a.download = fileName;
  a.style.display = 'none';
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

/**
 * Sets a form field as the user would: its value (a checkbox: checked), then its input and change events. A value the
 * field already holds fires nothing, as when a user picks it again (a view that repeats the settings restarts nothing).
 */
export function changeTo(field: HTMLInputElement | HTMLSelectElement, value: string | boolean): void {
  if (field instanceof HTMLInputElement && field.type === 'checkbox') {
    if (field.checked === value) return;
    field.checked = value as boolean;
  } else {
    if (field.value === String(value)) return;
    field.value = String(value);
  }
  field.dispatchEvent(new Event('input', { bubbles: true }));
  field.dispatchEvent(new Event('change', { bubbles: true }));
}
