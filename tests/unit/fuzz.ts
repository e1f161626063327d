// Seeded fuzz cases for the motion parsers' unit tests: a small PRNG, makers of damaged inputs, and the
// check every case must pass (rejected with a short Error naming the file kind, or accepted with finite
// positions, and within a work budget counted by the parsers, not timed).
import { expect } from 'vitest';
import { parseWork } from '../../web/motion/text';
import { MAX_ERROR_MESSAGE, type Motion } from '../../web/motion/types';

export interface Random {
  /** Uniform in [0, 1). */
  next(): number;
  /** Uniform integer in [0, n). */
  int(n: number): number;
  pick<T>(items: readonly T[]): T;
}

/** mulberry32: the same seed gives the same cases on every machine. */
export function seededRandom(seed: number): Random {
  let state = seed >>> 0;
  const next = () => {
    state = (state + 0x6d2b79f5) >>> 0;
    let t = state;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 2 ** 32;
  };
  const int = (n: number) => Math.floor(next() * n);
  return { next, int, pick: (items) => items[int(items.length)] };
}

/** One fuzz case: what was done to the input (for failure messages) and the text to parse. */
export interface FuzzCase {
  what: string;
  text: string;
}

/** The text cut at a random offset (at least one character kept, at least one removed). */
export function truncated(random: Random, text: string): FuzzCase {
  const at = 1 + random.int(text.length - 1);
  return { what: `truncated at ${at} of ${text.length}`, text: text.slice(0, at) };
}

/** A few characters with one random bit of their low byte flipped (control characters and NUL included). */
export function byteFlips(random: Random, text: string): FuzzCase {
  const chars = text.split('');
  const flips = 1 + random.int(4);
  const at: number[] = [];
  for (let k = 0; k < flips; k++) {
    const i = random.int(chars.length);
    chars[i] = String.fromCharCode(chars[i].charCodeAt(0) ^ (1 << random.int(8)));
    at.push(i);
  }
  return { what: `bits flipped at ${at.join(', ')}`, text: chars.join('') };
}

/** Numbers no motion file should hold: overflowing, non-finite, denormal, absurdly large, or not decimal. */
export const HUGE_NUMBERS = ['1e300', '-1e300', '1e308', '1e309', '-1e999', '1e15', '1e-320', 'NaN', 'Infinity', '-Infinity', '123456789012345678901234567890', '0x10', '1e+300'];

const NUMBER_TOKEN = /(?<![\w.+-])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])/g;

/** A few number tokens (found after random offsets) replaced by HUGE_NUMBERS. */
export function hugeNumbers(random: Random, text: string): FuzzCase {
  let t = text;
  const done: string[] = [];
  const count = 1 + random.int(3);
  for (let k = 0; k < count; k++) {
    NUMBER_TOKEN.lastIndex = random.int(t.length);
    const match = NUMBER_TOKEN.exec(t) ?? ((NUMBER_TOKEN.lastIndex = 0), NUMBER_TOKEN.exec(t));
    if (!match) break;
    const huge = random.pick(HUGE_NUMBERS);
    t = t.slice(0, match.index) + huge + t.slice(match.index + match[0].length);
    done.push(`${match[0]} → ${huge} at ${match.index}`);
  }
  return { what: `numbers replaced: ${done.join('; ')}`, text: t };
}

/** Pieces of the formats' structure and number syntax that junkTokens inserts. */
export const JUNK_TOKENS = ['{', '}', '\n', ' ', 'JOINT', 'End Site', 'OFFSET', '-', '.', 'e', '9', 'NaN', '#', ':', 'root', '1'];

/** A few JUNK_TOKENS inserted at random offsets. */
export function junkTokens(random: Random, text: string): FuzzCase {
  let t = text;
  const done: string[] = [];
  const count = 1 + random.int(4);
  for (let k = 0; k < count; k++) {
    const at = random.int(t.length + 1);
    const junk = random.pick(JUNK_TOKENS);
    t = t.slice(0, at) + junk + t.slice(at);
    done.push(`${JSON.stringify(junk)} at ${at}`);
  }
  return { what: `junk inserted: ${done.join(', ')}`, text: t };
}

/** Line breaks a file may use, by name: each variant should read exactly as the \n original. */
export const LINE_ENDINGS = { CRLF: '\r\n', CR: '\r', 'U+2028': '\u2028', 'U+2029': '\u2029' } as const;

/** Every line break replaced by one variant, or by a random variant per line ("mixed"). */
export function lineEndings(random: Random, text: string): FuzzCase {
  const variants = Object.values(LINE_ENDINGS);
  const name = random.pick([...Object.keys(LINE_ENDINGS), 'mixed']) as keyof typeof LINE_ENDINGS | 'mixed';
  const replaced = text.replace(/\r\n|\n/g, () => (name === 'mixed' ? random.pick(variants) : LINE_ENDINGS[name]));
  return { what: `line endings ${name}`, text: replaced };
}

/** Frame counts or frame numbers a file may declare that no import can hold (or that are not counts). */
export const HUGE_COUNTS = ['1000001', '2147483648', '4294967296', '9007199254740993', '99999999999999999999999', '1e9', '1e300', '-1'];

