// The optimiser over the shipped generator, run by onnxruntime-web's Node build: the steered rollout
// reduces to free generation when steering has no authority, imposes its target with full authority,
// and the path follower and live controller do what they are for on short runs.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { exportBVH } from '../../web/motion/bvh';
import { footSkating } from '../../web/motion/footSkating';
import { validateMotion } from '../../web/motion/validate';
import { checkSchedule, LiveController, simulateControl } from '../../web/optimizer/liveControl';
import { angleDifference, GroundPath, type GroundPoint } from '../../web/optimizer/path';
import { OptimizerRequests } from '../../web/runtime/generator/optimizerRequests';
import type { FollowPathParams } from '../../web/runtime/generator/protocol';
import { followPath } from '../../web/optimizer/pathFollower';
import { rollout, type SteerRequest, type Variables } from '../../web/optimizer/rollout';
import { heldNormal, Rng } from '../../web/model/sampler';
import { noiseCorrelation } from '../../web/model/generatorInfo';
import { readRepoFile } from './corpus';
import { bytes, ort, shippedSession } from './shippedModel';

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json');
const D = info.onnx.dim;
let core: GeneratorCore;
const step = (b: number, x: Float32Array, h: Float32Array, c: Float32Array) => core.step(b, x, h, c);

beforeAll(async () => {
  core = new GeneratorCore(await shippedSession(info.file), info, ort.Tensor);
});
afterAll(() => core?.release());

function seedState(i: number) {
  const s = info.seeds[i];
  return { x: Float32Array.from(s.x), h: Float32Array.from(s.h), c: Float32Array.from(s.c), root: { x: 0, z: 0, heading: 0 } };
}

/** All-zero sampling variables: the heaviest component's mean, no input noise. */
function zeroVariables(P: number, T: number): Variables {
  return { P, T, u: new Float64Array(P * T), z: new Float32Array(P * T * D), d: new Float32Array(P * T * D) };
}

const steer = (target: number[], authority: number) => ({
  target(_b: number, _t: number, _x: number, _z: number, _h: number, out: SteerRequest) {
    out.target.set(target);
    out.authority.fill(authority);
  },
});

/**
 * One particle's variables drawn in the sampler's order (a uniform, then D normals, each frame), no input noise. With
 * `heldRoot` the root channels (Δtx, Δtz, Δry, which the rollout draws fresh) get the normals free generation would
 * hold there, so the rollout draws what free generation draws.
 */
function samplerOrderVariables(seed: number, T: number, heldRoot?: number): Variables {
  const rng = new Rng(seed);
  const v = zeroVariables(1, T);
  for (let t = 0; t < T; t++) {
    v.u[t] = rng.uniform();
    for (let k = 0; k < D; k++) {
      const fresh = rng.normal();
      v.z[t * D + k] = heldRoot !== undefined && k < 3 && t > 0 ? heldNormal(v.z[(t - 1) * D + k], fresh, heldRoot) : fresh;
    }
  }
  return v;
}

function largestDifference(a: ArrayLike<number>, b: ArrayLike<number>): number {
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]));
  return worst;
}

