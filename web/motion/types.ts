// Shared motion types. Conventions for every Motion in the app and the public API:
// metres, y up, right-handed; the ground is the x–z plane; heading 0 faces +z, heading π/2 faces +x.

/** A motion as world-space joint positions: what the viewer draws and the API returns. */
export interface Motion {
  fps: number;
  frames: number;
  /** Joint names, in the same order as `parents` and the positions' joint axis. */
  joints: string[];
  /** Index of each joint's parent, -1 for the root. Parents come before children. */
  parents: number[];
  /** frames × joints × 3, world space, metres. */
  positions: Float32Array;
  /** Optional foot contacts, frames × 2 (left, right), 1 = planted. */
  contacts?: Uint8Array;
}

/** A rigid skeleton: rest offsets of each joint from its parent, in the parent's frame (metres). */
export interface Skeleton {
  joints: string[];
  parents: number[];
  /** joints × 3; the root's offset is normally zero. */
  offsets: Float32Array;
}

export type MotionFormat = 'bvh' | 'amc' | 'asf';

/** The longest message a MotionFormatError carries; a longer one is cut (it would quote the file at length). */
export const MAX_ERROR_MESSAGE = 300;

/**
 * Raised for malformed input: says which file kind, where (1-based line if known) and what was expected.
 * The message is at most MAX_ERROR_MESSAGE characters, whatever the parser put in it; quote input with
 * quoteInput (text.ts) so the useful part survives.
 */
export class MotionFormatError extends Error {
  readonly format: MotionFormat;
  readonly line?: number;
  constructor(format: MotionFormat, message: string, line?: number) {
    const full = `${format.toUpperCase()}${line !== undefined ? ` line ${line}` : ''}: ${message}`;
    super(full.length > MAX_ERROR_MESSAGE ? `${full.slice(0, MAX_ERROR_MESSAGE - 1)}…` : full);
    this.name = 'MotionFormatError';
    this.format = format;
    this.line = line;
  }
}
