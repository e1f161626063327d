// The generator worker's optimiser requests: path following, and live control by speed and heading
// (one live stream at a time, and its scripted twin simulateControl). The algorithms live in
// web/optimizer/; this file checks the requests and packs results for the page. followPath and
// simulateControl stop at the next model step once cancelled (their optimiser runs with a step that
// passes a checkpoint, cancellation.ts); a controlPull that has started runs whole, so the live stream
// always stands where its last reply left it.
import { followPath, gaitSeeds, type Gait } from '../../optimizer/pathFollower';
import { checkFollowRequest, checkFitSigma, checkFootLock, checkGait, checkSeconds, checkSeed, optional } from '../../optimizer/options';
import { checkSchedule, LiveController, simulateControl } from '../../optimizer/liveControl';
import { moveBack } from '../../optimizer/path';
import { PlantedFeet, plantFeet } from '../../motion/footLock';
import { footStats } from '../../motion/footSkating';
import type { StepFn } from '../../optimizer/rollout';
import { StyleRamp } from '../../model/styleRamp';
import type { GeneratorCore } from './generatorCore';
import type { ControlChunkReply, ControlStartParams, ControlTargetParams, FollowPathChunk, FollowPathParams, SimulateControlParams, SimulatedControlChunk, StreamInfo } from './protocol';

export class OptimizerRequests {
  private live: { controller: LiveController; seedIndex: number; feet: PlantedFeet; style?: string; ramp?: StyleRamp } | undefined;

  constructor(private readonly core: GeneratorCore) {}

  /**
   * The generator step the optimiser runs; with `signal`, each step is a cancellation checkpoint. A style generator's
   * steps all carry `style` (a name; default its first style); a generator without styles refuses one.
   */
  private stepFn(signal?: AbortSignal, style?: string): StepFn {
    const input = this.core.styleInput(checkStyle(style));
    return (batch, x, h, c) => this.core.step(batch, x, h, c, signal, input);
  }

  private controller(seed: number, gait: Gait, signal?: AbortSignal, style?: string, stepFn?: StepFn): { controller: LiveController; seedIndex: number } {
    const info = this.core.info;
    const step = stepFn ?? this.stepFn(signal, style);
    const seeds = gaitSeeds(info, gait, style);
    const seedIndex = seeds[seed % seeds.length];
    return { controller: new LiveController({ step, info, mean: this.core.mean, std: this.core.std, seed, seedIndex }), seedIndex };
  }

  async followPath(p: FollowPathParams, progress: (fraction: number) => void, signal?: AbortSignal): Promise<FollowPathChunk> {
    // Followed, locked and measured near the origin; moved back to where the path is last.
    const { gait, seed, lock, origin, ground: path } = checkFollowRequest(p);
    const fitSigma = checkFitSigma(optional(p.fitSigma, 0.1));
    const info = this.core.info;
    const step = this.stepFn(signal, p.style);
    const r = await followPath({ step, info, mean: this.core.mean, std: this.core.std, path, gait, seed, style: p.style, fitSigma, onProgress: progress });
    const shown = lock ? this.plant(r.positions, r.contacts) : { positions: r.positions, contacts: r.contacts };
    const stats = { ...r.stats, ...footStats(this.core.info, r.frames, shown, { positions: r.positions, contacts: r.contacts }) };
    return { frames: r.frames, features: r.features, positions: moveBack(shown.positions, origin), contacts: shown.contacts, rootHeading: r.rootHeading, seedIndex: r.seedIndex, startFrame: 0, stats, path: path.flatAt(origin) };
  }

  /** Contacts labelled on a whole motion of the generator's skeleton and planted feet locked (hips and above unchanged). */
  private plant(positions: Float32Array, bits: Uint8Array): { positions: Float32Array; contacts: Uint8Array } {
    const { skeleton, fps } = this.core.info;
    return plantFeet(positions, bits, skeleton.joints, skeleton.offsets, fps);
  }

  controlStart(p: ControlStartParams): StreamInfo {
    this.live = undefined;
    const { joints, offsets } = this.core.info.skeleton;
    const input = this.core.styleInput(checkStyle(p.style));
    // A style generator's live stream carries its style as a ramp, so controlStyle can switch it mid-stream: every
    // step of a search reads the weights of the stream frame it makes (the committed frames plus its rollout frame).
    const ramp = input ? new StyleRamp(input) : undefined;
    let committed = () => 0;
    const step: StepFn | undefined = ramp ? (batch, x, h, c, frame) => this.core.step(batch, x, h, c, undefined, ramp.at(committed() + (frame ?? 0))) : undefined;
    const made = this.controller(checkSeed(p.seed), checkGait(p.gait), undefined, p.style, step);
    committed = () => made.controller.frame;
    this.live = { ...made, feet: new PlantedFeet(joints, offsets, this.core.info.fps), style: p.style, ...(ramp ? { ramp } : {}) };
    const style = p.style ?? this.core.info.styles?.[0];
    return { seedIndex: this.live.seedIndex, seedName: this.core.info.seeds[this.live.seedIndex].name, ...(style ? { style } : {}) };
  }

