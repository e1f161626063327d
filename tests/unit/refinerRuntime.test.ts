// The refiner runtime (web/runtime/refiner/refinerCore.ts) on the shipped models, run by onnxruntime-web's Node build
// (the same wasm runtime the browser worker uses): the JSON checks, one-step parity and the end effectors
// against tests/fixtures/refiner_reference.json (Python onnxruntime), the streamed refinement, and the
// generator's `refine` streams (raw frames unchanged, refined + foot-locked frames that skate less).
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { footSkating } from '../../web/motion/footSkating';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { RefinerCore } from '../../web/runtime/refiner/refinerCore';
import { checkRefinerPairing, parseRefinerInfo, type RefinerInfo } from '../../web/runtime/refiner/refinerModel';
import type { GeneratedChunk } from '../../web/runtime/generator/protocol';
import { readRepoFile } from './corpus';
import { bytes, ort, shippedSession } from './shippedModel';

interface RefinerFixture {
  batch: number;
  hidden: number;
  dim: number;
  frames: number;
  end_effectors: string[];
  frames_normalised: number[];
  frames_physical: number[];
  ends: number[];
  calls: { frames: number; inputs: Record<'x' | 'ends' | 'ends_prev' | 'h' | 'c', number[]>; outputs: Record<'x_refined' | 'h_out' | 'c_out', number[]> }[];
}

const PARITY_TOLERANCE = 1e-4;
const generatorInfo = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json');
const rawRefinerJson = JSON.parse(readRepoFile('public/models/refiner.json'));
const refinerInfo = parseRefinerInfo(rawRefinerJson, 'public/models/refiner.json');
const fixture = JSON.parse(readRepoFile('tests/fixtures/refiner_reference.json')) as RefinerFixture;
const D = fixture.dim;
const E3 = fixture.end_effectors.length * 3;

/** |a − b| / max(1, |b|), the export's parity measure. */
function worstScaled(a: ArrayLike<number>, b: ArrayLike<number>): number {
  if (a.length !== b.length) return Infinity;
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]) / Math.max(1, Math.abs(b[i])));
  return worst;
}

let refiner: RefinerCore;
let generator: GeneratorCore;
let loads = 0;

beforeAll(async () => {
  refiner = new RefinerCore(await shippedSession(refinerInfo.file), refinerInfo, generatorInfo, ort.Tensor);
  await refiner.check();
  generator = new GeneratorCore(await shippedSession(generatorInfo.file), generatorInfo, ort.Tensor, 1, {
    loadRefiner: async () => {
      loads++;
      return refiner;
    },
  });
});

afterAll(async () => {
  await generator?.release(); // releases the refiner it loaded too
});