describe('rollout', () => {
  it('holds the pose channels\' normals over frames as free generation does (generator.json sampling), not the steered root\'s', async () => {
    const rho = noiseCorrelation(info);
    expect(rho).toBeGreaterThan(0);
    const free = await core.generate({ frames: 24, seed: 7, temperature: 0.5, seedIndex: 0 });
    const run = (noiseCorrelation: number, heldRoot?: number) => rollout({ step, info, mean: core.mean, std: core.std, start: seedState(0), variables: samplerOrderVariables(7, 24, heldRoot), steering: steer([0, 0, 0], 0), temperature: 0.5, commit: 24, noiseCorrelation });
    // The rollout keeps its normals as float32 variables, the sampler as doubles: equal up to rounding.
    expect(largestDifference((await run(rho, rho)).features, free.features)).toBeLessThan(1e-3);
    expect(largestDifference((await run(rho)).features, free.features)).toBeGreaterThan(1e-2); // a fresh root draws other steps
    expect(largestDifference((await run(0, rho)).features, free.features)).toBeGreaterThan(1e-2); // and a fresh pose other poses
  });

  it('carries the held normals across commits: two rollouts continue one', async () => {
    const rho = noiseCorrelation(info);
    const whole = samplerOrderVariables(3, 20);
    const part = (from: number, to: number): Variables => ({ P: 1, T: to - from, u: whole.u.slice(from, to), z: whole.z.slice(from * D, to * D), d: whole.d.slice(from * D, to * D) });
    const base = { step, info, mean: core.mean, std: core.std, steering: steer([0, 0, 0], 0), temperature: 0.5, noiseCorrelation: rho };
    const one = await rollout({ ...base, start: seedState(0), variables: whole, commit: 20 });
    const first = await rollout({ ...base, start: seedState(0), variables: part(0, 8), commit: 8 });
    expect(first.states[0].held).toHaveLength(D);
    const second = await rollout({ ...base, start: first.states[0], variables: part(8, 20), commit: 12 });
    expect(largestDifference(second.features, one.features.subarray(8 * D))).toBeLessThan(1e-5);
    const { held: _dropped, ...forgetful } = first.states[0];
    const restarted = await rollout({ ...base, start: forgetful, variables: part(8, 20), commit: 12 });
    expect(largestDifference(restarted.features, one.features.subarray(8 * D))).toBeGreaterThan(1e-3);
  });

  it('without authority and noise is free generation at temperature 0', async () => {
    const free = await core.generate({ frames: 20, seed: 0, temperature: 0, seedIndex: 0 });
    const r = await rollout({ step, info, mean: core.mean, std: core.std, start: seedState(0), variables: zeroVariables(2, 20), steering: steer([0, 0, 0], 0), temperature: 0, commit: 20 });
    const row0 = r.features.subarray(0, 20 * D);
    let worst = 0;
    for (let i = 0; i < row0.length; i++) worst = Math.max(worst, Math.abs(row0[i] - free.features[i]));
    expect(worst).toBeLessThan(1e-5);
    expect(bytes(r.features.subarray(20 * D))).toEqual(bytes(row0)); // identical particles stay identical
    expect(r.noiseCost[0]).toBe(0);
    expect(Number.isFinite(r.priorCost[0])).toBe(true);
  });

  it('with full authority imposes the root target, and costs more prior than free frames', async () => {
    const target = [0.01, 0.05, 0.02]; // a 1.5 m/s sidestepping, turning step
    const free = await rollout({ step, info, mean: core.mean, std: core.std, start: seedState(0), variables: zeroVariables(1, 10), steering: steer(target, 0), temperature: 0, commit: 10 });
    const forced = await rollout({ step, info, mean: core.mean, std: core.std, start: seedState(0), variables: zeroVariables(1, 10), steering: steer(target, 1), temperature: 0, commit: 10 });
    for (let t = 0; t < 10; t++) for (let k = 0; k < 3; k++) expect(forced.features[t * D + k]).toBeCloseTo(target[k], 5);
    expect(forced.roots[9 * 3 + 2]).toBeCloseTo(0.2, 5); // ten 0.02 rad turns
    expect(forced.priorCost[0]).toBeGreaterThan(free.priorCost[0]);
  });
});

describe('followPath', () => {
  const path = GroundPath.fromPoints([[0, 0], [0, 2], [1.5, 3.5]]);
  const run = (seed: number) => followPath({ step, info, mean: core.mean, std: core.std, path, gait: 'walk', seed, particles: 16, rounds: 2 });

  it('follows a short path with a bend to its end, deterministically for a seed', async () => {
    const progress: number[] = [];
    const a = await followPath({ step, info, mean: core.mean, std: core.std, path, gait: 'walk', seed: 3, particles: 16, rounds: 2, onProgress: (f) => progress.push(f) });
    expect(a.stats.meanError).toBeLessThan(0.1);
    expect(a.stats.maxError).toBeLessThan(0.3);
    expect(a.stats.arcProgress).toBeGreaterThan(0.95);
    expect(a.positions.every(Number.isFinite)).toBe(true);
    expect(progress.at(-1)).toBe(1);
    expect(progress).toEqual([...progress].sort((x, y) => x - y));
    // Starts on the path's first point, facing along it.
    expect(Math.hypot(a.positions[0], a.positions[2])).toBeLessThan(0.1);
    const b = await run(3);
    expect(bytes(b.features)).toEqual(bytes(a.features));
    const m = { fps: 30, frames: a.frames, joints: info.skeleton.joints, parents: info.skeleton.parents, positions: a.positions, contacts: a.contacts };
    expect(footSkating(m)).toBeLessThan(2); // m/s; a sliding, unconstrained root would be far above
  }, 60000);
});

