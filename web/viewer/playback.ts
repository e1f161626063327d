// Time-based playback clock: the motion's fps is independent of the display rate.

export const MIN_SPEED = 0.25;
export const MAX_SPEED = 2;

export interface PlaybackState {
  playing: boolean;
  /** Index of the frame being shown (the one at or just before `time`). */
  frame: number;
  /** Seconds since the first frame. */
  time: number;
  speed: number;
  frames: number;
  fps: number;
}

export class Playback {
  fps = 30;
  frames = 0;
  time = 0;
  speed = 1;
  playing = false;
  loop = true;
  /** Live data: at the end, wait (still playing) for more frames instead of looping or stopping. */
  hold = false;

  get duration(): number {
    return this.frames > 1 ? (this.frames - 1) / this.fps : 0;
  }

  /** Fractional frame position, in [0, frames-1]. */
  get frameFloat(): number {
    return Math.min(Math.max(this.time * this.fps, 0), Math.max(this.frames - 1, 0));
  }

  get frame(): number {
    return Math.min(Math.floor(this.time * this.fps + 1e-6), Math.max(this.frames - 1, 0));
  }

  reset(frames: number, fps: number): void {
    this.frames = frames;
    this.fps = fps;
    this.time = 0;
  }

  /** Advances by `dt` seconds of wall time (scaled by speed); wraps at the end when looping. */
  advance(dt: number): void {
    if (!this.playing || this.frames < 2) return;
    this.time += dt * this.speed;
    const d = this.duration;
    if (this.time > d) {
      if (this.hold) this.time = d;
      else if (this.loop) this.time = d > 0 ? this.time % d : 0;
      else { this.time = d; this.playing = false; }
    }
  }

  seek(frame: number): void {
    const f = Math.min(Math.max(frame, 0), Math.max(this.frames - 1, 0));
    this.time = f / this.fps;
  }

  setSpeed(x: number): number {
    this.speed = Math.min(Math.max(x, MIN_SPEED), MAX_SPEED);
    return this.speed;
  }

  state(): PlaybackState {
    return {
      playing: this.playing,
      frame: this.frame,
      time: this.time,
      speed: this.speed,
      frames: this.frames,
      fps: this.fps,
    };
  }
}
