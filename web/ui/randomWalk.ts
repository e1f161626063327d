// Random walk mode: the generator runs endlessly in its worker, a chunk at a time, a little ahead of
// the playhead; the viewer shows a rolling window of the last ~20 s (interpolated at the display rate).

import type { Motion } from '../motion/types';
import type { GeneratorClient } from '../runtime/generatorClient';
import type { App } from './app';
import { errorMessage } from './app';

/** Frames requested per call (1 s at 30 fps). */
const CHUNK = 30;
/** Keep at least this many frames generated beyond the playhead. */
const AHEAD = 45;
/** Frames kept behind the playhead (20 s at 30 fps): memory and drawing stay bounded for hours. */
const KEEP = 600;
const DEFAULT_TEMPERATURE = 0.5;

function $<T extends HTMLElement>(id: string): T {
  const el = document.getElementById(id);
  if (!el) throw new Error(`missing #${id} in index.html`);
  return el as T;
}

export class RandomWalk {
  private active = false;
  /** Bumped on every (re)start and stop: a running loop whose token is stale ends. */
  private token = 0;
  private client: GeneratorClient | null = null;
  private skeleton: { fps: number; joints: string[]; parents: number[] } | null = null;
  private positions = new Float32Array(0);
  private contacts = new Uint8Array(0);
  private frames = 0;
  /** Stream index of the window's first frame. */
  private start = 0;
  private seedName = '';
  private statusAt = 0;
  private seedsListed = false;

  private readonly temperature = $<HTMLInputElement>('walk-temperature');
  private readonly temperatureOut = $('walk-temperature-out');
  private readonly seedState = $<HTMLSelectElement>('walk-seed-state');
  private readonly seed = $<HTMLInputElement>('walk-seed');
  private readonly status = $('walk-status');

  /** Called when the walk stops by itself (an error): the page goes back to Clip mode. */
  onFailed: (() => void) | null = null;

  constructor(private readonly app: App) {
    this.temperature.value = String(DEFAULT_TEMPERATURE);
    this.showTemperature();
    this.temperature.addEventListener('input', () => this.showTemperature());
    // Parameters are fixed for a stream: a change starts the walk again with them.
    this.temperature.addEventListener('change', () => this.restartIfActive());
    this.seedState.addEventListener('change', () => this.restartIfActive());
    this.seed.addEventListener('change', () => this.restartIfActive());
    $('walk-restart').addEventListener('click', () => this.restartIfActive());
  }

  get running(): boolean {
    return this.active;
  }

  /** Stream frame index at the playhead. */
  get frame(): number {
    return this.start + this.app.viewer.playback.frame;
  }

  async begin(): Promise<void> {
    this.active = true;
    await this.restart();
  }

  stop(): void {
    this.active = false;
    this.token++;
  }

  private restartIfActive(): void {
    if (this.active) void this.restart();
  }

  private showTemperature(): void {
    this.temperatureOut.textContent = Number(this.temperature.value).toFixed(2);
  }

  private params(): { seed: number; temperature: number; seedIndex?: number } {
    let seed = Math.floor(Number(this.seed.value));
    if (!Number.isFinite(seed) || seed < 0) seed = 0;
    seed = Math.min(seed, 0xffffffff);
    const temperature = Math.min(Math.max(Number(this.temperature.value) || 0, 0), 2);
    const idx = this.seedState.value === '' ? undefined : Number(this.seedState.value);
    return { seed, temperature, ...(idx === undefined ? {} : { seedIndex: idx }) };
  }

  private async restart(): Promise<void> {
    const token = ++this.token;
    this.status.textContent = 'loading…';
    try {
      const { client, info } = await this.app.generator.load();
      if (token !== this.token) return;
      if (!this.seedsListed) {
        for (const [i, name] of info.seeds.entries()) this.seedState.add(new Option(name, String(i)));
        this.seedsListed = true;
      }
      this.client = client;
      this.skeleton = { fps: info.fps, joints: info.joints, parents: info.parents };
      const stream = await client.startStream(this.params());
      if (token !== this.token) return;
      this.seedName = stream.seedName;
      this.frames = 0;
      this.start = 0;
      this.positions = new Float32Array(0);
      this.contacts = new Uint8Array(0);
      await this.loop(token, client);
    } catch (e) {
      if (token !== this.token) return;
      this.app.generator.reset(this.client ?? undefined);
      this.stop();
      this.status.textContent = '';
      this.app.reportError(`Random walk: ${errorMessage(e)}`);
      this.onFailed?.();
    }
  }

  private async loop(token: number, client: GeneratorClient): Promise<void> {
    let first = true;
    while (token === this.token) {
      const ahead = first ? 0 : this.frames - 1 - this.app.viewer.playback.frameFloat;
      if (ahead < AHEAD) {
        const chunk = await client.pull(CHUNK);
        if (token !== this.token) return;
        this.append(chunk.positions, chunk.contacts, chunk.frames, first);
        first = false;
      } else {
        await new Promise((r) => setTimeout(r, 100));
      }
      this.updateStatus();
    }
  }

  private append(positions: Float32Array, contacts: Uint8Array, frames: number, first: boolean): void {
    const sk = this.skeleton!;
    const stride = sk.joints.length * 3;
    const playhead = first ? 0 : this.app.viewer.playback.frame;
    const drop = Math.max(0, playhead - KEEP);
    const kept = this.frames - drop;
    const P = new Float32Array((kept + frames) * stride);
    P.set(this.positions.subarray(drop * stride, this.frames * stride));
    P.set(positions, kept * stride);
    const C = new Uint8Array((kept + frames) * 2);
    C.set(this.contacts.subarray(drop * 2, this.frames * 2));
    C.set(contacts, kept * 2);
    this.positions = P;
    this.contacts = C;
    this.frames = kept + frames;
    this.start += drop;
    const motion: Motion = { fps: sk.fps, frames: this.frames, joints: sk.joints, parents: sk.parents, positions: P, contacts: C };
    this.app.showLive(motion, first ? -1 : drop);
  }

  /** Refreshes the status readout (frame count, seed state) a few times a second. */
  updateStatus(force = false): void {
    const now = performance.now();
    if (!force && now - this.statusAt < 250) return;
    this.statusAt = now;
    const f = this.frame;
    this.status.dataset.frame = String(f);
    const fps = this.skeleton?.fps ?? 30;
    this.status.textContent = `frame ${f} · ${(f / fps).toFixed(1)} s · ${this.seedName} · τ ${this.params().temperature.toFixed(2)}`;
  }
}