describe('followPath requests (the worker side)', () => {
  const shape: GroundPoint[] = [[0, 0], [0, 2], [1.5, 3.5]];
  const request = (points: GroundPoint[]): FollowPathParams => ({ points, gait: 'walk', seed: 3 });
  const ignore = () => undefined;

  it('give the same motion wherever the path lies, moved there', async () => {
    const requests = new OptimizerRequests(core);
    const [dx, dz] = [9000, -7000]; // near the ±10 km limit; exact in float64, so the moved path is the same shape
    const here = await requests.followPath(request(shape), ignore);
    const there = await requests.followPath(request(shape.map(([x, z]) => [x + dx, z + dz])), ignore);
    expect(bytes(there.features)).toEqual(bytes(here.features));
    expect(bytes(there.contacts)).toEqual(bytes(here.contacts));
    const { optimizeMs: _h, ...hereStats } = here.stats;
    const { optimizeMs: _t, ...thereStats } = there.stats;
    expect(thereStats).toEqual(hereStats);
    const moved = (values: Float32Array, stride: number, zAt: number) => Array.from(values, (v, i) => Math.fround(v + (i % stride === 0 ? dx : i % stride === zAt ? dz : 0)));
    expect(Array.from(there.positions)).toEqual(moved(here.positions, 3, 2));
    expect(Array.from(there.path)).toEqual(moved(here.path, 2, 1));
  }, 120000);

  it('refuse coordinates float32 positions cannot hold, before optimising', async () => {
    const requests = new OptimizerRequests(core);
    for (const far of [1e300, 1e15, 1e5]) {
      await expect(requests.followPath(request(shape.map(([x, z]) => [x + far, z])), ignore)).rejects.toThrow(/^points\[0\] .* is too far out: x and z must be within ±10000 m/);
    }
  });
});

describe('LiveController', () => {
  it('turns toward a new heading and keeps a requested speed', async () => {
    const controller = new LiveController({ step, info, mean: core.mean, std: core.std, seed: 5, seedIndex: 0 });
    const schedule = checkSchedule([{ t: 0, speed: 1.2, heading: 0 }, { t: 1, speed: 1.2, heading: Math.PI / 2 }]);
    const sim = await simulateControl(controller, schedule, 3, 30);
    const frames = sim.chunks.reduce((n, c) => n + c.frames, 0);
    expect(frames).toBe(90);
    const last = sim.chunks.at(-1)!;
    expect(Math.abs(angleDifference(last.heading[last.frames - 1], Math.PI / 2))).toBeLessThan(0.3);
    expect(Math.abs(last.speed[last.frames - 1] - 1.2)).toBeLessThan(0.35);
    expect(sim.targets[29].heading).toBe(0);
    expect(sim.targets[30].heading).toBe(Math.PI / 2);
  }, 60000);

  it('gives at least one frame for a run shorter than a frame, a motion show and exportBVH take', async () => {
    const controller = new LiveController({ step, info, mean: core.mean, std: core.std, seed: 5, seedIndex: 0 });
    const sim = await simulateControl(controller, checkSchedule([{ t: 0, speed: 1.2, heading: 0 }]), 0.01, 30);
    expect(sim.chunks.map((c) => c.frames)).toEqual([1]);
    expect(sim.targets).toHaveLength(1);
    const motion = validateMotion({ fps: 30, frames: 1, joints: info.skeleton.joints, parents: info.skeleton.parents, positions: sim.chunks[0].positions });
    expect(exportBVH(motion)).toMatch(/Frames: 1\s/);
  });

  it('refuses bad schedules and targets with messages saying why', async () => {
    expect(() => checkSchedule([])).toThrow(/non-empty array/);
    expect(() => checkSchedule([{ t: 1, speed: 1, heading: 0 }])).toThrow(/schedule\[0\]\.t must be 0/);
    expect(() => checkSchedule([{ t: 0, speed: 1, heading: 0 }, { t: 0, speed: 1, heading: 0 }])).toThrow(/must be later/);
    expect(() => checkSchedule([{ t: 0, speed: 9, heading: 0 }])).toThrow(/schedule\[0\]\.speed must be a number from 0 to 4/);
    const controller = new LiveController({ step, info, mean: core.mean, std: core.std, seed: 5, seedIndex: 0 });
    await expect(controller.advance({ speed: 1, heading: NaN })).rejects.toThrow(/heading must be a finite number/);
    await expect(controller.advance({ speed: 1, heading: 0 }, 6, 2)).rejects.toThrow(/particles must be an integer from 4 to 64/);
    const cheap = await controller.advance({ speed: 1, heading: 0 }, 6, 8); // the page's budget when the machine is busy
    expect(cheap.frames).toBe(6);
    expect(cheap.positions.every(Number.isFinite)).toBe(true);
  });
});
