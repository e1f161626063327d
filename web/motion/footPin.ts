// Planted feet held still in a whole cleaned motion (motion clean-up). The foot lock (footLock.ts) is built for
// generated motion: it anchors the toe where a contact starts, brings it to a fixed ground height and re-solves the
// knee. Captured motion already has its feet nearly in place, rolling from heel to toe, so here the feet are only
// kept from sliding (on the canonical skeleton, whose feet are ankle, toe and toe tip): in each contact, the foot point that is lowest in a frame is moved (with the rest of the foot)
// horizontally to where that point sits on median over the contact's frames in which it is lowest, so a heel stays
// where it struck and the toe where it rolled onto, heights are kept, and the shift fades in and out over a few frames
// at the contact's ends. The knee follows by two-bone IK in its own bend plane.
import { findLegs, footPoints } from './legs';
import { twoBoneIK } from './footLock';

/** Frames over which the shift fades in at a contact's start and out at its end. */
export const PIN_RAMP = 3;

type V3 = [number, number, number];

/**
 * `positions` (frames × joints × 3) with each planted foot pinned (see the file comment); `contacts` frames × 2.
 * `tolerance` (m): a foot point within this horizontal distance of its anchor is left where it is, one further away
 * is brought back to that distance (a captured foot's lowest point wanders a few millimetres as it rolls).
 */
export function pinFeet(positions: Float32Array, contacts: ArrayLike<number>, joints: readonly string[], tolerance = 0): Float32Array {
  const J = joints.length;
  const frames = positions.length / (J * 3);
  const out = Float32Array.from(positions);
  const legs = findLegs(joints, 'foot pinning');
  const at = (src: Float32Array, f: number, j: number): V3 => [src[(f * J + j) * 3], src[(f * J + j) * 3 + 1], src[(f * J + j) * 3 + 2]];
  legs.forEach((leg, side) => {
    const points = footPoints(leg);
    const { hip, knee, ankle } = leg;
    let f = 0;
    while (f < frames) {
      if (!contacts[f * 2 + side]) {
        f++;
        continue;
      }
      const start = f;
      while (f < frames && contacts[f * 2 + side]) f++;
      const end = f; // exclusive
      const lowest = (g: number) => points.reduce((low, j) => (positions[(g * J + j) * 3 + 1] < positions[(g * J + low) * 3 + 1] ? j : low), points[0]);
      const anchors = new Map<number, V3>();
      for (const j of points) {
        const xs: number[] = [], zs: number[] = [];
        for (let g = start; g < end; g++) {
          if (lowest(g) !== j) continue;
          xs.push(positions[(g * J + j) * 3]);
          zs.push(positions[(g * J + j) * 3 + 2]);
        }
        if (xs.length) anchors.set(j, [median(xs), 0, median(zs)]);
      }
      for (let g = start; g < end; g++) {
        const low = lowest(g);
        const a = anchors.get(low)!;
        const w = Math.min(1, (g - start + 1) / (PIN_RAMP + 1), (end - g) / (PIN_RAMP + 1));
        const ox = a[0] - positions[(g * J + low) * 3], oz = a[2] - positions[(g * J + low) * 3 + 2];
        const off = Math.hypot(ox, oz);
        const share = off > tolerance ? (off - tolerance) / off : 0;
        const dx = ox * share * w, dz = oz * share * w;
        for (const j of points) {
          out[(g * J + j) * 3] += dx;
          out[(g * J + j) * 3 + 2] += dz;
        }
        const h = at(out, g, hip), k = at(out, g, knee), t = at(out, g, ankle);
        const l1 = Math.hypot(k[0] - h[0], k[1] - h[1], k[2] - h[2]);
        const l2 = Math.hypot(at(positions, g, ankle)[0] - k[0], at(positions, g, ankle)[1] - k[1], at(positions, g, ankle)[2] - k[2]);
        const [newKnee] = twoBoneIK(h, k, t, l1, l2, 1, null, 0);
        out.set(newKnee, (g * J + knee) * 3);
      }
    }
  });
  return out;
}

function median(values: number[]): number {
  const v = values.slice().sort((a, b) => a - b);
  return v[Math.floor(v.length / 2)];
}
