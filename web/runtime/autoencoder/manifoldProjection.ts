// The `manifold` method of motion clean-up (issue 16; Holden et al.'s projection onto the motion manifold):
// canonical-skeleton motion at the manifold's fps goes through the shipped denoising convolutional autoencoder
// (public/models/manifold-encoder.onnx, manifold-decoder.onnx) in overlapping windows, and clean canonical
// positions come back.
//
//   world positions (frames × 25 × 3) → rows (web/model/manifoldRows.ts motionRows: local positions, control,
//   contacts), normalised with manifold.json's normalisation
//   → windows of manifold.window frames (120) every HOP = window / 2 frames; the end of the clip (or a whole clip
//     shorter than a window) padded by repeating the last row, as the training's window_at pads
//   → each window: the encoder (rows (1, 120, 80) → latent (1, 30, 256), with the training's zero padding at the
//     window's ends), then the unpadded decoder on the latent padded by `radius` steps at each end by repeating
//     the first and last steps (training/autoencoder/exporting.py decode_clip): 30 + 2·9 steps → 120 frames
//   → the windows cross-faded linearly where they overlap (the weights of the frames a window shares with the
//     window before rise from 0 to 1, those it shares with the window after fall back; normalised to sum 1), cut
//     to the clip's frames, denormalised
//   → the decoded local positions back in the world with the INPUT's own ground frame (groundFrame of the input
//     positions), not by integrating the decoded control: that drifts over long clips (the control's held-out
//     RMS error is 0.12 m/s forward and 0.24 rad/s turn, manifold.json report.control_rmse); the decoded contact
//     channels > 0.5 are the contacts.
//
// Without contacts the input rows' contact channels are the training mean (0 once normalised), what masked
// noise, the corruption the autoencoder was trained to undo, puts there.
//
// The networks are injected (`encode`, `decode`), so this runs wherever a session does: the latent ERD worker
// (latentErdCore.ts projectManifold) and the unit tests with onnxruntime-web's Node build.
import type { ManifoldInfo } from '../../model/latentErdInfo';
import { motionRows, rowLayout, toWorld } from '../../model/manifoldRows';

/** A manifold.json as it is shipped: the window the autoencoder was trained on (frames) is there too. */
export type ManifoldWindowInfo = ManifoldInfo & { window?: number };

export interface ManifoldProjectionArgs {
  /** Normalised rows (1, frames, dim) flattened → latent (1, frames / pooling, latent) flattened. */
  encode: (windowRowsNormalised: Float32Array, frames: number) => Promise<Float32Array>;
  /** Latent (1, steps, latent) flattened → normalised rows (1, pooling · (steps − 2·radius), dim): the unpadded decoder. */
  decode: (latent: Float32Array, steps: number) => Promise<Float32Array>;
  manifold: ManifoldWindowInfo;
  /** World positions on the manifold's (canonical) skeleton, frames × joints × 3. */
  positions: ArrayLike<number>;
  /** Foot contacts (left, right; 1 planted), frames × 2; without them the rows carry the training mean. */
  contacts?: ArrayLike<number>;
  /** Must be the manifold's fps (resample first). */
  fps: number;
  /** Called before each window with the windows done and their count (a progress bar; may throw to cancel). */
  onWindow?: (done: number, windows: number) => void | Promise<void>;
}

export interface ManifoldProjection {
  /** Frames × joints × 3 world positions. */
  positions: Float32Array;
  /** Frames × 2: the decoded contact channels > 0.5. */
  contacts: Uint8Array;
  /** Windows the clip went through. */
  windows: number;
}

/** The decoded contact channel above which a foot is planted. */
export const CONTACT_THRESHOLD = 0.5;

/** The window length (frames) of a manifold.json: its `window`, a positive multiple of `pooling`. */
export function manifoldWindow(manifold: ManifoldWindowInfo): number {
  const w = manifold.window;
  if (typeof w !== 'number' || !Number.isInteger(w) || w <= 0 || w % manifold.pooling !== 0) {
    throw new Error(`manifold.json's window must be a positive multiple of pooling (${manifold.pooling}) frames, got ${String(w)}`);
  }
  return w;
}

/** Window starts (frames) for a clip of `frames`: every `hop` frames until a window reaches the end; the padded length. */
export function windowStarts(frames: number, window: number, hop: number): { starts: number[]; padded: number } {
  const count = frames <= window ? 1 : Math.ceil((frames - window) / hop) + 1;
  return { starts: Array.from({ length: count }, (_, k) => k * hop), padded: window + (count - 1) * hop };
}