  /** Switches the live stream's style over a second from its next frame (styleRamp.ts), as a stream's switch does. */
  controlStyle(style: unknown): StreamInfo {
    const live = this.live;
    if (!live) throw new Error('no control stream: send controlStart first');
    if (!live.ramp) throw new Error(`the model "${this.core.info.id}" has no styles`);
    const name = checkStyle(style);
    if (name === undefined) throw new Error('style must be a style\'s name, got undefined');
    live.ramp.switchTo(this.core.styleInput(name)!, live.controller.frame);
    live.style = name;
    return { seedIndex: live.seedIndex, seedName: this.core.info.seeds[live.seedIndex].name, style: name };
  }

  async controlPull(p: ControlTargetParams & { frames: number; particles?: number }): Promise<ControlChunkReply> {
    const live = this.live;
    if (!live) throw new Error('no control stream: send controlStart first');
    const startFrame = live.controller.frame;
    const chunk = await live.controller.advance({ speed: p.speed, heading: p.heading }, p.frames, p.particles);
    // Contacts labelled and planted feet locked frame by frame, continuing across batches (as simulateControl's
    // whole-run lock); the chunk's contacts become the labels.
    const n = this.core.info.skeleton.joints.length * 3;
    const bits = new Uint8Array(2);
    for (let f = 0; f < chunk.frames; f++) {
      const pose = chunk.positions.subarray(f * n, (f + 1) * n);
      const labels = chunk.contacts.subarray(f * 2, f * 2 + 2);
      bits.set(labels);
      live.feet.step(pose, bits, labels);
    }
    return { ...chunk, seedIndex: live.seedIndex, startFrame };
  }

  async simulate(p: SimulateControlParams, progress: (fraction: number) => void, signal?: AbortSignal): Promise<SimulatedControlChunk> {
    checkSeconds(p.seconds);
    const schedule = checkSchedule(p.schedule);
    const seed = checkSeed(p.seed);
    const gait = p.gait === undefined ? (schedule[0].speed >= 2 ? 'run' : 'walk') : checkGait(p.gait);
    const { controller, seedIndex } = this.controller(seed, gait, signal, p.style);
    const fps = this.core.info.fps;
    const sim = await simulateControl(controller, schedule, p.seconds, fps, progress);
    const frames = sim.targets.length;
    const D = this.core.info.onnx.dim;
    const J = this.core.info.skeleton.joints.length;
    const out: SimulatedControlChunk = {
      frames,
      features: new Float32Array(frames * D),
      positions: new Float32Array(frames * J * 3),
      contacts: new Uint8Array(frames * 2),
      rootHeading: new Float32Array(frames),
      seedIndex,
      startFrame: 0,
      speed: new Float32Array(frames),
      heading: new Float32Array(frames),
      targetSpeed: Float32Array.from(sim.targets, (t) => t.speed),
      targetHeading: Float32Array.from(sim.targets, (t) => t.heading),
      computeMs: new Float32Array(frames),
      batchMs: Float32Array.from(sim.chunks, (c) => c.computeMs),
      batchFrames: Uint8Array.from(sim.chunks, (c) => c.frames),
    };
    let at = 0;
    const lock = checkFootLock(p.footLock);
    for (const c of sim.chunks) {
      out.features.set(c.features, at * D);
      out.positions.set(c.positions, at * J * 3);
      out.contacts.set(c.contacts, at * 2);
      out.rootHeading.set(c.rootHeading, at);
      out.speed.set(c.speed, at);
      out.heading.set(c.heading, at);
      out.computeMs.fill(c.computeMs / c.frames, at, at + c.frames);
      at += c.frames;
    }
    if (lock) ({ positions: out.positions, contacts: out.contacts } = this.plant(out.positions, out.contacts));
    return out;
  }
}

/** A request's `style`: absent, or a style's name (which names a model has is checked by the core). */
function checkStyle(style: unknown): string | undefined {
  if (style !== undefined && typeof style !== 'string') throw new Error(`style must be a style's name, got ${String(style)}`);
  return style;
}
