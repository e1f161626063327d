// How a value that failed a check reads in an error message ("…, got [1, NaN]"): short whatever it is,
// with what JSON.stringify and String hide shown as it is (NaN, Infinity, undefined, strings in quotes).
import { quoteInput } from './text';

/** Items of an array (keys of an object) shown before "…". */
const SHOWN_ITEMS = 4;
/** Characters of a string quoted inside an array or object (a lone string gets quoteInput's 40). */
const NESTED_QUOTE = 12;
/** Longest text String() may give for a symbol, a bigint or a class name before it is cut. */
const MAX_PLAIN = 24;
/** Longest description: escaped invisible characters (6 characters each) can make the parts longer than they look. */
export const MAX_DESCRIPTION = 120;

const SIMPLE_KEY = /^[A-Za-z_$][\w$]{0,19}$/;

function clip(text: string): string {
  return text.length > MAX_PLAIN ? `${text.slice(0, MAX_PLAIN)}…` : text;
}

function describeAt(value: unknown, nested: boolean): string {
  switch (typeof value) {
    case 'string':
      return quoteInput(value, nested ? NESTED_QUOTE : undefined);
    case 'number':
      return Object.is(value, -0) ? '-0' : String(value);
    case 'bigint':
      return `${clip(String(value))}n`;
    case 'symbol':
      return clip(String(value));
    case 'function':
      return 'a function';
    case 'undefined':
    case 'boolean':
      return String(value);
  }
  if (value === null) return 'null';
  if (ArrayBuffer.isView(value)) return `${clip(value.constructor.name)}(${'length' in value ? value.length : value.byteLength})`;
  if (Array.isArray(value)) {
    if (value.length === 0) return '[]';
    if (nested) return `[…${value.length} items]`;
    const shown = value.slice(0, SHOWN_ITEMS).map((v) => describeAt(v, true));
    return `[${shown.join(', ')}${value.length > SHOWN_ITEMS ? `, … ${value.length} items` : ''}]`;
  }
  const prototype = Object.getPrototypeOf(value);
  if (prototype !== Object.prototype && prototype !== null) return `a ${clip(String(prototype?.constructor?.name || 'object'))}`;
  const keys = Object.keys(value as object);
  if (keys.length === 0) return '{}';
  if (nested) return '{…}';
  const shown = keys.slice(0, SHOWN_ITEMS).map((k) => `${SIMPLE_KEY.test(k) ? k : quoteInput(k, NESTED_QUOTE)}: ${describeAt((value as Record<string, unknown>)[k], true)}`);
  return `{ ${shown.join(', ')}${keys.length > SHOWN_ITEMS ? ', …' : ''} }`;
}

/**
 * A value as an error message shows it: numbers as written, NaN and ±Infinity included; strings in double
 * quotes (at most 40 characters, invisible ones escaped: quoteInput), so "10" and 10 read differently;
 * arrays and plain objects with their first 4 items (strings inside cut to 12 characters, nested arrays
 * and objects as […n items] and {…}); typed arrays, class instances and functions by kind. At most
 * MAX_DESCRIPTION characters (then …); a value whose inspection throws (a hostile Proxy or getter) reads as "an unreadable value".
 */
export function describeValue(value: unknown): string {
  try {
    const text = describeAt(value, false);
    return text.length > MAX_DESCRIPTION ? `${text.slice(0, MAX_DESCRIPTION)}…` : text;
  } catch {
    return 'an unreadable value';
  }
}
