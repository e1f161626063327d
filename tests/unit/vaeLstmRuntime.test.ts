// The VAE-LSTM's runtime (web/runtime/vae_lstm/vaeLstmCore.ts, vaeLstmRequests.ts) on the shipped models, run by
// onnxruntime-web's Node build (the same wasm runtime the browser worker uses): parity with
// tests/fixtures/vae_lstm_reference.json (each of the four graphs, and a whole generation over more than one
// chunk of the cell), seeds, the placement on the asked control, the skeleton fit and the foot lock, paths,
// and the model file's checks. Every number compared comes from the fixture or the model JSON.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { integrateControl, PolylinePath } from '../../web/motion/control';
import { parseVaeLstmInfo, VAE_LSTM_GRAPHS, type VaeLstmGraph, type VaeLstmModel } from '../../web/model/vaeLstmInfo';
import { freeLatents, priorLatents, VaeLstmCore } from '../../web/runtime/vae_lstm/vaeLstmCore';
import { phaseStart, strideSway } from '../../web/model/vaeLstmStride';
import { controlForPath, followPathVae } from '../../web/runtime/vae_lstm/vaeLstmRequests';
import { readRepoFile } from './corpus';
import { bytes, maxAbsDiff, ort, shippedSession } from './shippedModel';

interface GraphCase {
  inputs: Record<string, { dims: number[]; data: number[] }>;
  outputs: Record<string, number[]>;
}
interface Fixture {
  tolerance: number;
  graphs: Record<VaeLstmGraph, GraphCase>;
  generate: { control: number[]; frames: number; z1: number[]; rows: number[] };
  prior: { seed: number; z1: number[]; rho: number; steps: number[][] };
  generate_steps: { zs: number[]; rows: number[] };
  /** The stride's sway for a control and a few seeds (training/vae_lstm/stride.py). */
  stride_sway: { control: number[]; seeds: Record<string, { phase: number; sway: number[] }> };
  /** z1 of a few seeds drawn as the shipped JSON says (generation.draw_z1 with its z1_prior). */
  shipped_prior: { z1_prior: boolean; z1: Record<string, number[]> };
}

const json = JSON.parse(readRepoFile('public/models/vae-lstm.json'));
const info = parseVaeLstmInfo(json, 'public/models/vae-lstm.json');
const model: VaeLstmModel = { info, urls: info.files };
const fixture = JSON.parse(readRepoFile('tests/fixtures/vae_lstm_reference.json')) as Fixture;
const J = info.skeleton.joints.length;
const D = info.rows.dim;

let core: VaeLstmCore;

beforeAll(async () => {
  core = new VaeLstmCore(await shippedSession(info.files.cell), model, ort.Tensor, 1, (_graph, file) => shippedSession(file));
  await core.check();
});

afterAll(() => core?.release());

describe('VAE-LSTM parity with the Python reference', () => {
  for (const graph of Object.keys(VAE_LSTM_GRAPHS) as VaeLstmGraph[]) {
    it(`the ${graph} graph matches torch within the fixture's tolerance`, async () => {
      const out = await core.parity({ graphs: { [graph]: fixture.graphs[graph].inputs } });
      for (const name of VAE_LSTM_GRAPHS[graph].outputs) {
        expect(maxAbsDiff(out[graph]![name], fixture.graphs[graph].outputs[name]), `${graph}.${name}`).toBeLessThan(fixture.tolerance);
      }
    });
  }

  it('a whole generation over more than one chunk of the cell (the state carried between chunks) matches torch', async () => {
    const g = fixture.generate;
    expect(g.frames / info.pooling).toBeGreaterThan(info.chunk_steps);
    const { rows } = await core.parity({ generate: { control: g.control, z1: g.z1 } });
    // The fixture's rows are normalised; the runtime's physical.
    const normalised = Float64Array.from(rows!, (v, i) => (v - info.normalisation.mean[i % D]) / info.normalisation.std[i % D]);
    const err = maxAbsDiff(normalised, g.rows);
    console.log(`# VAE-LSTM generation parity: ${err.toExponential(2)} (normalised rows, ${g.frames} frames)`);
    expect(err).toBeLessThan(fixture.tolerance);
  });

  it('the same generation in teacher mode on per-step latents matches torch, and differs from the free mode', async () => {
    const g = fixture.generate;
    const { rows } = await core.parity({ generate: { control: g.control, z1: g.z1, zs: fixture.generate_steps.zs } });
    const normalised = Float64Array.from(rows!, (v, i) => (v - info.normalisation.mean[i % D]) / info.normalisation.std[i % D]);
    expect(maxAbsDiff(normalised, fixture.generate_steps.rows)).toBeLessThan(fixture.tolerance);
    expect(maxAbsDiff(normalised, g.rows)).toBeGreaterThan(100 * fixture.tolerance);
  });
});

