// What the live modes (Random walk, Dance) share: a model streams endlessly in its worker, a chunk at a
// time, a little ahead of the playhead; the viewer shows a rolling window of the last seconds
// (interpolated at the display rate), so memory and drawing stay bounded for hours. A restart (a setting
// changed) or stop (the mode left) cancels the stream's requests still in the worker's queue.

import { detectContacts } from '../../motion/contacts';
import type { Motion } from '../../motion/types';
import { WorkerFailedError } from '../../runtime/worker/workerClient';
import { errorMessage } from '../dom';
import type { ModeHost } from './host';

/** Frames as a stream delivers them. Without contacts they are detected over the shown window. */
export interface LiveChunk {
  frames: number;
  positions: Float32Array;
  contacts?: Uint8Array;
}

export interface LiveSkeleton {
  fps: number;
  joints: string[];
  parents: number[];
}

export interface LiveStream<Chunk extends LiveChunk> {
  skeleton: LiveSkeleton;
  pull(frames: number): Promise<Chunk>;
  /** This stream's frames per pull and frames kept ready (default the mode's settings: a mode may run streams of two models). */
  chunk?: number;
  ahead?: number;
}

export interface LiveSettings {
  /** Frames requested per pull. */
  chunk: number;
  /** Keep at least this many frames generated beyond the playhead. */
  ahead: number;
  /** Frames kept behind the playhead. */
  keep: number;
  /** Names the mode in messages ("Random walk") and in exported file names ("random-walk"). */
  label: string;
  name: string;
}

export abstract class LiveMode<Chunk extends LiveChunk> {
  private active = false;
  /** Bumped on every (re)start and stop: a running loop whose token is stale ends. */
  private token = 0;
  /** Cancels the running stream's requests (aborted on every restart and stop). */
  private requests = new AbortController();
  private skeleton: LiveSkeleton | null = null;
  private positions = new Float32Array(0);
  private contacts = new Uint8Array(0);
  private frames = 0;
  /** Stream index of the window's first frame. */
  private start = 0;
  private statusAt = 0;

  /** Called when the mode stops by itself (an error): the page goes back to Clip mode. */
  onFailed: (() => void) | null = null;

  constructor(
    protected readonly app: ModeHost,
    private readonly status: HTMLElement,
    private readonly settings: LiveSettings,
  ) {}

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
    this.requests.abort();
  }

  /** Parameters are fixed for a stream: a change starts it again with them. */
  protected restartIfActive(): void {
    if (this.active) void this.restart();
  }

  /**
   * Loads the model (first time) and starts a new stream with the current settings; the stream's requests
   * (its start and every pull) carry `signal`, which aborts when the stream is replaced or stopped. Once it has
   * aborted, a newer stream owns the mode's state: after an await that takes no signal (the model list, a model's
   * load), call `signal.throwIfAborted()` before touching it (a replaced start that went on had set the running
   * model back to the one it was loading).
   */
  protected abstract open(signal: AbortSignal): Promise<LiveStream<Chunk>>;
  /** Forgets the model after its worker failed, so the next start loads it afresh. */
  protected abstract forget(): void;
  /** Called with each new chunk once it is shown (`first`: a new stream). */
  protected abstract received(chunk: Chunk, first: boolean): void;
  /** The status line for stream frame `frame`. */
  protected abstract describe(frame: number, fps: number): string;

  private async restart(): Promise<void> {
    const token = ++this.token;
    this.requests.abort();
    this.requests = new AbortController();
    this.status.textContent = 'loading…';
    try {
      const stream = await this.open(this.requests.signal);
      if (token !== this.token) return;
      this.skeleton = stream.skeleton;
      this.frames = 0;
      this.start = 0;
      this.positions = new Float32Array(0);
      this.contacts = new Uint8Array(0);
      await this.loop(token, stream);
    } catch (e) {
      if (token !== this.token) return;
      // Only a worker that failed is dropped: the client is shared (the API, other modes), and a request it
      // refused, or a mode's own check, leaves it working.
      if (e instanceof WorkerFailedError) this.forget();
      this.stop();
      this.status.textContent = '';
      this.app.reportError(`${this.settings.label}: ${errorMessage(e)}`);
      this.onFailed?.();
    }
  }

  private async loop(token: number, stream: LiveStream<Chunk>): Promise<void> {
    let first = true;
    while (token === this.token) {
      const ahead = first ? 0 : this.frames - 1 - this.app.viewer.playback.frameFloat;
      if (ahead < (stream.ahead ?? this.settings.ahead)) {
        const chunk = await stream.pull(stream.chunk ?? this.settings.chunk);
        if (token !== this.token) return;
        this.append(chunk, first);
        this.received(chunk, first);
        first = false;
      } else {
        await new Promise((r) => setTimeout(r, 100));
      }
      this.updateStatus();
    }
  }

  private append(chunk: Chunk, first: boolean): void {
    const sk = this.skeleton!;
    const stride = sk.joints.length * 3;
    const playhead = first ? 0 : this.app.viewer.playback.frame;
    const drop = Math.max(0, playhead - this.settings.keep);
    const kept = this.frames - drop;
    const P = new Float32Array((kept + chunk.frames) * stride);
    P.set(this.positions.subarray(drop * stride, this.frames * stride));
    P.set(chunk.positions, kept * stride);
    this.positions = P;
    this.frames = kept + chunk.frames;
    this.start += drop;
    const motion: Motion = { fps: sk.fps, frames: this.frames, joints: sk.joints, parents: sk.parents, positions: P };
    if (chunk.contacts) {
      const C = new Uint8Array(this.frames * 2);
      C.set(this.contacts.subarray(drop * 2, (kept + drop) * 2));
      C.set(chunk.contacts, kept * 2);
      motion.contacts = this.contacts = C;
    } else {
      try {
        motion.contacts = detectContacts(motion);
      } catch {
        // footprints are decoration: a skeleton without recognisable feet just has none
      }
    }
    this.app.showLive(motion, first ? -1 : drop, this.settings.name);
  }

  /** Refreshes the status readout a few times a second. */
  protected updateStatus(force = false): void {
    const now = performance.now();
    if (!force && now - this.statusAt < 250) return;
    this.statusAt = now;
    const f = this.frame;
    this.status.dataset.frame = String(f);
    this.status.textContent = this.describe(f, this.skeleton?.fps ?? 30);
  }
}
