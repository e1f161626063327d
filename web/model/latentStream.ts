// Online generation with the latent ERD: a port of training/latent_erd/streaming.py LatentStream (the
// fixture tests/fixtures/latent_erd_reference.json checks the two against each other; keep them in step).
//
// The decoder needs latents on both sides of a frame (RADIUS = 9 steps, 1.2 s each way), so a stream
// cannot wait for the real future. Each latent step (4 frames, 133 ms):
//   1. the ERD commits the next latent from the current one and the control for that step;
//   2. it looks ahead LOOKAHEAD more steps from a copy of its state, with the control it expects (the
//      same control repeated, or the known future control when there is one): a guess at the future,
//      thrown away afterwards;
//   3. the decoder turns the window [RADIUS committed steps, the new one, the guesses, the last guess
//      repeated up to RADIUS] into the 4 frames of the new step;
//   4. the root moves by the decoded frames' own control channels (control.ts stepRoot), so the feet and
//      the root agree.
// So a change of control shows in the next emitted step: the added lag is one latent step (133 ms) at
// most. The cost is LOOKAHEAD extra ERD steps per 4 frames.
//
// The arithmetic follows the Python's: normalising the control and de-normalising the window in float64
// and rounding to float32 once, the decoded rows and the root in float64. The networks are behind
// `LatentBackend` (onnxruntime in web/runtime/latent_erd/latentErdCore.ts), so this file needs no onnxruntime.
import { stepRoot, type Root } from '../motion/control';
import type { LatentErdInfo, ManifoldInfo } from './latentErdInfo';

/** The two networks, one stream at a time (batch 1). */
export interface LatentBackend {
  /** One ERD step: z (latent, normalised), control (control_dim, normalised), h and c (layers × hidden) → the next z and state. */
  step(z: Float32Array, control: Float32Array, h: Float32Array, c: Float32Array): Promise<{ z: Float32Array; h: Float32Array; c: Float32Array }>;
  /** The decoder on a window of 2 × radius + 1 physical latent steps (flattened) → pooling × rows.dim normalised rows. */
  decode(window: Float32Array): Promise<Float32Array>;
}

/** The normalisations and layout a stream needs, from latent-erd.json and manifold.json. */
export interface StreamLayout {
  fps: number;
  pooling: number;
  radius: number;
  latent: number;
  layers: number;
  hidden: number;
  joints: number;
  rowDim: number;
  positions: number;
  control: number;
  contacts: number;
  latentMean: Float64Array;
  latentStd: Float64Array;
  rowMean: Float64Array;
  rowStd: Float64Array;
}

export function streamLayout(erd: LatentErdInfo, manifold: ManifoldInfo): StreamLayout {
  return {
    fps: erd.fps,
    pooling: erd.pooling,
    radius: erd.radius,
    latent: erd.latent,
    layers: erd.layers,
    hidden: erd.hidden,
    joints: manifold.skeleton.joints.length,
    rowDim: manifold.rows.dim,
    positions: manifold.rows.positions[0],
    control: manifold.rows.control[0],
    contacts: manifold.rows.contacts[0],
    latentMean: Float64Array.from(erd.latent_normalisation.mean),
    latentStd: Float64Array.from(erd.latent_normalisation.std),
    rowMean: Float64Array.from(manifold.normalisation.mean),
    rowStd: Float64Array.from(manifold.normalisation.std),
  };
}

/** One emitted step: `pooling` frames. */
export interface StreamStep {
  /** pooling × rowDim physical rows (positions in the root facing frame, control, contacts). */
  rows: Float64Array;
  /** pooling × joints × 3 world positions (the decoded points, bone lengths as predicted). */
  positions: Float64Array;
  /** pooling × 3: x, z, heading of each frame's root. */
  roots: Float64Array;
  /** pooling × 2: decoded contact channel > 0.5. */
  contacts: Uint8Array;
}

export class LatentStream {
  /** Where the next frame's root stands. */
  root: Root;
  /** Latent steps emitted so far (not counting the seed). */
  steps = 0;
  /** ERD step calls made so far (the seed warm-up, each step and its look-ahead). */
  erdCalls = 0;
  private h: Float32Array;
  private c: Float32Array;
  private current: Float32Array;
  /** The latest committed latents (normalised), at most radius + 1. */
  private history: Float32Array[];

  private constructor(
    private readonly backend: LatentBackend,
    private readonly layout: StreamLayout,
    readonly lookahead: number,
    root: Root,
    state: { h: Float32Array; c: Float32Array; current: Float32Array; history: Float32Array[] },
  ) {
    this.root = { ...root };
    ({ h: this.h, c: this.c, current: this.current, history: this.history } = state);
  }

