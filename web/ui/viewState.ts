// What a view is, as text: the <motion-playground> element's attributes and the page's link (query)
// parameters share these names and this checking. A bad value is refused with a reason and the
// setting keeps its default; nothing here ever becomes HTML.

import { checkPathPoints } from '../optimizer/path';
import type { Capability } from '../runtime/descriptor';
import type { Registry } from '../runtime/registry';
import { errorMessage } from './dom';
import { LOOKS, type Look } from '../viewer/look';

export type Mode = 'clip' | 'walk' | 'dance' | 'path' | 'steer';
export const MODES: readonly Mode[] = ['clip', 'walk', 'dance', 'path', 'steer'];

/** What a model must be able to do to be shown in each mode (Clip mode shows no model). */
const MODE_CAPABILITY: Record<Mode, Capability | null> = { clip: null, walk: 'walk', dance: 'dance', path: 'followPath', steer: 'liveControl' };

/** The models each mode can show (`model` is checked against the mode), from the registry. */
export type ModeModels = Record<Mode, readonly string[]>;

export function modeModels(registry: Registry): ModeModels {
  const ids = (mode: Mode) => {
    const capability = MODE_CAPABILITY[mode];
    return capability ? registry.ids(capability) : [];
  };
  return { clip: ids('clip'), walk: ids('walk'), dance: ids('dance'), path: ids('path'), steer: ids('steer') };
}

/** The settings a link or the attributes carry; a missing one is the mode's default. */
export interface ViewState {
  mode?: Mode;
  model?: string;
  style?: string;
  seed?: number;
  temperature?: number;
  refine?: boolean;
  /** Ground points [x, z] in metres (Path mode). */
  path?: [number, number][];
  /** What is drawn: the stick figure, the character (the default) or both. */
  look?: Look;
}

/** The names, in the order links and snippets write them. */
export const VIEW_KEYS = ['mode', 'model', 'style', 'seed', 'temperature', 'refine', 'path', 'look'] as const;
export type ViewKey = (typeof VIEW_KEYS)[number];

/** The view a first visit opens on: something alive, not an empty clip view. */
export const FIRST_VIEW: ViewState = { mode: 'walk', refine: true };

export const TEMPERATURE_RANGE = [0, 1.5] as const; // Random walk's slider
const MAX_TEXT = 4000; // a path of a few hundred points; longer text is refused before it is parsed

/** One setting from text: the value, or the reason it is refused (short, quoting the text cut short). */
export function parseViewValue(key: ViewKey, text: string): { value: ViewState[ViewKey] } | { error: string } {
  const quoted = JSON.stringify(text.length > 40 ? `${text.slice(0, 40)}…` : text);
  const refuse = (why: string) => ({ error: `${key}=${quoted}: ${why}` });
  if (text.length > MAX_TEXT) return refuse(`too long (at most ${MAX_TEXT} characters)`);
  switch (key) {
    case 'mode':
      return (MODES as readonly string[]).includes(text) ? { value: text as Mode } : refuse(`must be one of ${MODES.join(', ')}`);
    case 'model':
      return /^[a-z0-9][a-z0-9._-]{0,63}$/.test(text) ? { value: text } : refuse('must be a model id such as generator');
    case 'style':
      return /^[a-z][a-z0-9_-]{0,31}$/.test(text) ? { value: text } : refuse('must be a style name such as salsa or elderly');
    case 'seed': {
      const n = Number(text);
      return text.trim() !== '' && Number.isInteger(n) && n >= 0 && n <= 0xffffffff ? { value: n } : refuse('must be a whole number from 0 to 4294967295');
    }
    case 'temperature': {
      const n = Number(text);
      const [lo, hi] = TEMPERATURE_RANGE;
      return text.trim() !== '' && Number.isFinite(n) && n >= lo && n <= hi ? { value: n } : refuse(`must be a number from ${lo} to ${hi}`);
    }
    case 'refine':
      if (text === '' || text === 'true') return { value: true };
      if (text === 'false') return { value: false };
      return refuse('must be true or false');
    case 'look':
      return (LOOKS as readonly string[]).includes(text) ? { value: text as Look } : refuse(`must be one of ${LOOKS.join(', ')}`);
    case 'path': {
      const pairs = text.split(/[;\s]+/).filter(Boolean).map((p) => p.split(',').map(Number));
      if (pairs.some((p) => p.length !== 2)) return refuse('must be x,z pairs separated by ";" (metres), e.g. 0,0;4,2;8,0');
      try {
        return { value: checkPathPoints(pairs) as [number, number][] };
      } catch (e) {
        return refuse(errorMessage(e));
      }
    }
  }
}