describe('refiner.json', () => {
  it('parses and fits the shipped generator', () => {
    expect(refinerInfo.end_effectors.names).toEqual(fixture.end_effectors);
    expect(() => checkRefinerPairing(refinerInfo, generatorInfo)).not.toThrow();
  });

  it('names the first bad field of a broken file', () => {
    const broken = (edit: (j: RefinerInfo) => void) => {
      const j = structuredClone(rawRefinerJson) as RefinerInfo;
      edit(j);
      return () => parseRefinerInfo(j, 'refiner.json');
    };
    expect(broken((j) => (j.onnx.inputs = ['x', 'h', 'c']))).toThrow(/refiner.json: onnx.inputs is \[x,h,c\], expected \[x,ends,ends_prev,h,c\]/);
    expect(broken((j) => (j.onnx.ends = 20))).toThrow(/end_effectors.names has 7 names but onnx.ends is 20/);
    expect(broken((j) => (j.normalisation.std[3] = 0))).toThrow(/normalisation.std\[3\] = 0 must be positive/);
    expect(broken((j) => (j.footlock.reach = 1.5))).toThrow(/footlock.reach must be at most 1/);
    expect(broken((j) => (j.kind = 'lstm-gmm'))).toThrow(/kind must be "refiner"/);
    const misplaced = structuredClone(refinerInfo);
    misplaced.end_effectors.joints[0] = 3;
    expect(() => checkRefinerPairing(misplaced, generatorInfo)).toThrow(/end_effectors.joints\[0\] = 3 is "LeftFoot" in the generator's skeleton, not "LeftHand"/);
  });
});

describe('RefinerCore', () => {
  it('matches Python onnxruntime call by call (3 frames, then 1) within 1e-4', async () => {
    expect(fixture.calls.map((c) => c.frames)).toEqual([3, 1]);
    for (const [k, call] of fixture.calls.entries()) {
      const out = await refiner.parity({ batch: fixture.batch, frames: call.frames, ...call.inputs });
      for (const name of ['x_refined', 'h_out', 'c_out'] as const) {
        expect(worstScaled(out[name], call.outputs[name]), `call ${k} ${name}`).toBeLessThan(PARITY_TOLERANCE);
      }
    }
  });

  it('computes the root-frame end effectors of physical frames as the Python side does', () => {
    const ends = refiner.endEffectors(Float32Array.from(fixture.frames_physical));
    expect(ends.length).toBe(fixture.ends.length);
    expect(worstScaled(ends, fixture.ends)).toBeLessThan(1e-5);
    // The same frames walked far from the origin and turned give the same root-frame positions.
    const moved = Float32Array.from(fixture.frames_physical);
    for (let f = 0; f < moved.length / D; f++) {
      moved[f * D] += 3;
      moved[f * D + 2] += 0.7;
    }
    expect(Array.from(refiner.endEffectors(moved))).toEqual(Array.from(ends));
  });

  it('streams the fixture frames through refine() in one call with the fixture calls\' outputs', async () => {
    // Frame t's expected output: call 1 holds frames 1-3 (batch × 3 × D), call 2 frame 4 (batch × 1 × D).
    const expectedFrame = (b: number, t: number) => {
      const call = t < 3 ? fixture.calls[0] : fixture.calls[1];
      const k = b * call.frames + (t < 3 ? t : 0);
      return call.outputs.x_refined.slice(k * D, (k + 1) * D);
    };
    const frames = fixture.frames;
    for (let b = 0; b < fixture.batch; b++) {
      const row = (data: number[], f: number) => data.slice((b * frames + f) * D, (b * frames + f + 1) * D);
      const stream = refiner.createStream(Float32Array.from(row(fixture.frames_physical, 0)));
      const normalised = Float32Array.from(Array.from({ length: frames - 1 }, (_, f) => row(fixture.frames_normalised, f + 1)).flat());
      const physical = Float32Array.from(Array.from({ length: frames - 1 }, (_, f) => row(fixture.frames_physical, f + 1)).flat());
      const refined = await refiner.refine(stream, normalised, physical);
      for (let t = 0; t < frames - 1; t++) {
        const expected = expectedFrame(b, t);
        const got = Array.from(refined.features.subarray(t * D, (t + 1) * D), (v, d) => (v - refinerInfo.normalisation.mean[d]) / refinerInfo.normalisation.std[d]);
        expect(worstScaled(got, expected), `stream ${b} step ${t}`).toBeLessThan(PARITY_TOLERANCE);
      }
      expect(worstScaled(stream.h, fixture.calls[1].outputs.h_out.slice(b * fixture.hidden, (b + 1) * fixture.hidden))).toBeLessThan(PARITY_TOLERANCE);
    }
  });

  it('rejects parity inputs of the wrong size with a clear message', async () => {
    await expect(refiner.parity({ batch: 1, frames: 1, x: [1, 2], ends: [], ends_prev: [], h: [], c: [] })).rejects.toThrow(/refiner parity inputs do not fit batch 1 × 1 frames: x 2 \(expected 69\)/);
  });
});

describe('GeneratorCore with refine', () => {
  const motion = (chunk: GeneratedChunk, refined: boolean) => {
    const part = refined ? chunk.refined! : chunk;
    return { fps: 30, frames: chunk.frames, joints: generatorInfo.skeleton.joints, parents: generatorInfo.skeleton.parents, positions: part.positions, contacts: part.contacts };
  };

  it('keeps the raw frames exactly and adds refined, foot-locked frames', async () => {
    const raw = await generator.generate({ frames: 300, seed: 3, temperature: 0.5 });
    const both = await generator.generate({ frames: 300, seed: 3, temperature: 0.5, refine: true });
    expect(loads).toBe(1);
    expect(raw.refined).toBeUndefined();
    // The generator is fed its own raw frames: refining changes nothing about them.
    expect(bytes(both.features)).toEqual(bytes(raw.features));
    expect(bytes(both.positions)).toEqual(bytes(raw.positions));
    const r = both.refined!;
    const J = generatorInfo.skeleton.joints.length;
    expect(r.positions.length).toBe(300 * J * 3);
    expect(r.contacts.length).toBe(600);
    expect(r.features.length).toBe(300 * D);
    expect(r.positions.every(Number.isFinite)).toBe(true);
    expect(r.contacts.every((c) => c === 0 || c === 1)).toBe(true);
    expect(bytes(r.positions)).not.toEqual(bytes(raw.positions));
    const rawSkating = footSkating(motion(raw, false));
    const refinedSkating = footSkating(motion(both, true));
    expect(rawSkating).toBeGreaterThan(0.5);
    expect(refinedSkating).toBeLessThan(0.3 * rawSkating);
    // The refined character walks its own (close) path from the same start.
    const hips = (P: Float32Array, f: number) => [P[f * J * 3], P[f * J * 3 + 2]];
    const [ax, az] = hips(raw.positions, 299), [bx, bz] = hips(r.positions, 299);
    expect(Math.hypot(ax - bx, az - bz)).toBeLessThan(3);
  });

  it('is deterministic, and streams in chunks exactly what generate gives in one go', async () => {
    const whole = await generator.generate({ frames: 50, seed: 8, temperature: 0.7, refine: true });
    const again = await generator.generate({ frames: 50, seed: 8, temperature: 0.7, refine: true });
    expect(bytes(again.refined!.positions)).toEqual(bytes(whole.refined!.positions));
    const stream = generator.createStream({ seed: 8, temperature: 0.7, refine: true });
    const a = await generator.advance(stream, 20), b = await generator.advance(stream, 30);
    const joined = new Float32Array(whole.refined!.positions.length);
    joined.set(a.refined!.positions);
    joined.set(b.refined!.positions, a.refined!.positions.length);
    expect(bytes(joined)).toEqual(bytes(whole.refined!.positions));
    expect(Array.from(a.refined!.contacts).concat(Array.from(b.refined!.contacts))).toEqual(Array.from(whole.refined!.contacts));
  });

  it('says why when the refiner cannot load, and tries again next time', async () => {
    let attempts = 0;
    const failing = new GeneratorCore(await shippedSession(generatorInfo.file), generatorInfo, ort.Tensor, 1, {
      loadRefiner: async () => {
        attempts++;
        throw new Error('refiner model models/refiner.onnx: HTTP 404 Not Found');
      },
    });
    try {
      await expect(failing.generate({ frames: 5, seed: 1, temperature: 0.5, refine: true })).rejects.toThrow(/HTTP 404/);
      await expect(failing.generate({ frames: 5, seed: 1, temperature: 0.5, refine: true })).rejects.toThrow(/HTTP 404/);
      expect(attempts).toBe(2);
      const plain = await failing.generate({ frames: 5, seed: 1, temperature: 0.5 });
      expect(plain.frames).toBe(5);
      expect(() => failing.createStream({ seed: 1, temperature: 0.5, refine: 'yes' as unknown as boolean })).toThrow(/refine must be true or false/);
    } finally {
      await failing.release();
    }
  });
});
