// Test helpers: simple measurements on Motion objects.
import type { Motion } from '../../web/motion/types';

export function jointIndex(m: Motion, name: string): number {
  const j = m.joints.indexOf(name);
  if (j < 0) throw new Error(`no joint ${name} in ${m.joints.join(', ')}`);
  return j;
}

export function position(m: Motion, frame: number, joint: number): [number, number, number] {
  const b = (frame * m.joints.length + joint) * 3;
  return [m.positions[b], m.positions[b + 1], m.positions[b + 2]];
}

export function distance(a: number[], b: number[]): number {
  return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/** Per frame, the y extent of the joints (metres): the figure's height measured at its joints. */
export function jointHeights(m: Motion): number[] {
  const heights: number[] = [];
  for (let f = 0; f < m.frames; f++) {
    let lo = Infinity, hi = -Infinity;
    for (let j = 0; j < m.joints.length; j++) {
      const y = position(m, f, j)[1];
      lo = Math.min(lo, y);
      hi = Math.max(hi, y);
    }
    heights.push(hi - lo);
  }
  return heights;
}

/** Largest y extent of the joints over all frames (standing height measured at the joints). */
export function maxHeight(m: Motion): number {
  let best = 0;
  for (const h of jointHeights(m)) best = Math.max(best, h);
  return best;
}

/** Largest change of any bone's length over the clip, relative to frame 0 (metres). */
export function boneLengthDrift(m: Motion): number {
  let drift = 0;
  for (let j = 1; j < m.joints.length; j++) {
    const p = m.parents[j];
    const l0 = distance(position(m, 0, j), position(m, 0, p));
    for (let f = 1; f < m.frames; f++) drift = Math.max(drift, Math.abs(distance(position(m, f, j), position(m, f, p)) - l0));
  }
  return drift;
}

/** Largest absolute difference between the positions of two motions with the same layout. */
export function maxPositionError(a: Motion, b: Motion): number {
  if (a.positions.length !== b.positions.length) return Infinity;
  let err = 0;
  for (let i = 0; i < a.positions.length; i += 3) {
    err = Math.max(err, Math.hypot(a.positions[i] - b.positions[i], a.positions[i + 1] - b.positions[i + 1], a.positions[i + 2] - b.positions[i + 2]));
  }
  return err;
}