/**
 * A whole view from named text values (attributes or query parameters): the settings that read, and a
 * reason for each that did not. A model that the mode does not have is refused too.
 */
export function parseView(get: (key: ViewKey) => string | null, models?: ModeModels): { view: ViewState; errors: string[] } {
  const view: ViewState = {};
  const errors: string[] = [];
  for (const key of VIEW_KEYS) {
    const text = get(key);
    if (text === null) continue;
    const r = parseViewValue(key, text);
    if ('error' in r) errors.push(r.error);
    else (view as Record<ViewKey, unknown>)[key] = r.value;
  }
  if (view.model !== undefined && models) {
    const mode = view.mode ?? 'clip';
    if (!models[mode].includes(view.model)) {
      errors.push(`model=${JSON.stringify(view.model)}: ${mode} mode ${models[mode].length ? `shows ${models[mode].join(', ')}` : 'has no model'}`);
      delete view.model;
    }
  }
  return { view, errors };
}

/** A setting as text (the inverse of parseViewValue; paths to the centimetre). */
export function formatViewValue(key: ViewKey, value: NonNullable<ViewState[ViewKey]>): string {
  if (key === 'path') return (value as [number, number][]).map(([x, z]) => `${+x.toFixed(2)},${+z.toFixed(2)}`).join(';');
  return String(value);
}

/** The view as query parameters (a link), in VIEW_KEYS order, leaving out what is not set. */
export function viewQuery(view: ViewState): string {
  const q = new URLSearchParams();
  for (const key of VIEW_KEYS) {
    const v = view[key];
    if (v !== undefined) q.set(key, formatViewValue(key, v));
  }
  return q.toString();
}

/**
 * The <motion-playground> attribute that carries a view's `style` in `mode` (the element's own `style` attribute is its
 * inline CSS): `dance-style` in Dance mode, `motion-style` (a walking style) in the others.
 */
export function styleAttribute(mode: Mode | undefined): 'dance-style' | 'motion-style' {
  return mode === 'dance' ? 'dance-style' : 'motion-style';
}

/** Escapes text for an HTML attribute value in a snippet shown to the user (shown as text, never parsed). */
function attributeText(s: string): string {
  return s.replace(/&/g, '&amp;').replace(/"/g, '&quot;').replace(/</g, '&lt;').replace(/>/g, '&gt;');
}

/** The <motion-playground> snippet that embeds this view; `moduleUrl` is where the element's module lives. */
export function embedSnippet(view: ViewState, moduleUrl: string): string {
  const attrs = VIEW_KEYS.flatMap((key) => {
    const v = view[key];
    const name = key === 'style' ? styleAttribute(view.mode) : key; // the element's `style` attribute is its inline CSS
    return v === undefined ? [] : [`${name}="${attributeText(formatViewValue(key, v))}"`];
  });
  return [
    `<script type="module" src="${attributeText(moduleUrl)}"></script>`,
    `<motion-playground ${[...attrs, 'autoplay', 'camera-controls', 'controls="minimal"'].join(' ')} style="width: 640px; height: 400px"></motion-playground>`,
  ].join('\n');
}