describe('VAE-LSTM generation', () => {
  it('a model trained with z1 in every free step reads it there: z1 repeated at its mix, none for Algorithm 1', () => {
    const z1 = Float32Array.of(0.5, -1, 2);
    expect(freeLatents(z1, 4, { mode: 'z1' })).toBeUndefined();
    expect(freeLatents(z1, 4, { mode: 'z1', mix: 0 })).toBeUndefined();
    expect(freeLatents(z1, 4, { mode: 'steps', rho: 0.9 })).toBeUndefined();
    const free = freeLatents(z1, 4, { mode: 'z1', mix: 0.3 })!;
    expect(free.mix).toBe(0.3);
    expect(Array.from(free.zs)).toEqual([0, 1, 2, 3].flatMap(() => Array.from(z1)));
  });

  it('a seed draws the same z1 and per-step latents as the Python side (generation.prior_latents)', () => {
    const p = fixture.prior;
    expect(maxAbsDiff(priorLatents(p.seed, info.latent).z1, p.z1)).toBeLessThan(1e-6);
    const { z1, zs } = priorLatents(p.seed, info.latent, p.steps.length, p.rho);
    expect(maxAbsDiff(z1, p.z1)).toBeLessThan(1e-6);
    expect(maxAbsDiff(zs!, p.steps.flat())).toBeLessThan(1e-6);
  });

  it('draws z1 from the posteriors of training starts as the Python side does (generation.draw_z1, sampling.z1_prior)', () => {
    const sampling = info.sampling;
    expect(sampling.mode === 'z1' && sampling.z1_prior).toBeTruthy();
    const prior = sampling.mode === 'z1' ? sampling.z1_prior! : undefined;
    expect(fixture.shipped_prior.z1_prior).toBe(true);
    for (const [seed, z1] of Object.entries(fixture.shipped_prior.z1)) {
      expect(maxAbsDiff(priorLatents(Number(seed), info.latent, 0, 0, prior).z1, z1)).toBe(0);
    }
    // Each draw sits at one of the K starts, its own sigma away: nearer to that start than N(0, I) draws would be.
    const z1 = priorLatents(4, info.latent, 0, 0, prior).z1;
    const nearest = Math.min(...prior!.means.map((m) => Math.hypot(...m.map((v, i) => (v - z1[i]) / prior!.sigma[i]))));
    expect(nearest).toBeLessThan(1.5 * Math.sqrt(info.latent));
    expect(maxAbsDiff(z1, priorLatents(4, info.latent).z1)).toBeGreaterThan(0.5);
  });

  it('adds the stride a drawn path lacks as the Python side does (stride.py: the same phase and sway)', () => {
    const { control, seeds } = fixture.stride_sway;
    for (const [seed, want] of Object.entries(seeds)) {
      expect(phaseStart(Number(seed))).toBe(want.phase);
      expect(maxAbsDiff(strideSway(control, info.fps, info.stride!, want.phase), want.sway)).toBeLessThan(1e-12);
    }
  });

  it('keeps stepping on a drawn straight path with the stride added, and glides without it', async () => {
    const frames = 450; // 15 s at 1.2 m/s
    const control = Array.from({ length: frames * 3 }, (_, i) => (i % 3 === 0 ? 1.2 : 0));
    const J = info.rows.joints.length, toe = info.rows.joints.indexOf('RightToeBase'), D = info.rows.dim;
    const lastSwing = (rows: Float32Array) => {
      // The toe's forward offset from the hips (root facing frame) over each of the last 5 seconds: its range, averaged.
      let sum = 0;
      for (let s = frames - 150; s < frames; s += 30) {
        let lo = Infinity, hi = -Infinity;
        for (let f = s; f < s + 30; f++) {
          const fwd = rows[f * D + toe * 3 + 2] - rows[f * D + 2];
          lo = Math.min(lo, fwd);
          hi = Math.max(hi, fwd);
        }
        sum += (hi - lo) / 5;
      }
      return sum;
    };
    expect(J).toBeGreaterThan(toe);
    const walking = await core.generate({ seed: 2, frames, control, footLock: false });
    const gliding = await core.generate({ seed: 2, frames, control, footLock: false, stride: false });
    expect(lastSwing(walking.rows)).toBeGreaterThan(0.4); // a real walk swings the toe about 0.7 m a second
    expect(lastSwing(gliding.rows)).toBeLessThan(0.1);
    expect(Array.from(walking.roots)).toEqual(Array.from(gliding.roots)); // the root moves by the control either way
  });

  it('the seed draws z1: the same seed gives the same motion, another seed another one', async () => {
    const control = Array.from({ length: 90 * 3 }, (_, i) => (i % 3 === 0 ? 1.2 : 0));
    const a = await core.generate({ seed: 4, frames: 90, control });
    const b = await core.generate({ seed: 4, frames: 90, control });
    const c = await core.generate({ seed: 5, frames: 90, control });
    expect(bytes(b.positions)).toEqual(bytes(a.positions));
    expect(maxAbsDiff(a.z1, priorLatents(4, info.latent, 0, 0, info.sampling.mode === 'z1' ? info.sampling.z1_prior : undefined).z1)).toBe(0);
    expect(maxAbsDiff(c.rows, a.rows)).toBeGreaterThan(1e-3);
  });

  it('the root moves by the asked control, the points are placed at it and fitted to the skeleton', async () => {
    const frames = 61; // not a multiple of 4: the control is padded, the motion is not
    const control = Array.from({ length: frames * 3 }, (_, i) => [1.1, 0, 0.5][i % 3]);
    const m = await core.generate({ seed: 2, frames, control, footLock: false });
    expect(m.frames).toBe(frames);
    expect(m.positions.length).toBe(frames * J * 3);
    const { xz, heading } = integrateControl(control, info.fps);
    for (let f = 0; f < frames; f++) {
      expect(m.roots[f * 3]).toBeCloseTo(xz[f * 2], 9);
      expect(m.roots[f * 3 + 1]).toBeCloseTo(xz[f * 2 + 1], 9);
      expect(m.roots[f * 3 + 2]).toBeCloseTo(heading[f], 9);
    }
    // Every bone has its rest length after the fit.
    const { parents, offsets } = core.skeleton;
    let worst = 0;
    for (let f = 0; f < frames; f++) {
      for (let j = 1; j < J; j++) {
        const p = parents[j];
        const d = Math.hypot(...[0, 1, 2].map((k) => m.positions[(f * J + j) * 3 + k] - m.positions[(f * J + p) * 3 + k]));
        worst = Math.max(worst, Math.abs(d - Math.hypot(offsets[j * 3], offsets[j * 3 + 1], offsets[j * 3 + 2])));
      }
    }
    expect(worst).toBeLessThan(1e-4);
    // Without the lock the contacts are the decoded channels.
    expect(bytes(m.contacts)).toEqual(bytes(m.decodedContacts));
  });

  it('without a control it follows randomControl(seed); with the lock the feet are planted on labelled contacts', async () => {
    const m = await core.generate({ seed: 9, frames: 120 });
    expect(m.control.length).toBe(120 * 3);
    expect(m.control[0]).toBeGreaterThan(0);
    // The lock moves planted feet, not the rest of the body.
    expect(maxAbsDiff(m.positions, m.fitted)).toBeGreaterThan(0);
    expect(maxAbsDiff(m.positions.subarray(0, 3), m.fitted.subarray(0, 3))).toBe(0);
  });

  it('refuses a control shorter than the motion and a z1 of the wrong size', async () => {
    await expect(core.generate({ seed: 0, frames: 10, control: [1, 0, 0] })).rejects.toThrow(/control has 1 frames; it needs at least 10/);
    await expect(core.generate({ seed: 0, frames: 8 }, undefined, { z1: [1, 2] })).rejects.toThrow(/z1 has 2 values/);
    await expect(core.generate({ seed: 0, frames: 40 }, undefined, { z1: new Float32Array(info.latent), zs: new Float32Array(info.latent) })).rejects.toThrow(/zs has 1 steps; the control needs 10/);
  });
});

