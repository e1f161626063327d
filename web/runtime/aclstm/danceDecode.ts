// Dance feature rows (physical units) → world positions of the 57 skeleton points. A port of
// training/data/dance.py `decode`; keep the two in step.
//   x(t) = [r_x(t) − r_x(t−1), r_y(t), r_z(t) − r_z(t−1), p_j(t) − r(t) for points j = 1…]
// The root's x and z integrate the steps (from where the previous frame ended), its height is absolute,
// and every other point is the root plus its offset (world axes).

/** Where the root stands (x, z, metres) before the first decoded frame. */
export interface DanceRoot {
  x: number;
  z: number;
}

export interface DecodedDance {
  /** frames × joints × 3, world metres. */
  positions: Float32Array;
  /** Root x, z after the last frame, in double precision: pass it as `start` to continue. */
  end: DanceRoot;
}

export function decodeDance(features: ArrayLike<number>, joints: number, start: DanceRoot = { x: 0, z: 0 }): DecodedDance {
  const D = joints * 3;
  if (features.length % D !== 0) throw new Error(`decodeDance: ${features.length} values is not a whole number of ${D}-value frames`);
  const frames = features.length / D;
  const positions = new Float32Array(frames * D);
  let x = start.x;
  let z = start.z;
  for (let f = 0; f < frames; f++) {
    const o = f * D;
    x += features[o];
    z += features[o + 2];
    const y = features[o + 1];
    positions[o] = x;
    positions[o + 1] = y;
    positions[o + 2] = z;
    for (let k = 3; k < D; k += 3) {
      positions[o + k] = x + features[o + k];
      positions[o + k + 1] = y + features[o + k + 1];
      positions[o + k + 2] = z + features[o + k + 2];
    }
  }
  return { positions, end: { x, z } };
}
