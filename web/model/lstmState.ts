// The LSTM state (h or c) of a batched ONNX call is laid out layers × batch × hidden, layer-major (the
// onnx export's layout; generator.json's seed states are one stream's layers × hidden). These move one
// stream's state in and out of a batch.

/** Stream b's L×H state out of a batch's L×B×H state. */
export function stateRow(src: Float32Array, L: number, B: number, H: number, b: number): Float32Array {
  const out = new Float32Array(L * H);
  for (let l = 0; l < L; l++) out.set(src.subarray((l * B + b) * H, (l * B + b + 1) * H), l * H);
  return out;
}

/** Writes one stream's L×H state (`row`) into row b of a batch's L×B×H state `dst` (the inverse of stateRow). */
export function setStateRow(dst: Float32Array, L: number, B: number, H: number, b: number, row: ArrayLike<number>): void {
  for (let l = 0; l < L; l++) {
    for (let i = 0; i < H; i++) dst[(l * B + b) * H + i] = row[l * H + i];
  }
}

/** One stream's L×H state repeated for B batch rows. */
export function repeatState(row: ArrayLike<number>, L: number, B: number, H: number): Float32Array {
  const out = new Float32Array(L * B * H);
  for (let b = 0; b < B; b++) setStateRow(out, L, B, H, b, row);
  return out;
}
