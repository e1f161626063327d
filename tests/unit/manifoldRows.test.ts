// The motion manifold's rows (web/model/manifoldRows.ts, the port of training/data/windows.py) against
// tests/fixtures/manifold_rows.json (python -m training.fixtures.manifold_rows), and the `manifold` clean-up
// (web/runtime/autoencoder/manifoldProjection.ts) on the fixture's held-out clip through the shipped autoencoder, run by
// onnxruntime-web's Node build, directly and through the latent ERD worker's core and request.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { controlFromTrajectory, wrap } from '../../web/motion/control';
import { addNoise } from '../../web/motion/noise';
import { parseLatentErdInfo, parseManifoldInfo, type LatentErdModel } from '../../web/model/latentErdInfo';
import { groundFrame, motionRows, rowLayout, smooth, toLocal, toWorld } from '../../web/model/manifoldRows';
import { LatentErdCore } from '../../web/runtime/latent_erd/latentErdCore';
import { LatentErdRequests, type ManifoldProjectParams } from '../../web/runtime/latent_erd/latentErdRequests';
import { manifoldWindow, projectOnManifold, windowStarts, type ManifoldProjectionArgs, type ManifoldWindowInfo } from '../../web/runtime/autoencoder/manifoldProjection';
import { readRepoFile } from './corpus';
import { maxAbsDiff, ort, shippedSession } from './shippedModel';

interface RowsCase {
  fps: number;
  frames: number;
  sigma_frames: number;
  xz: number[];
  heading: number[];
  rows: number[];
  world?: number[];
}
interface Fixture {
  joints: string[];
  window: number;
  clip: { file: string; fps: number; frames: number; positions: number[]; contacts: number[] };
  rows: RowsCase[];
}

/** The fixture rounds to 6 decimals. */
const TOLERANCE = 1e-5;

const fixture = JSON.parse(readRepoFile('tests/fixtures/manifold_rows.json')) as Fixture;
const manifold = parseManifoldInfo(JSON.parse(readRepoFile('public/models/manifold.json')), 'public/models/manifold.json') as ManifoldWindowInfo;
const layout = rowLayout(manifold);
const J = layout.joints;
const clip = fixture.clip;
const clipPositions = Float64Array.from(clip.positions);
const clipContacts = Uint8Array.from(clip.contacts);

describe('manifold rows: parity with training/data/windows.py', () => {
  it('the fixture is on the manifold skeleton and window', () => {
    expect(fixture.joints).toEqual(manifold.rows.joints);
    expect(fixture.window).toBe(manifoldWindow(manifold));
    expect(clip.fps).toBe(manifold.fps);
    const { leftHip, rightHip, leftArm, rightArm } = layout.facing;
    expect([leftHip, rightHip, leftArm, rightArm].map((j) => manifold.rows.joints[j])).toEqual(['LeftUpLeg', 'RightUpLeg', 'LeftArm', 'RightArm']);
  });

  for (const c of fixture.rows) {
    describe(`${c.frames} frames at ${c.fps} fps`, () => {
      const positions = clipPositions.subarray(0, c.frames * J * 3);
      const contacts = clipContacts.subarray(0, c.frames * 2);

      it('ground_frame: the smoothed root trajectory and facing', () => {
        const ground = groundFrame(positions, layout, c.fps);
        expect(maxAbsDiff(ground.xz, c.xz)).toBeLessThan(TOLERANCE);
        const heading = Array.from(ground.heading, (h, f) => Math.abs(wrap(h - c.heading[f])));
        expect(Math.max(...heading)).toBeLessThan(TOLERANCE);
      });

      it('motion_rows: local positions, control (controlFromTrajectory = control_from_trajectory), contacts', () => {
        const { rows, ground } = motionRows(positions, contacts, layout, c.fps);
        expect(rows.length).toBe(c.frames * layout.dim);
        expect(maxAbsDiff(rows, c.rows)).toBeLessThan(TOLERANCE);
        // The control part on its own, from the fixture's (rounded) ground frame.
        const control = controlFromTrajectory(c.xz, c.heading, c.fps);
        const [c0] = layout.control;
        const fromRows = Array.from({ length: c.frames * 3 }, (_, i) => c.rows[Math.floor(i / 3) * layout.dim + c0 + (i % 3)]);
        expect(maxAbsDiff(control, fromRows)).toBeLessThan(1e-3); // the rounded xz's differences times fps
        expect(maxAbsDiff(controlFromTrajectory(ground.xz, ground.heading, c.fps), fromRows)).toBeLessThan(TOLERANCE);
      });

      if (c.world) {
        it('to_world of the local positions with the ground frame gives the positions back', () => {
          const ground = groundFrame(positions, layout, c.fps);
          const world = toWorld(toLocal(positions, J, ground), J, ground);
          expect(maxAbsDiff(world, c.world!)).toBeLessThan(TOLERANCE);
          expect(maxAbsDiff(world, positions)).toBeLessThan(1e-9);
        });
      }
    });
  }

  it('smooth keeps a constant, is edge-padded and needs a positive sigma', () => {
    expect(maxAbsDiff(smooth([2, 2, 2, 2], 1, 1.5), [2, 2, 2, 2])).toBeLessThan(1e-12);
    const step = smooth([0, 0, 0, 1, 1, 1], 1, 0.8);
    expect(step[0]).toBeGreaterThan(0);
    expect(step[5]).toBeLessThan(1);
    expect(step[2] + step[3]).toBeCloseTo(1, 12);
    expect(() => smooth([1, 2], 1, 0)).toThrow(/sigma must be positive/);
  });

  it('rowLayout names a missing facing joint', () => {
    const rows = { ...manifold.rows, joints: manifold.rows.joints.map((n) => (n === 'LeftArm' ? 'LeftShoulder' : n)) };
    expect(() => rowLayout({ rows })).toThrow(/no joint "LeftArm"/);
  });
});