  /**
   * A stream from a seed: P real latent steps (normalised) and their step controls (normalised). The ERD
   * reads the seed teacher-forced (latent i with control i + 1); the first emitted frames are those of the
   * step after it. The root starts at `root` (default the origin facing +z).
   */
  static async create(
    backend: LatentBackend,
    layout: StreamLayout,
    seed: { latents: ArrayLike<number>[]; controls: ArrayLike<number>[] },
    lookahead: number,
    root: Root = { x: 0, z: 0, heading: 0 },
    beforeStep?: () => void | Promise<void>,
  ): Promise<LatentStream> {
    const z = seed.latents.map((v) => Float32Array.from(v));
    let h: Float32Array = new Float32Array(layout.layers * layout.hidden);
    let c: Float32Array = new Float32Array(layout.layers * layout.hidden);
    for (let i = 0; i < z.length - 1; i++) {
      await beforeStep?.();
      ({ h, c } = await backend.step(z[i], Float32Array.from(seed.controls[i + 1]), h, c));
    }
    const stream = new LatentStream(backend, layout, lookahead, root, { h, c, current: z[z.length - 1].slice(), history: z.slice() });
    stream.erdCalls = z.length - 1;
    return stream;
  }

  /** Physical control (pooling frames × 3, flattened) → the ERD's normalised step control. */
  normaliseControl(frames: ArrayLike<number>): Float32Array {
    const { pooling, control, rowMean, rowStd } = this.layout;
    const out = new Float32Array(pooling * 3);
    for (let t = 0; t < pooling; t++) {
      for (let k = 0; k < 3; k++) out[t * 3 + k] = (frames[t * 3 + k] - rowMean[control + k]) / rowStd[control + k];
    }
    return out;
  }

  /**
   * The next `pooling` frames for `control` (pooling × 3 physical, flattened); `future` optionally gives
   * the expected controls (each pooling × 3) of the steps after it, for the look-ahead (else `control` is
   * repeated). `beforeStep` runs before every network call (a cancellation checkpoint).
   */
  async step(control: ArrayLike<number>, future?: ArrayLike<number>[], beforeStep?: () => void | Promise<void>): Promise<StreamStep> {
    const { radius, latent, latentMean, latentStd, rowMean, rowStd, rowDim, pooling } = this.layout;
    const now = this.normaliseControl(control);
    await beforeStep?.();
    const next = await this.backend.step(this.current, now, this.h, this.c);
    this.erdCalls++;
    this.current = next.z;
    this.h = next.h;
    this.c = next.c;
    this.history.push(next.z);
    const guesses: Float32Array[] = [];
    let zz = next.z, h = next.h, c = next.c;
    for (let k = 0; k < this.lookahead; k++) {
      const ck = future && k < future.length ? this.normaliseControl(future[k]) : now;
      await beforeStep?.();
      ({ z: zz, h, c } = await this.backend.step(zz, ck, h, c));
      this.erdCalls++;
      guesses.push(zz);
    }
    const past = this.history.slice(-(radius + 1));
    while (past.length < radius + 1) past.unshift(past[0]);
    const ahead = guesses.slice();
    const fill = guesses.length ? guesses[guesses.length - 1] : past[past.length - 1];
    while (ahead.length < radius) ahead.push(fill);
    const span = [...past, ...ahead];
    const window = new Float32Array(span.length * latent);
    span.forEach((z, s) => {
      for (let d = 0; d < latent; d++) window[s * latent + d] = z[d] * latentStd[d] + latentMean[d];
    });
    await beforeStep?.();
    const decoded = await this.backend.decode(window);
    if (decoded.length !== pooling * rowDim) throw new Error(`the decoder gave ${decoded.length} values for one step, expected ${pooling} rows of ${rowDim}`);
    const rows = new Float64Array(pooling * rowDim);
    for (let i = 0; i < rows.length; i++) {
      const d = i % rowDim;
      rows[i] = decoded[i] * rowStd[d] + rowMean[d];
    }
    if (!rows.every(Number.isFinite)) throw new Error(`the model produced a non-finite value at latent step ${this.steps}`);
    if (this.history.length > radius + 1) this.history = this.history.slice(-(radius + 1));
    this.steps++;
    return this.place(rows);
  }

  /** World positions of the rows (root facing frame → world at the root), and the root moved by their control channels. */
  private place(rows: Float64Array): StreamStep {
    const { pooling, rowDim, joints, positions: p0, control, contacts: c0, fps } = this.layout;
    const positions = new Float64Array(pooling * joints * 3);
    const roots = new Float64Array(pooling * 3);
    const contacts = new Uint8Array(pooling * 2);
    let r = this.root;
    for (let t = 0; t < pooling; t++) {
      const row = rows.subarray(t * rowDim, (t + 1) * rowDim);
      const ch = Math.cos(r.heading), sh = Math.sin(r.heading);
      for (let j = 0; j < joints; j++) {
        const lx = row[p0 + j * 3], ly = row[p0 + j * 3 + 1], lz = row[p0 + j * 3 + 2];
        const o = (t * joints + j) * 3;
        positions[o] = ch * lx + sh * lz + r.x;
        positions[o + 1] = ly;
        positions[o + 2] = -sh * lx + ch * lz + r.z;
      }
      roots[t * 3] = r.x;
      roots[t * 3 + 1] = r.z;
      roots[t * 3 + 2] = r.heading;
      contacts[t * 2] = row[c0] > 0.5 ? 1 : 0;
      contacts[t * 2 + 1] = row[c0 + 1] > 0.5 ? 1 : 0;
      r = stepRoot(r, row.subarray(control, control + 3), fps);
    }
    this.root = r;
    return { rows, positions, roots, contacts };
  }
}
