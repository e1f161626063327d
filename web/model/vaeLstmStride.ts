// The stride a drawn path lacks (training/vae_lstm/stride.py, the same numbers; vae-lstm.json "stride"). The VAE-LSTM
// steps to the sway that a real root's velocity keeps after smoothing; a drawn path's control has none, and without it
// the model stops stepping within seconds and glides. So the control it reads is the drawn control plus the training
// clips' mean sway over one stride at that speed (about the control: each stride's own mean removed), the gait phase
// advancing by 1/period a second from a phase the seed draws. The root still moves by the drawn control itself.
import { Rng } from '../motion/random';
import type { VaeLstmStride } from './vaeLstmInfo';

const PHASE_SEED_SALT = 0x2545f491;

/** Where in the stride a seed's motion starts, in [0, 1) (stride.py phase_start). */
export function phaseStart(seed: number): number {
  return new Rng((seed ^ PHASE_SEED_SALT) >>> 0).uniform();
}

/**
 * The sway (frames × 3: forward m/s, sideways m/s, turn rad/s) for a drawn control (frames × 3) from gait phase
 * `phase`: each frame's period and sway interpolated linearly between the two bands whose speeds bracket its
 * forward speed (the end bands beyond them), the sway linearly between phase bins.
 */
export function strideSway(control: ArrayLike<number>, fps: number, stride: VaeLstmStride, phase: number): Float64Array {
  const { bands, phase_bins: bins } = stride;
  const frames = Math.floor(control.length / 3);
  const out = new Float64Array(frames * 3);
  for (let f = 0; f < frames; f++) {
    const v = control[f * 3];
    let k = -1;
    while (k + 1 < bands.length && bands[k + 1].speed < v) k++;
    let lo = bands[0], hi = bands[0], w = 0;
    if (k >= bands.length - 1) lo = hi = bands[bands.length - 1];
    else if (k >= 0) {
      lo = bands[k];
      hi = bands[k + 1];
      w = (v - lo.speed) / (hi.speed - lo.speed);
    }
    const x = phase * bins;
    const i = Math.trunc(x) % bins, j = (i + 1) % bins, a = x - Math.trunc(x);
    for (let c = 0; c < 3; c++) {
      const low = lo.sway[i][c] + a * (lo.sway[j][c] - lo.sway[i][c]);
      const high = hi.sway[i][c] + a * (hi.sway[j][c] - hi.sway[i][c]);
      out[f * 3 + c] = low + w * (high - low);
    }
    const period = lo.period_s + w * (hi.period_s - lo.period_s);
    phase = (phase + 1 / (period * fps)) % 1;
  }
  return out;
}

/** What the model reads for a drawn control: the control plus the stride's sway from the seed's phase (a copy). */
export function withStride(control: Float64Array, fps: number, stride: VaeLstmStride, seed: number): Float64Array {
  const sway = strideSway(control, fps, stride, phaseStart(seed));
  const read = Float64Array.from(control);
  for (let i = 0; i < sway.length; i++) read[i] += sway[i];
  return read;
}