describe('VAE-LSTM paths', () => {
  it('the path becomes one control signal that walks a bare root along it and stops at the end', () => {
    const path = new PolylinePath([[0, 0], [0, 4], [3, 4]]);
    const control = controlForPath(path, { x: 0, z: 0, heading: 0 }, 1.2, info.fps, 1000);
    const { xz } = integrateControl(control, info.fps);
    const n = control.length / 3;
    expect(Math.hypot(xz[(n - 1) * 2] - 3, xz[(n - 1) * 2 + 1] - 4)).toBeLessThan(0.1);
    expect(control.subarray(control.length - 3).every((v) => v === 0)).toBe(true);
  });

  it('followPath walks the path: small error, the whole path, stats like the other followers', async () => {
    const fractions: number[] = [];
    const r = await followPathVae(core, { points: [[10, 10], [10, 14], [13, 14]], gait: 'walk', seed: 1 }, (f) => fractions.push(f));
    expect(r.stats.meanError).toBeLessThan(0.15);
    expect(r.stats.arcProgress).toBeGreaterThan(0.95);
    expect(fractions.at(-1)).toBe(1);
    // Moved back to where the path is.
    expect(Math.hypot(r.positions[0] - 10, r.positions[2] - 10)).toBeLessThan(0.3);
    for (const key of ['skating', 'skatingBeforeLock', 'sliding', 'slidingBeforeLock', 'optimizeMs'] as const) expect(Number.isFinite(r.stats[key]), key).toBe(true);
    await expect(followPathVae(core, { points: [[0, 0]], gait: 'walk', seed: 0 }, () => undefined)).rejects.toThrow(/at least 2/);
  });
});