/** The cross-fade weight of frame `i` of window `k` of `count`: rises over the frames it shares with the window before, falls over those it shares with the one after. */
function fadeWeight(i: number, k: number, count: number, window: number, hop: number): number {
  const overlap = window - hop;
  if (overlap <= 0) return 1;
  let w = 1;
  if (k > 0 && i < overlap) w = Math.min(w, (i + 0.5) / overlap);
  if (k < count - 1 && i >= hop) w = Math.min(w, 1 - (i - hop + 0.5) / overlap);
  return w;
}

/** Projects canonical motion onto the motion manifold; see the file comment. */
export async function projectOnManifold(args: ManifoldProjectionArgs): Promise<ManifoldProjection> {
  const { manifold, positions, fps } = args;
  if (fps !== manifold.fps) throw new RangeError(`the manifold runs at ${manifold.fps} fps, got motion at ${fps} fps: resample it first`);
  const layout = rowLayout(manifold);
  const J = layout.joints, D = layout.dim;
  const frames = positions.length / (J * 3);
  if (!Number.isInteger(frames) || frames < 1) throw new RangeError(`positions must hold whole frames of ${J} joints × 3 values, got ${positions.length} values`);
  for (let i = 0; i < positions.length; i++) {
    if (!Number.isFinite(positions[i])) throw new RangeError(`positions[${i}] is ${positions[i]}: every position must be a finite number`);
  }
  const { mean, std } = manifold.normalisation;
  const [k0, k1] = layout.contacts;
  let contacts = args.contacts;
  if (contacts !== undefined && contacts.length !== frames * 2) throw new RangeError(`contacts must hold ${frames * 2} values (frames × 2), got ${contacts.length}`);
  const masked = contacts === undefined;
  contacts ??= new Uint8Array(frames * 2);
  const { rows, ground } = motionRows(positions, contacts, layout, fps);

  const window = manifoldWindow(manifold);
  const hop = window / 2;
  const { pooling, radius, latent: Z } = manifold;
  const steps = window / pooling;
  const { starts, padded } = windowStarts(frames, window, hop);
  // Normalised rows, the end padded by repeating the last frame's row.
  const input = new Float32Array(padded * D);
  for (let f = 0; f < padded; f++) {
    const src = Math.min(f, frames - 1) * D;
    for (let d = 0; d < D; d++) input[f * D + d] = masked && d >= k0 && d < k1 ? 0 : (rows[src + d] - mean[d]) / std[d];
  }

  const sum = new Float64Array(padded * D);
  const weight = new Float64Array(padded);
  const latentPadded = new Float32Array((steps + 2 * radius) * Z);
  for (let k = 0; k < starts.length; k++) {
    await args.onWindow?.(k, starts.length);
    const start = starts[k];
    const z = await args.encode(input.slice(start * D, (start + window) * D), window);
    if (z.length !== steps * Z) throw new Error(`the encoder gave ${z.length} values for ${window} frames, expected ${steps} steps × ${Z}`);
    for (let s = 0; s < steps + 2 * radius; s++) {
      const from = Math.min(Math.max(s - radius, 0), steps - 1);
      latentPadded.set(z.subarray(from * Z, (from + 1) * Z), s * Z);
    }
    const out = await args.decode(latentPadded, steps + 2 * radius);
    if (out.length !== window * D) throw new Error(`the decoder gave ${out.length} values for ${steps + 2 * radius} latent steps, expected ${window} frames × ${D}`);
    for (let i = 0; i < window; i++) {
      const w = fadeWeight(i, k, starts.length, window, hop);
      const f = start + i;
      weight[f] += w;
      for (let d = 0; d < D; d++) sum[f * D + d] += w * out[i * D + d];
    }
  }
  await args.onWindow?.(starts.length, starts.length);

  const [p0] = layout.positions;
  const local = new Float64Array(frames * J * 3);
  const outContacts = new Uint8Array(frames * 2);
  for (let f = 0; f < frames; f++) {
    const phys = (d: number) => (sum[f * D + d] / weight[f]) * std[d] + mean[d];
    for (let i = 0; i < J * 3; i++) local[f * J * 3 + i] = phys(p0 + i);
    for (let c = 0; c < 2; c++) outContacts[f * 2 + c] = phys(k0 + c) > CONTACT_THRESHOLD ? 1 : 0;
  }
  // Back in the world with the input's own smoothed ground frame, not the decoded control (see the file comment).
  return { positions: Float32Array.from(toWorld(local, J, ground)), contacts: outContacts, windows: starts.length };
}
