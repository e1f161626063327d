// Shape and value checks for Motion objects handed in by API users or produced by the parsers.
import type { Motion } from './types';
import { MAX_FRAMES, MAX_VALUES, quoteInput } from './text';
import { describeValue } from './describe';

export const MAX_JOINTS = 1024;
/** Largest coordinate of a joint position, in metres (1000 km from the origin along any axis). */
export const MAX_POSITION = 1e6;

const AXIS_NAMES = ['x', 'y', 'z'];

/**
 * Why a joint position is out of bounds, or undefined when `value` (metres, on `axis` 0…2) lies within
 * ±MAX_POSITION: `frame` is the frame's number as the caller counts it. Shared by the parsers and
 * validateMotion, so every format names the bound alike. The value is shown to 7 digits, as a position keeps it.
 */
export function positionOutOfBounds(value: number, frame: number, joint: string, axis: number): string | undefined {
  if (Math.abs(value) <= MAX_POSITION) return undefined;
  return `frame ${frame} puts joint ${quoteInput(joint)} at ${AXIS_NAMES[axis]} = ${Number(value.toPrecision(7))} m (at most ±${MAX_POSITION} m on each axis)`;
}

/**
 * The index of the first hole of a sparse array (`[1, , 2]`, `new Array(3)`, a deleted item), or -1: forEach, every
 * and map skip holes, so an array check that uses them passes a hole that fails later as `undefined`.
 */
export function firstHole(array: readonly unknown[]): number {
  for (let i = 0; i < array.length; i++) if (!(i in array)) return i;
  return -1;
}

/** Throws a TypeError naming the first hole of `array` (called `name` in the message), if it has one. */
export function checkNoHoles(array: readonly unknown[], name: string): void {
  const i = firstHole(array);
  if (i >= 0) throw new TypeError(`${name}[${i}] is missing (the array has a hole there)`);
}

function fail(message: string): never {
  throw new Error(`Invalid motion: ${message}`);
}

function toFloat32(value: unknown, name: string): Float32Array {
  if (value instanceof Float32Array) return value;
  if (value instanceof Float64Array || Array.isArray(value)) return Float32Array.from(value as ArrayLike<number>);
  return fail(`${name} must be a Float32Array or an array of numbers`);
}

/**
 * Checks a Motion object (plain arrays are accepted for positions and contacts and converted to typed
 * arrays). Throws an Error naming the first problem found; returns the checked Motion.
 */
export function validateMotion(m: unknown): Motion {
  if (typeof m !== 'object' || m === null) fail('expected an object with fps, frames, joints, parents, positions');
  const o = m as Record<string, unknown>;

  const fps = o.fps;
  if (typeof fps !== 'number' || !Number.isFinite(fps) || fps <= 0 || fps > 10000) fail(`fps must be a positive number (≤ 10000), got ${describeValue(fps)}`);
  const frames = o.frames;
  if (typeof frames !== 'number' || !Number.isInteger(frames) || frames < 1 || frames > MAX_FRAMES) {
    fail(`frames must be an integer from 1 to ${MAX_FRAMES}, got ${describeValue(frames)}`);
  }

  const joints = o.joints;
  if (!Array.isArray(joints) || joints.length === 0) fail('joints must be a non-empty array of names');
  if (joints.length > MAX_JOINTS) fail(`too many joints (${joints.length}, at most ${MAX_JOINTS})`);
  const hole = (a: unknown[], name: string) => {
    const i = firstHole(a);
    if (i >= 0) fail(`${name}[${i}] is missing (the array has a hole there)`);
  };
  hole(joints, 'joints');
  const seen = new Set<string>();
  joints.forEach((name, j) => {
    if (typeof name !== 'string' || name.length === 0) fail(`joints[${j}] must be a non-empty string`);
    if (seen.has(name)) fail(`duplicate joint name ${quoteInput(name)}`);
    seen.add(name);
  });

  const parents = o.parents;
  if (!Array.isArray(parents) || parents.length !== joints.length) {
    fail(`parents must be an array with one entry per joint (${joints.length}), got ${Array.isArray(parents) ? parents.length : typeof parents}`);
  }
  hole(parents, 'parents');
  parents.forEach((p, j) => {
    if (typeof p !== 'number' || !Number.isInteger(p)) fail(`parents[${j}] must be an integer`);
    if (j === 0 && p !== -1) fail(`the first joint must be the root (parent -1), got parent ${p}`);
    if (j > 0 && (p < 0 || p >= j)) fail(`parents[${j}] = ${p}: every non-root joint needs a parent listed before it`);
  });

  if (Array.isArray(o.positions)) hole(o.positions, 'positions');
  const positions = toFloat32(o.positions, 'positions');
  const expected = frames * joints.length * 3;
  if (expected > MAX_VALUES) fail(`too many position values (${expected}, at most ${MAX_VALUES})`);
  if (positions.length !== expected) {
    fail(`positions has ${positions.length} values, expected frames × joints × 3 = ${frames} × ${joints.length} × 3 = ${expected}`);
  }
  for (let i = 0; i < positions.length; i++) {
    if (Math.abs(positions[i]) <= MAX_POSITION) continue; // NaN and ±Infinity are not
    const frame = Math.floor(i / (joints.length * 3));
    const joint = joints[Math.floor(i / 3) % joints.length];
    if (!Number.isFinite(positions[i])) fail(`positions contain a non-finite value (${positions[i]}) at frame ${frame}, joint ${quoteInput(joint)}`);
    fail(positionOutOfBounds(positions[i], frame, joint, i % 3)!);
  }

  const motion: Motion = { fps, frames, joints: joints.slice(), parents: parents.slice(), positions };
  if (o.contacts !== undefined) {
    const c = o.contacts;
    if (!(c instanceof Uint8Array) && !Array.isArray(c)) fail('contacts must be a Uint8Array or an array of 0/1');
    if (Array.isArray(c)) hole(c, 'contacts');
    const contacts = c instanceof Uint8Array ? c : Uint8Array.from(c as number[]);
    if (contacts.length !== frames * 2) fail(`contacts has ${contacts.length} values, expected frames × 2 = ${frames * 2}`);
    for (let i = 0; i < contacts.length; i++) {
      const v = Array.isArray(c) ? c[i] : contacts[i];
      if (v !== 0 && v !== 1) fail(`contacts[${i}] must be 0 or 1, got ${describeValue(v)}`);
    }
    motion.contacts = contacts;
  }
  return motion;
}
