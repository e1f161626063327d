// Shared pieces of the model description files (public/models/<id>.json): fetching one with clear
// errors, and field checkers that name the first bad field, so a mismatched or truncated file fails
// at load time rather than mid-stream.

/** Base of each model's JSON error class: the message starts with the file. */
export class ModelInfoError extends Error {
  constructor(source: string, message: string) {
    super(`${source}: ${message}`);
  }
}

type InfoErrorClass = new (source: string, message: string) => Error;

/** Fetches a model JSON (or the manifest) and checks it with `parse`; every error is an `ErrorClass` naming the URL. */
export async function loadModelInfo<T>(url: string | URL, parse: (raw: unknown, source: string) => T, ErrorClass: InfoErrorClass, init?: RequestInit): Promise<T> {
  const source = String(url);
  const error = (message: string) => new ErrorClass(source, message);
  let response: Response;
  try {
    response = await fetch(url, init);
  } catch (err) {
    throw error(`could not fetch (${err instanceof Error ? err.message : String(err)})`);
  }
  if (!response.ok) throw error(`HTTP ${response.status} ${response.statusText}`);
  let raw: unknown;
  try {
    raw = await response.json();
  } catch (err) {
    throw error(`not valid JSON (${err instanceof Error ? err.message : String(err)})`);
  }
  return parse(raw, source);
}

export interface FieldChecks {
  fail(message: string): never;
  /** The file's top-level object, with a positive `fps`. */
  file(raw: unknown): Record<string, unknown>;
  obj(value: unknown, path: string): Record<string, unknown>;
  num(value: unknown, path: string): number;
  posInt(value: unknown, path: string): number;
  positive(value: unknown, path: string): number;
  numbers(value: unknown, path: string, length?: number): number[];
  strings(value: unknown, path: string): string[];
  /** A list of strings that must equal `expected` (e.g. the ONNX input names). */
  names(value: unknown, path: string, expected: readonly string[]): void;
  /** `skeleton.{joints, parents, offsets}`: root first, parents before children, joints × 3 offsets. Returns the joint count. */
  skeleton(value: unknown): number;
  /** `normalisation.{mean, std}` of `dim` values each, every std positive. */
  normalisation(value: unknown, dim: number): void;
}

/** Field checkers that throw an `ErrorClass` for `source` naming the field. */
export function fieldChecks(source: string, ErrorClass: InfoErrorClass): FieldChecks {
  const fail = (message: string): never => {
    throw new ErrorClass(source, message);
  };
  const c: FieldChecks = {
    fail,
    file(raw) {
      const root = c.obj(raw, 'the file');
      c.positive(root.fps, 'fps');
      return root;
    },
    obj: (value, path) =>
      typeof value === 'object' && value !== null && !Array.isArray(value) ? (value as Record<string, unknown>) : fail(`${path} must be an object`),
    num: (value, path) => (typeof value === 'number' && Number.isFinite(value) ? value : fail(`${path} must be a finite number`)),
    posInt(value, path) {
      const n = c.num(value, path);
      return Number.isInteger(n) && n > 0 ? n : fail(`${path} must be a positive integer, got ${n}`);
    },
    positive(value, path) {
      const n = c.num(value, path);
      return n > 0 ? n : fail(`${path} must be positive, got ${n}`);
    },
    numbers(value, path, length) {
      if (!Array.isArray(value)) return fail(`${path} must be an array of numbers`);
      if (length !== undefined && value.length !== length) fail(`${path} has ${value.length} values, expected ${length}`);
      const bad = value.findIndex((v) => typeof v !== 'number' || !Number.isFinite(v));
      if (bad >= 0) fail(`${path}[${bad}] is not a finite number`);
      return value as number[];
    },
    strings: (value, path) =>
      Array.isArray(value) && value.every((v) => typeof v === 'string') ? (value as string[]) : fail(`${path} must be an array of strings`),
    names(value, path, expected) {
      const got = c.strings(value, path);
      if (got.join() !== expected.join()) fail(`${path} is [${got}], expected [${expected}]`);
    },
    skeleton(value) {
      const skeleton = c.obj(value, 'skeleton');
      const joints = c.strings(skeleton.joints, 'skeleton.joints');
      const J = joints.length;
      if (J === 0) fail('skeleton.joints is empty');
      const parents = c.numbers(skeleton.parents, 'skeleton.parents', J);
      parents.forEach((p, j) => {
        if (j === 0 ? p !== -1 : !Number.isInteger(p) || p < 0 || p >= j) fail(`skeleton.parents[${j}] = ${p}: the root must be first (-1) and parents must precede children`);
      });
      c.numbers(skeleton.offsets, 'skeleton.offsets', J * 3);
      return J;
    },
    normalisation(value, dim) {
      const norm = c.obj(value, 'normalisation');
      c.numbers(norm.mean, 'normalisation.mean', dim);
      const std = c.numbers(norm.std, 'normalisation.std', dim);
      const badStd = std.findIndex((s) => s <= 0);
      if (badStd >= 0) fail(`normalisation.std[${badStd}] = ${std[badStd]} must be positive`);
    },
  };
  return c;
}

/**
 * A model's JSON format: its error class (named `errorName`), `parse(raw, source?)` which checks the file
 * with `check(checks, root)` (throwing the error class naming the first bad field) and `load(url)`.
 */
export function modelInfoFormat<T>(errorName: string, defaultSource: string, check: (c: FieldChecks, root: Record<string, unknown>) => void) {
  const InfoError = class extends ModelInfoError {
    override readonly name = errorName;
  };
  const parse = (raw: unknown, source = defaultSource): T => {
    const c = fieldChecks(source, InfoError);
    check(c, c.file(raw));
    return raw as T;
  };
  return { InfoError, parse, load: (url: string | URL): Promise<T> => loadModelInfo(url, parse, InfoError) };
}