describe('vae-lstm.json checks', () => {
  it('names the file and the first bad field', () => {
    expect(() => parseVaeLstmInfo({ ...json, files: { ...json.files, decoder: '' } }, 'x.json')).toThrow(/x\.json: files\.decoder must name/);
    expect(() => parseVaeLstmInfo({ ...json, onnx: { ...json.onnx, cell: { inputs: ['hc'], outputs: ['canvas', 'state_out'] } } })).toThrow(/onnx\.cell\.inputs is \[hc\], expected \[hc,state,z,mix\]/);
    expect(() => parseVaeLstmInfo({ ...json, pooling: 2 })).toThrow(/pooling must be 4/);
    expect(() => parseVaeLstmInfo({ ...json, sampling: { mode: 'steps', rho: 1 } })).toThrow(/sampling\.rho must be in \[0, 1\)/);
    expect(() => parseVaeLstmInfo({ ...json, sampling: { mode: 'many' } })).toThrow(/sampling\.mode must be "z1" or "steps"/);
    expect(() => parseVaeLstmInfo({ ...json, sampling: { mode: 'z1', mix: 1 } })).toThrow(/sampling\.mix must be in \[0, 1\)/);
    expect(() => parseVaeLstmInfo({ ...json, stride: { ...json.stride, phase_bins: 1 } })).toThrow(/stride\.phase_bins must be an integer of at least 2/);
    expect(() => parseVaeLstmInfo({ ...json, stride: { ...json.stride, bands: [...json.stride.bands].reverse() } })).toThrow(/stride\.bands\[1\]\.speed must be a number above/);
    expect(() => parseVaeLstmInfo({ ...json, stride: { ...json.stride, bands: [{ ...json.stride.bands[0], sway: [[0, 0, 0]] }] } })).toThrow(/stride\.bands\[0\]\.sway must be 16 rows of 3 finite numbers/);
    const prior = json.sampling.z1_prior;
    expect(() => parseVaeLstmInfo({ ...json, sampling: { ...json.sampling, z1_prior: { ...prior, means: [prior.means[0].slice(1)] } } })).toThrow(/sampling\.z1_prior\.means must be a non-empty list of rows of 128 finite numbers/);
    expect(() => parseVaeLstmInfo({ ...json, sampling: { ...json.sampling, z1_prior: { ...prior, sigma: prior.sigma.map(() => -1) } } })).toThrow(/sampling\.z1_prior\.sigma must be 128 numbers, none negative/);
    expect(() => parseVaeLstmInfo({ ...json, rows: { ...json.rows, control: [75, 77] } })).toThrow(/rows\.control is \[75, 77\]/);
  });
});
