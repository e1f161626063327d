// A stand-in for a sampled (mdn) dance model's ONNX session (issue 42's interface), for testing DanceCore's sampled
// path without an exported model: a tiny one-layer recurrent network with a K-component mixture head, then the phrase
// rule (training/aclstm/phrase_sampling.py: redraw, inverse-CDF draw on the step's uniform, AR(1) wander) and the
// causal biquad on the drawn frames, exactly as the graph runs them, in JavaScript. It records every call's feeds
// and outputs, so tests can check what the page passes in and what it does with what comes out.
import type { InferenceSession } from 'onnxruntime-web';
import { DANCE_MDN_INPUTS, DANCE_MDN_OUTPUTS, type DanceInfo } from '../../web/runtime/aclstm/danceModel';
import { Rng } from '../../web/motion/random';
import { ort } from './shippedModel';
import { readRepoFile } from './corpus';

export const FAKE_HIDDEN = 6;
export const FAKE_COMPONENTS = 4;

/** The shipped acLSTM's JSON (skeleton, seeds, normalisation) turned into a sampled model's, with the fake's sizes. */
export function fakeMdnInfo(): DanceInfo & Record<string, any> {
  const raw = JSON.parse(readRepoFile('public/models/aclstm.json'));
  raw.id = 'fake-mdn';
  raw.file = 'fake-mdn.onnx';
  raw.head = 'mdn';
  raw.components = FAKE_COMPONENTS;
  raw.onnx = { ...raw.onnx, inputs: [...DANCE_MDN_INPUTS], outputs: [...DANCE_MDN_OUTPUTS], layers: 1, hidden: FAKE_HIDDEN };
  raw.sampling = {
    rule: 'phrase',
    params: {
      salsa: { temperature: 0.3, max_hold: 12, rho: 0.9, threshold: 0.1, min_hold: 3 },
      indian: { temperature: 0.5, max_hold: 20, rho: 0.8, threshold: 0.05, min_hold: 5 },
      martial: { temperature: 0.2, max_hold: 8, rho: 0.95, threshold: 0.15, min_hold: 2 },
    },
    // Second-order Butterworth low-passes at 6, 8 and 10 Hz for 30 fps (bilinear transform, unit gain at 0 Hz).
    filter: {
      salsa: { cutoff_hz: 6, b: [0.20657208, 0.41314417, 0.20657208], a: [1, -0.36952738, 0.19581571] },
      indian: { cutoff_hz: 8, b: [0.32424464, 0.64848928, 0.32424464], a: [1, 0.12274123, 0.17423734] },
      martial: { cutoff_hz: 10, b: [0.46515308, 0.93030615, 0.46515308], a: [1, 0.6202041, 0.24040821] },
    },
  };
  return raw;
}

export interface FakeCall {
  feeds: Record<string, ort.Tensor>;
  outputs: Record<string, ort.Tensor>;
}