/** Mean joint distance (m) between two frames × joints × 3 arrays. */
function meanJointError(a: ArrayLike<number>, b: ArrayLike<number>): number {
  let total = 0;
  const n = a.length / 3;
  for (let i = 0; i < n; i++) total += Math.hypot(a[3 * i] - b[3 * i], a[3 * i + 1] - b[3 * i + 1], a[3 * i + 2] - b[3 * i + 2]);
  return total / n;
}

function agreement(a: ArrayLike<number>, b: ArrayLike<number>): number {
  let same = 0;
  for (let i = 0; i < a.length; i++) same += a[i] === b[i] ? 1 : 0;
  return same / a.length;
}

describe('manifold projection on the shipped autoencoder', () => {
  let encoder: ort.InferenceSession;
  let decoder: ort.InferenceSession;
  const calls = { encode: 0, decode: 0 };
  const encode: ManifoldProjectionArgs['encode'] = async (rows, frames) => {
    calls.encode++;
    const out = await encoder.run({ rows: new ort.Tensor('float32', rows, [1, frames, layout.dim]) });
    return out.latent.data as Float32Array;
  };
  const decode: ManifoldProjectionArgs['decode'] = async (latent, steps) => {
    calls.decode++;
    const out = await decoder.run({ latent: new ort.Tensor('float32', latent, [1, steps, manifold.latent]) });
    return out.rows.data as Float32Array;
  };
  const project = (positions: ArrayLike<number>, contacts?: ArrayLike<number>, fps = manifold.fps) =>
    projectOnManifold({ encode, decode, manifold, positions, fps, ...(contacts ? { contacts } : {}) });
  const noisy = () =>
    addNoise({ fps: clip.fps, frames: clip.frames, joints: manifold.skeleton.joints, parents: manifold.skeleton.parents, positions: Float32Array.from(clipPositions) }, { jitter: 0.05, seed: 7 }).motion
      .positions;

  beforeAll(async () => {
    [encoder, decoder] = await Promise.all([shippedSession(manifold.files.encoder), shippedSession(manifold.files.decoder)]);
  });
  afterAll(async () => {
    await encoder?.release();
    await decoder?.release();
  });

  it('windows of 120 frames every 60, the end padded', () => {
    expect(windowStarts(300, 120, 60)).toEqual({ starts: [0, 60, 120, 180], padded: 300 });
    expect(windowStarts(301, 120, 60)).toEqual({ starts: [0, 60, 120, 180, 240], padded: 360 });
    expect(windowStarts(90, 120, 60)).toEqual({ starts: [0], padded: 120 });
    expect(windowStarts(120, 120, 60)).toEqual({ starts: [0], padded: 120 });
  });

  it('a clean held-out clip comes back near the report\'s reconstruction error', async () => {
    calls.encode = calls.decode = 0;
    const out = await project(clipPositions, clipContacts);
    expect(out.positions.length).toBe(clip.positions.length);
    expect(out.contacts.length).toBe(clip.frames * 2);
    expect(out.windows).toBe(4);
    expect(calls).toEqual({ encode: 4, decode: 4 });
    const error = meanJointError(out.positions, clipPositions);
    const withoutContacts = await project(clipPositions);
    const errorWithout = meanJointError(withoutContacts.positions, clipPositions);
    const report = (manifold.report as { reconstruction_cm_clean: number }).reconstruction_cm_clean;
    console.log(
      `manifold projection, clean ${clip.file} (${clip.frames} frames): ${(100 * error).toFixed(2)} cm with contacts, ${(100 * errorWithout).toFixed(2)} cm without ` +
        `(report ${report} cm); contacts agree ${(100 * agreement(out.contacts, clipContacts)).toFixed(1)}% with, ${(100 * agreement(withoutContacts.contacts, clipContacts)).toFixed(1)}% without`,
    );
    expect(error).toBeLessThan(0.08);
    expect(errorWithout).toBeLessThan(0.08);
    expect(agreement(out.contacts, clipContacts)).toBeGreaterThan(0.8);
  });

  it('5 cm of jitter: the projection is closer to the clean clip than the noisy input is', async () => {
    const input = noisy();
    const noisyError = meanJointError(input, clipPositions);
    const out = await project(input);
    const projectedError = meanJointError(out.positions, clipPositions);
    const withContacts = meanJointError((await project(input, clipContacts)).positions, clipPositions);
    console.log(
      `manifold projection, 5 cm jitter: noisy input ${(100 * noisyError).toFixed(2)} cm from the clean clip, projected ${(100 * projectedError).toFixed(2)} cm ` +
        `(${(100 * withContacts).toFixed(2)} cm given the clean contacts)`,
    );
    expect(noisyError).toBeGreaterThan(0.07);
    expect(projectedError).toBeLessThan(noisyError);
  });

  it('a clip shorter than a window is padded and cut; one not on the hop grid keeps its frames', async () => {
    const short = clipPositions.subarray(0, 90 * J * 3);
    const out = await project(short);
    expect(out.windows).toBe(1);
    expect(out.positions.length).toBe(short.length);
    expect(out.positions.every(Number.isFinite)).toBe(true);
    expect(meanJointError(out.positions, short)).toBeLessThan(0.1);
    const odd = clipPositions.subarray(0, 211 * J * 3);
    const more = await project(odd);
    expect(more.windows).toBe(3);
    expect(more.positions.length).toBe(odd.length);
    expect(meanJointError(more.positions, odd)).toBeLessThan(0.08);
  });

  it('rejects another fps, partial frames, bad values and bad contacts', async () => {
    await expect(project(clipPositions, undefined, 60)).rejects.toThrow(/runs at 30 fps, got motion at 60 fps: resample/);
    await expect(project(clipPositions.subarray(0, 100))).rejects.toThrow(/whole frames of 25 joints/);
    const nan = Float32Array.from(clipPositions.subarray(0, 10 * J * 3));
    nan[7] = NaN;
    await expect(project(nan)).rejects.toThrow(/positions\[7\] is NaN/);
    await expect(project(clipPositions, new Uint8Array(3))).rejects.toThrow(/contacts must hold 600 values/);
  });

  describe('through the latent ERD core and its manifoldProject request', () => {
    const erd = parseLatentErdInfo(JSON.parse(readRepoFile('public/models/latent-erd.json')), 'public/models/latent-erd.json');
    const model: LatentErdModel = { erd, manifold, decoderUrl: manifold.files.decoder, encoderUrl: manifold.files.encoder };
    let core: LatentErdCore;
    let encoderLoads = 0;

    beforeAll(async () => {
      core = new LatentErdCore(await shippedSession(erd.file), model, ort.Tensor, 1, () => shippedSession(manifold.files.decoder), () => {
        encoderLoads++;
        return shippedSession(manifold.files.encoder);
      });
      await core.check();
    });
    afterAll(() => core?.release());

    it('gives what projectOnManifold gives, loading the encoder once', async () => {
      const positions = Float32Array.from(clipPositions);
      const direct = await project(positions, clipContacts);
      const fractions: number[] = [];
      const viaCore = await core.projectManifold(positions, clipContacts, undefined, (f) => fractions.push(f));
      expect(maxAbsDiff(viaCore.positions, direct.positions)).toBeLessThan(1e-6);
      expect(Array.from(viaCore.contacts)).toEqual(Array.from(direct.contacts));
      expect(fractions).toEqual([0, 0.25, 0.5, 0.75, 1]);
      const requests = new LatentErdRequests(core);
      const viaRequest = await requests.manifoldProject({ positions }, () => undefined);
      expect(maxAbsDiff(viaRequest.positions, (await project(positions)).positions)).toBeLessThan(1e-6);
      expect(encoderLoads).toBe(1);
    });

    it('stops when cancelled and checks the request', async () => {
      const controller = new AbortController();
      controller.abort();
      await expect(core.projectManifold(Float32Array.from(clipPositions), undefined, controller.signal)).rejects.toThrow();
      const requests = new LatentErdRequests(core);
      // As the worker passes them on: a request's body is whatever the page sent.
      const sent = (body: object) => body as ManifoldProjectParams;
      expect(() => requests.manifoldProject(sent({ positions: [1, 2, 3] }), () => undefined)).toThrow(/positions must be a Float32Array/);
      expect(() => requests.manifoldProject(sent({ positions: new Float32Array(75), contacts: [1, 0] }), () => undefined)).toThrow(/contacts must be a Uint8Array/);
    });

    it('a core made without the encoder says so', async () => {
      const bare = new LatentErdCore(await shippedSession(erd.file), model, ort.Tensor, 1, () => shippedSession(manifold.files.decoder));
      await expect(bare.projectManifold(new Float32Array(75), undefined)).rejects.toThrow(/without the manifold encoder/);
      await bare.release();
    });
  });
});
