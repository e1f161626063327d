// Shared helpers for the text parsers: input sanity checks, line splitting, strict number parsing.
import { MotionFormatError, type MotionFormat } from './types';

/** Hard limits on imported motions; larger inputs are rejected rather than allocated. */
export const MAX_FRAMES = 1_000_000;
export const MAX_VALUES = 100_000_000;

/** Longest stretch of the input an error message quotes. */
export const MAX_QUOTE = 40;

/**
 * A piece of the input as an error message quotes it: in double quotes, at most `max` characters (then "…"),
 * with line breaks and other invisible characters (U+2028, controls) shown as escapes, so the message says
 * what is really there.
 */
export function quoteInput(value: string, max = MAX_QUOTE): string {
  const cut = value.length > max ? value.slice(0, max) : value;
  const shown = cut.replace(/[\u0000-\u001f\u007f-\u009f\u2028\u2029\ufeff]/g, (c) => `\\u${c.charCodeAt(0).toString(16).padStart(4, '0')}`);
  return `"${shown}${value.length > max ? '…' : ''}"`;
}

/** Longest message the page shows (a banner, `lastError()`) or the element fires in an `error` event. */
export const MAX_MESSAGE = 300;

/**
 * `message` in at most `max` characters: a longer one keeps its start and its end with "…" between them (the
 * end often says what went wrong, the start where), never splitting a surrogate pair.
 */
export function capMessage(message: string, max = MAX_MESSAGE): string {
  if (message.length <= max) return message;
  let head = Math.ceil((max - 1) * 0.6);
  let tail = max - 1 - head;
  if (/[\ud800-\udbff]/.test(message[head - 1] ?? '')) head--;
  if (/[\udc00-\udfff]/.test(message[message.length - tail] ?? '')) tail--;
  return `${message.slice(0, head)}…${tail > 0 ? message.slice(message.length - tail) : ''}`;
}

const NUMBER = /^[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$/;

/** Rejects empty and binary input before any parsing. */
export function checkText(text: string, format: MotionFormat): void {
  if (typeof text !== 'string') throw new MotionFormatError(format, 'expected text input');
  if (text.trim().length === 0) throw new MotionFormatError(format, 'file is empty');
  if (text.includes('\0')) throw new MotionFormatError(format, 'file contains NUL bytes (binary data, not a text file)');
  // Control characters other than tab/CR/LF, or U+FFFD from failed decoding, mean binary data.
  const sample = text.length > 65536 ? text.slice(0, 65536) : text;
  let bad = 0;
  for (let i = 0; i < sample.length; i++) {
    const c = sample.charCodeAt(i);
    if ((c < 32 && c !== 9 && c !== 10 && c !== 13) || c === 127 || c === 0xfffd) bad++;
  }
  if (bad > 0.01 * sample.length) {
    throw new MotionFormatError(format, `file looks binary (${bad} non-printable characters in the first ${sample.length})`);
  }
}

/**
 * Work the parsers have done, in steps: a line split off, a token, a number read, a joint visited, a joint
 * placed in a frame. Never reset by the parsers; tests read it before and after a parse and bound the
 * difference by the input and output sizes, so quadratic parsing fails a test without timing anything.
 */
export const parseWork = { steps: 0 };

/**
 * Lines without terminators; handles \n, \r\n, \r and the Unicode separators U+2028 and U+2029 (line
 * breaks to JavaScript, and already whitespace to `tokens`). Line i of the result is file line i + 1.
 */
export function splitLines(text: string): string[] {
  const lines = text.split(/\r\n|[\n\r\u2028\u2029]/);
  parseWork.steps += lines.length;
  return lines;
}

/** Whitespace-separated tokens of one line. */
export function tokens(line: string): string[] {
  const t = line.trim();
  const parts = t.length === 0 ? [] : t.split(/\s+/);
  parseWork.steps += parts.length;
  return parts;
}

/** Parses a decimal number strictly (no NaN, Infinity, hex or trailing junk). */
export function parseNumber(token: string, format: MotionFormat, line: number, what = 'a number'): number {
  parseWork.steps++;
  const v = NUMBER.test(token) ? Number(token) : NaN;
  if (!Number.isFinite(v)) {
    throw new MotionFormatError(format, `expected ${what}, found ${quoteInput(token)}`, line);
  }
  return v;
}

/**
 * parseNumber, then at most `max` in magnitude: a finite value beyond it is absurd for `what` (name the
 * unit in `what`, e.g. "an angle in degrees") and rejected with the limit.
 */
export function parseBounded(token: string, format: MotionFormat, line: number, what: string, max: number): number {
  const v = parseNumber(token, format, line, what);
  if (Math.abs(v) > max) throw new MotionFormatError(format, `expected ${what} of at most ${max} in magnitude, found ${quoteInput(token)}`, line);
  return v;
}