/** A fake InferenceSession running the interface's step rule; `calls` holds every call's feeds and outputs. */
export function fakeMdnSession(info: DanceInfo): InferenceSession & { calls: FakeCall[] } {
  const D = info.onnx.dim, S = info.styles.length, H = FAKE_HIDDEN, K = FAKE_COMPONENTS;
  const rng = new Rng(20260412);
  const matrix = (rows: number, cols: number, scale: number) => Float64Array.from({ length: rows * cols }, () => scale * rng.normal());
  const wx = matrix(H, D, 0.3 / Math.sqrt(D)), ws = matrix(H, S, 0.5), wh = matrix(H, H, 0.6 / Math.sqrt(H));
  const wl = matrix(K, H, 2.5), wm = matrix(K * D, H, 0.4), bm = matrix(K, D, 0.3), ls = matrix(K, D, 0.2);
  const calls: FakeCall[] = [];

  function run(feeds: Record<string, ort.Tensor>): Record<string, ort.Tensor> {
    const f = (n: string) => feeds[n].data as Float32Array;
    const i = (n: string) => feeds[n].data as BigInt64Array;
    const B = feeds.x.dims[0];
    const steps = Number(i('steps')[0]);
    for (const n of DANCE_MDN_INPUTS) if (!feeds[n]) throw new Error(`fake mdn session: missing input ${n}`);
    const want: Record<string, number[]> = {
      x: [B, D], style: [B, S], h: [1, B, H], c: [1, B, H], held: [B], age: [B], wander: [B, D], temperature: [B], rho: [B], threshold: [B],
      max_hold: [B], min_hold: [B], uniforms: [steps, B], normals: [steps, B, D], filt: [B, 4, D], filter_b: [B, 3], filter_a: [B, 2],
    };
    for (const [n, dims] of Object.entries(want)) {
      if (feeds[n].dims.join() !== dims.join()) throw new Error(`fake mdn session: ${n} has dims ${feeds[n].dims}, expected ${dims}`);
    }
    const x = Float32Array.from(f('x')), h = Float32Array.from(f('h')), c = Float32Array.from(f('c'));
    const held = BigInt64Array.from(i('held')), age = BigInt64Array.from(i('age'));
    const wander = Float32Array.from(f('wander')), filt = Float32Array.from(f('filt'));
    const ys = new Float32Array(steps * B * D), display = new Float32Array(steps * B * D), weightsOut = new Float32Array(steps * B * K);
    const hNew = new Float64Array(H), logits = new Float64Array(K), weights = new Float64Array(K), allowed = new Float64Array(K);
    for (let k = 0; k < steps; k++) {
      for (let b = 0; b < B; b++) {
        // The network: h' = tanh(Wx x + Ws style + Wh h), c' = (c + h') / 2; mixture from h'.
        for (let j = 0; j < H; j++) {
          let s = 0;
          for (let d = 0; d < D; d++) s += wx[j * D + d] * x[b * D + d];
          for (let t = 0; t < S; t++) s += ws[j * S + t] * f('style')[b * S + t];
          for (let t = 0; t < H; t++) s += wh[j * H + t] * h[b * H + t];
          hNew[j] = Math.tanh(s);
        }
        for (let j = 0; j < H; j++) {
          h[b * H + j] = hNew[j];
          c[b * H + j] = (c[b * H + j] + hNew[j]) / 2;
        }
        let top = 0, total = 0;
        for (let m = 0; m < K; m++) {
          logits[m] = 0;
          for (let j = 0; j < H; j++) logits[m] += wl[m * H + j] * hNew[j];
          if (logits[m] > logits[top]) top = m;
        }
        for (let m = 0; m < K; m++) total += weights[m] = Math.exp(logits[m] - logits[top]);
        for (let m = 0; m < K; m++) weightsOut[(k * B + b) * K + m] = weights[m] /= total;
        // The phrase rule.
        const threshold = f('threshold')[b];
        const fresh = held[b] < 0n;
        const weak = age[b] >= i('min_hold')[b] && weights[fresh ? 0 : Number(held[b])] < threshold;
        if (fresh || age[b] >= i('max_hold')[b] || weak) {
          let sum = 0;
          for (let m = 0; m < K; m++) sum += allowed[m] = weights[m] >= threshold ? weights[m] : 0;
          if (sum <= 0) {
            allowed.fill(0);
            allowed[top] = 1;
            sum = 1;
          }
          const u = f('uniforms')[k * B + b] * sum;
          let drawn = 0, cumulative = 0;
          for (let m = 0; m < K; m++) if ((cumulative += allowed[m]) <= u) drawn++;
          held[b] = BigInt(drawn);
          age[b] = 0n;
        }
        age[b] += 1n;
        const rho = f('rho')[b], temperature = f('temperature')[b];
        const m = Number(held[b]);
        const [b0, b1, b2] = f('filter_b').subarray(b * 3, b * 3 + 3);
        const [a1, a2] = f('filter_a').subarray(b * 2, b * 2 + 2);
        for (let d = 0; d < D; d++) {
          const w = (wander[b * D + d] = rho * wander[b * D + d] + Math.sqrt(1 - rho * rho) * f('normals')[(k * B + b) * D + d]);
          let mu = bm[m * D + d];
          for (let j = 0; j < H; j++) mu += wm[(m * D + d) * H + j] * hNew[j];
          const y = mu + temperature * Math.exp(ls[m * D + d]) * w;
          const o = b * 4 * D + d;
          const [x1, x2, y1, y2] = [filt[o], filt[o + D], filt[o + 2 * D], filt[o + 3 * D]];
          const shown = b0 * y + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
          filt[o] = y;
          filt[o + D] = x1;
          filt[o + 2 * D] = shown;
          filt[o + 3 * D] = y1;
          ys[(k * B + b) * D + d] = y;
          display[(k * B + b) * D + d] = shown;
          x[b * D + d] = y;
        }
      }
    }
    const t = (data: Float32Array | BigInt64Array, dims: number[]) => new ort.Tensor(data instanceof BigInt64Array ? 'int64' : 'float32', data, dims);
    return {
      ys: t(ys, [steps, B, D]),
      display: t(display, [steps, B, D]),
      h_out: t(h, [1, B, H]),
      c_out: t(c, [1, B, H]),
      held_out: t(held, [B]),
      age_out: t(age, [B]),
      wander_out: t(wander, [B, D]),
      filt_out: t(filt, [B, 4, D]),
      weights: t(weightsOut, [steps, B, K]),
    };
  }

  const session = {
    inputNames: [...DANCE_MDN_INPUTS],
    outputNames: [...DANCE_MDN_OUTPUTS],
    calls,
    async run(feeds: Record<string, ort.Tensor>) {
      // Copies of the feeds: the caller may reuse its arrays.
      const copied = Object.fromEntries(Object.entries(feeds).map(([n, v]) => [n, new ort.Tensor(v.type as 'float32', (v.data as Float32Array).slice(), v.dims)]));
      const outputs = run(copied);
      calls.push({ feeds: copied, outputs });
      return outputs;
    },
    async release() {},
  };
  return session as unknown as InferenceSession & { calls: FakeCall[] };
}

/** The first index where two float arrays differ bit for bit (−1 when they are identical, −2 when their lengths differ): a failure prints a number, not two long arrays. */
export function firstBitDifference(a: Float32Array, b: Float32Array): number {
  if (a.length !== b.length) return -2;
  const x = new Uint32Array(a.buffer, a.byteOffset, a.length), y = new Uint32Array(b.buffer, b.byteOffset, b.length);
  for (let i = 0; i < x.length; i++) if (x[i] !== y[i]) return i;
  return -1;
}