export type HierarchyShape = 'chain' | 'wide' | 'random';

/** Joint counts for generated hierarchies: small, at and just past MAX_JOINTS (1024), and far past it. */
export const HIERARCHY_SIZES = [2, 31, 1024, 1025, 5000, 20_000];

/**
 * Parent indices of a generated hierarchy of `joints` joints (joint 0 is the root, parent -1; every
 * parent comes before its child): a single deep chain, every joint a child of the root, or random.
 */
export function hierarchyParents(random: Random, shape: HierarchyShape, joints: number): number[] {
  const parents = [-1];
  for (let j = 1; j < joints; j++) parents.push(shape === 'chain' ? j - 1 : shape === 'wide' ? 0 : random.int(j));
  return parents;
}

/** Parse steps (parseWork) allowed per input character plus per output position value. */
export const WORK_PER_UNIT = 4;

export type FuzzOutcome = 'accepted' | 'rejected';

/**
 * Runs one case's parse and checks it: either it throws an Error whose message starts with one of `kinds`
 * (e.g. ["ASF", "AMC"]) and has at most MAX_ERROR_MESSAGE characters, or it returns a motion whose positions
 * are all finite. Either way the parse may do at most WORK_PER_UNIT steps per input character plus output
 * value. `label` (the seed and the case's `what`) is in every failure message.
 */
export function checkFuzzCase(label: string, parse: () => Motion, inputLength: number, kinds: readonly string[]): FuzzOutcome {
  const before = parseWork.steps;
  let motion: Motion | undefined;
  let error: unknown;
  try {
    motion = parse();
  } catch (e) {
    error = e;
  }
  const work = parseWork.steps - before;
  const outputValues = motion ? motion.positions.length : 0;
  expect(work, `${label}: ${work} parse steps for ${inputLength} characters and ${outputValues} values`).toBeLessThanOrEqual(WORK_PER_UNIT * (inputLength + outputValues));
  if (motion) {
    const bad = motion.positions.findIndex((v) => !Number.isFinite(v));
    expect(bad, `${label}: accepted with a non-finite position at index ${bad}`).toBe(-1);
    return 'accepted';
  }
  expect(error, `${label}: threw a non-Error ${String(error)}`).toBeInstanceOf(Error);
  const message = (error as Error).message;
  expect(kinds.some((k) => message.startsWith(k)), `${label}: message does not name the file kind (${kinds.join('/')}): ${message.slice(0, 200)}`).toBe(true);
  expect(message.length, `${label}: message of ${message.length} characters: ${message.slice(0, 200)}`).toBeLessThanOrEqual(MAX_ERROR_MESSAGE);
  return 'rejected';
}

/**
 * ASF text with bones b1 … b<n−1> (one inch long, pointing up, with the given dofs: rx ry rz unless told) and a
 * :hierarchy of the given parent → child links (joint indices: 0 is the root, j is bone b<j>), one line per
 * parent in first-seen order. Each bone takes 7 lines, whatever its dofs.
 */
export function generatedASF(bones: number, links: ReadonlyArray<readonly [number, number]>, dofs = 'rx ry rz'): string {
  const name = (j: number) => (j === 0 ? 'root' : `b${j}`);
  const boneData: string[] = [];
  for (let j = 1; j <= bones; j++) boneData.push(`begin\nname b${j}\ndirection 0 1 0\nlength 1\naxis 0 0 0 XYZ\ndof ${dofs}\nend`);
  const children = new Map<number, number[]>();
  for (const [parent, child] of links) {
    const list = children.get(parent);
    if (list) list.push(child);
    else children.set(parent, [child]);
  }
  const hierarchy = [...children].map(([parent, list]) => `${name(parent)} ${list.map(name).join(' ')}`);
  return `:units\nlength 1\nangle deg\n:root\norder TX TY TZ RX RY RZ\naxis XYZ\nposition 0 0 0\norientation 0 0 0\n:bonedata\n${boneData.join('\n')}\n:hierarchy\nbegin\n${hierarchy.join('\n')}\nend\n`;
}

/** The parent → child links of a parents array (as from hierarchyParents). */
export function parentLinks(parents: readonly number[]): Array<[number, number]> {
  const links: Array<[number, number]> = [];
  for (let j = 1; j < parents.length; j++) links.push([parents[j], j]);
  return links;
}

/**
 * AMC text for generatedASF's skeleton with `bones` bones (0 for a skeleton whose bones have no dofs): `frames`
 * frames of small rotations. Frame f's number is on line 3 + (f − 1) × (bones + 2).
 */
export function generatedAMC(random: Random, bones: number, frames: number): string {
  const angle = () => (random.next() * 60 - 30).toFixed(3);
  const lines = [':FULLY-SPECIFIED', ':DEGREES'];
  for (let f = 1; f <= frames; f++) {
    lines.push(String(f), `root ${angle()} ${angle()} ${angle()} ${angle()} ${angle()} ${angle()}`);
    for (let j = 1; j <= bones; j++) lines.push(`b${j} ${angle()} ${angle()} ${angle()}`);
  }
  return lines.join('\n') + '\n';
}
