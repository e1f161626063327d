// Steer mode: live control by speed and heading, of the generator (Wang, Chai, Xia §5.3, Fig. 9) or the
// latent ERD (the model choice, modelChoice.ts). The generator's live controller (in its worker) optimises 6
// frames at a time toward the current target; the latent ERD (in its worker) makes one latent step of 4
// frames at a time, its control signal controlTowardHeading(root heading, target heading, target speed)
// from where the character stands (web/motion/control.ts); both a little ahead of the playhead
// (LiveMode), feet locked. Inputs: keyboard (turn and speed), a gamepad's left stick or
// the on-screen stick (direction relative to the camera, push further to go faster), the speed slider.
// A mint arrow on the ground at the character shows the target heading; the readout at the top left
// compares target and achieved speed.

import { angleDifference } from '../../optimizer/path';
import type { LiveControlChunk, ModelClientBase, ModelDescriptor } from '../../runtime/descriptor';
import { GroundArrow, TARGET_COLOR } from '../../viewer/groundPath';
import { $, currentScope, setSliderFill } from '../dom';
import type { ModeHost } from './host';
import { LiveMode, type LiveStream } from './liveMode';
import type { Gait } from '../../optimizer/pathFollower';

/** What a live batch of either model carries: frames, achieved speed and heading per frame, compute time. */
type SteerChunk = LiveControlChunk;


/** Frames per optimised batch, and frames kept ready beyond the playhead (0.4 s at 30 fps). */
const BATCH = 6;
const AHEAD = 12;
/** Turn rate of the left / right keys (rad/s) and speed change of up / down (m/s per second). */
const TURN_RATE = Math.PI / 2;
const SPEED_RATE = 1;
const MAX_SPEED = 3;
/** Speed the slider starts at per gait (set when the gait changes). */
const GAIT_SPEED: Record<Gait, number> = { walk: 1.2, run: 2.5 };
const STICK_DEAD_ZONE = 0.2;
/**
 * The camera swings round behind the character's facing, a little to its side (rad), at this rate
 * (1/s), from this far and this high (direction's y before normalising); a drag of the view pauses
 * the swing for CHASE_PAUSE ms.
 */
const CHASE_SIDE = 0.45;
const CHASE_RATE = 0.9;
const CHASE_DISTANCE = 6.5;
const CHASE_RISE = 0.5;
const CHASE_PAUSE = 2500;
/**
 * Particle budget of the live loop: a batch should take well under the 0.2 s it lasts. Slower than 70% of
 * that, the next batch uses a quarter fewer particles (down to 8); faster than 35%, a quarter more (up to
 * the controller's default 24, which the report measures). A busy machine then steers a little less
 * precisely instead of stalling the playback.
 */
const PARTICLES_MAX = 24;
const PARTICLES_MIN = 8;
/** Achieved speed and heading are kept for this many stream frames behind the newest. */
const HISTORY = 900;

const KEYS: Record<string, 'left' | 'right' | 'up' | 'down'> = {
  ArrowLeft: 'left', a: 'left', A: 'left',
  ArrowRight: 'right', d: 'right', D: 'right',
  ArrowUp: 'up', w: 'up', W: 'up',
  ArrowDown: 'down', s: 'down', S: 'down',
};

const degrees = (a: number) => Math.round((angleDifference(a, 0) * 180) / Math.PI);

export class SteerMode extends LiveMode<SteerChunk> {
  private readonly gait = $<HTMLSelectElement>('steer-gait');
  private readonly speed = $<HTMLInputElement>('steer-speed');
  private readonly speedOut = $('steer-speed-out');
  private readonly readout = $('steer-readout');
  private readonly targetBar = $('steer-target-bar');
  private readonly achievedBar = $('steer-achieved-bar');
  private readonly targetText = $('steer-target-speed');
  private readonly achievedText = $('steer-achieved-speed');
  private readonly headingText = $('steer-heading');
  private readonly joystick = $('steer-joystick');
  private readonly knob = $('steer-knob');
  private readonly statusLine = $('steer-status');
  private readonly scope = currentScope();
  private readonly arrow = new GroundArrow(TARGET_COLOR, 0.85);
  private client: { id: string; client: ModelClientBase } | undefined;
  /** The model of the stream running (the choice when it started), and how it is steered. */
  private model = '';
  private live: NonNullable<ModelDescriptor['liveControl']> | undefined;
  private seedName = '';

  /**
   * The target: heading (rad, world), the cruising speed (the slider's, kept unrounded so held keys
   * change it smoothly) and a throttle 0…1 on it (sticks set it; keys and the slider reset it to 1).
   */
  private heading = 0;
  private cruise = GAIT_SPEED.walk;
  private throttle = 1;
  private readonly held = new Set<'left' | 'right' | 'up' | 'down'>();
  /** The on-screen stick while pressed: its pointer and offset (−1…1, y down). */
  private pad: { id: number; x: number; y: number } | null = null;
  /** A gamepad stick was out of its dead zone last frame. */
  private gamepadActive = false;
  private frameRequest = 0;
  private lastTick = 0;
  private readoutAt = 0;
  /** What the arrow shows (x, z, heading, length), to redraw only on change. */
  private arrowShown = '';
  /** Achieved speed and heading per stream frame from `historyStart`; batch times for the status. */
  private history = { start: 0, speed: [] as number[], heading: [] as number[] };
  private computeMs = 0;
  private particles = PARTICLES_MAX;
  /** The running stream's style (a model with styles). */
  private streamStyle: string | undefined;
  /** Until when the camera is left where the user turned it. */
  private chasePausedUntil = 0;

  constructor(app: ModeHost) {
    // 20 s kept behind the playhead.
    super(app, $('steer-status'), { chunk: BATCH, ahead: AHEAD, keep: 600, label: 'Steer', name: 'steer' });
    app.viewer.scene.add(this.arrow.mesh);
    this.setSpeed(GAIT_SPEED.walk);
    this.speed.addEventListener('input', () => {
      this.throttle = 1;
      this.setSpeed(Number(this.speed.value), false);
    });
    this.gait.addEventListener('change', () => {
      this.setSpeed(GAIT_SPEED[this.gaitValue]);
      this.restartIfActive();
    });
    // Another model: a new stream at the origin (choosing the VAE-LSTM in Path mode changes nothing here).
    app.controlModel.onChange(() => {
      if (app.controlModel.steerable !== this.model) this.restartIfActive();
    });
    // Another style: the running stream blends into it over about a second, where it goes on.
    app.controlStyle.onChange(() => this.switchStyle());
    // On the document, so it runs before the page's own shortcuts (on window), which it then skips.
    const signal = currentScope().signal; // the page's listeners go with the element's playground
    document.addEventListener('keydown', (e) => this.onKey(e, true), { signal });
    document.addEventListener('keyup', (e) => this.onKey(e, false), { signal });
    window.addEventListener('blur', () => this.held.clear(), { signal });
    app.viewer.controls.addEventListener('start', () => (this.chasePausedUntil = Infinity));
    app.viewer.controls.addEventListener('end', () => (this.chasePausedUntil = performance.now() + CHASE_PAUSE));
    this.joystick.addEventListener('pointerdown', (e) => this.onPad(e, 'down'));
    this.joystick.addEventListener('pointermove', (e) => this.onPad(e, 'move'));
    this.joystick.addEventListener('pointerup', (e) => this.onPad(e, 'up'));
    this.joystick.addEventListener('pointercancel', (e) => this.onPad(e, 'up'));
  }

  private get gaitValue(): Gait {
    return this.gait.value === 'run' ? 'run' : 'walk';
  }

  /** The speed asked for now (m/s). */
  get targetSpeed(): number {
    return this.cruise * this.throttle;
  }

  get targetHeading(): number {
    return this.heading;
  }

  private setSpeed(v: number, moveSlider = true): void {
    this.cruise = Math.min(Math.max(v, 0), MAX_SPEED);
    if (moveSlider) this.speed.value = String(this.cruise);
    this.speedOut.textContent = `${this.cruise.toFixed(1)} m/s`;
    setSliderFill(this.speed, this.cruise / MAX_SPEED);
  }

  override async begin(): Promise<void> {
    const viewer = this.app.viewer;
    viewer.setLayers({ follow: true });
    this.app.syncLayers();
    this.lastTick = performance.now();
    cancelAnimationFrame(this.frameRequest);
    this.frameRequest = requestAnimationFrame((t) => this.tick(t));
    await super.begin();
  }

  override stop(): void {
    super.stop();
    cancelAnimationFrame(this.frameRequest);
    this.held.clear();
    this.releasePad();
    this.arrow.hide();
    this.arrowShown = '';
    this.app.viewer.invalidate();
  }

  protected async open(signal: AbortSignal): Promise<LiveStream<SteerChunk>> {
    await this.app.whenModels();
    signal.throwIfAborted();
    const model = (this.model = this.app.controlModel.steerable);
    const live = (this.live = this.app.registry.find(model)?.descriptor.liveControl);
    if (!live) throw new Error('no model that takes live control is listed in models/index.json');
    this.statusLine.dataset.model = model;
    const { client, info } = await this.app.host(model).load();
    signal.throwIfAborted();
    this.client = { id: model, client };
    const style = this.app.controlStyle.for(this.app.stylesOf(model));
    const stream = await live.start(client, { seed: 0, gait: this.gaitValue, ...(style ? { style } : {}) }, { signal });
    this.seedName = stream.seedName;
    this.streamStyle = style;
    // The stream starts at the origin facing +z, at the slider's speed.
    this.heading = 0;
    this.throttle = 1;
    this.history = { start: 0, speed: [], heading: [] };
    this.computeMs = 0;
    this.particles = PARTICLES_MAX;
    this.app.setLiveLabel('Steer', `${this.app.registry.shortName(model)} · ${info.fps} fps · live control · ${this.gaitValue}`);
    const target = () => ({ speed: this.targetSpeed, heading: this.heading, ...(live.particles ? { particles: this.particles } : {}) });
    return {
      skeleton: info,
      ...(live.chunk ? { chunk: live.chunk } : {}),
      ...(live.ahead ? { ahead: live.ahead } : {}),
      pull: (frames) => live.pull(client, frames, target(), { signal }),
    };
  }

  /** A new style for the running stream (a model with styles): it switches from its next batch, blended over a second. */
  private switchStyle(): void {
    const client = this.client;
    const live = this.live;
    if (!this.running || !client || !live?.switchStyle || client.id !== this.app.controlModel.steerable) return;
    const style = this.app.controlStyle.for(this.app.stylesOf(client.id));
    if (!style || style === this.streamStyle) return;
    this.streamStyle = style;
    live.switchStyle(client.client, style, {}).catch((e: unknown) => this.app.reportError(`Steer: ${e instanceof Error ? e.message : String(e)}`));
  }

  protected forget(): void {
    if (this.client) this.app.host(this.client.id).reset(this.client.client);
  }

  protected received(chunk: SteerChunk, first: boolean): void {
    if (first) this.placeCamera();
    const h = this.history;
    const at = chunk.startFrame - h.start;
    h.speed.length = h.heading.length = Math.max(0, at);
    h.speed.push(...chunk.speed);
    h.heading.push(...chunk.heading);
    if (h.speed.length > HISTORY + 300) {
      h.speed.splice(0, 300);
      h.heading.splice(0, 300);
      h.start += 300;
    }
    this.computeMs = this.computeMs ? this.computeMs * 0.8 + chunk.computeMs * 0.2 : chunk.computeMs;
    if (!this.live?.particles) return; // the particle budget is a searching controller's
    const budget = (chunk.frames / 30) * 1000;
    if (chunk.computeMs > 0.7 * budget) this.particles = Math.max(PARTICLES_MIN, Math.round(this.particles * 0.75));
    else if (chunk.computeMs < 0.35 * budget) this.particles = Math.min(PARTICLES_MAX, Math.round(this.particles * 1.25));
  }

  protected describe(frame: number, fps: number): string {
    const time = `frame ${frame} · ${(frame / fps).toFixed(1)} s · ${this.seedName}`;
    if (!this.live?.particles) return `${time} · ${this.app.registry.shortName(this.model)} · ${this.computeMs.toFixed(1)} ms per ${this.live?.chunk ?? BATCH} frames`;
    return `${time} · ${Math.round(this.computeMs)} ms per ${BATCH} frames · ${this.particles} particles`;
  }

  // ---------- camera ----------

  /** A new stream: the camera behind the character (facing +z), a little to its side, a little further back than for a clip. */
  private placeCamera(): void {
    this.app.viewer.placeBehind(0, CHASE_SIDE, CHASE_DISTANCE, CHASE_RISE);
    this.chasePausedUntil = 0;
  }

  /** Swings the camera's compass direction toward behind the character's facing. */
  private chase(dt: number, facing: number, now: number): void {
    if (!Number.isFinite(facing) || now < this.chasePausedUntil || !this.app.viewer.layers().follow) return;
    this.app.viewer.swingBehind(facing, CHASE_SIDE, 1 - Math.exp(-dt * CHASE_RATE));
  }

  // ---------- inputs ----------

  private onKey(e: KeyboardEvent, down: boolean): void {
    if (!this.running || e.altKey || e.ctrlKey || e.metaKey || (down && !this.scope.ownsEvent(e))) return; // a release always lets go
    const key = KEYS[e.key];
    if (!key) return;
    const t = (e.composedPath()[0] ?? e.target) as HTMLElement | null; // inside the shadow root, not the host
    // Typing in a number field keeps its keys.
    if (t && (t.tagName === 'TEXTAREA' || (t.tagName === 'INPUT' && !['range', 'checkbox', 'button'].includes((t as HTMLInputElement).type)))) return;
    e.preventDefault();
    if (down) {
      this.held.add(key);
      if (key === 'up' || key === 'down') this.throttle = 1;
    } else {
      this.held.delete(key);
    }
  }

  private onPad(e: PointerEvent, kind: 'down' | 'move' | 'up'): void {
    if (kind === 'down') {
      if (this.pad) return;
      this.joystick.setPointerCapture(e.pointerId);
      this.pad = { id: e.pointerId, x: 0, y: 0 };
      this.joystick.classList.add('active');
    }
    if (!this.pad || e.pointerId !== this.pad.id) return;
    e.preventDefault();
    if (kind === 'up') {
      this.releasePad();
      return;
    }
    const r = this.joystick.getBoundingClientRect();
    const radius = r.width / 2;
    let x = (e.clientX - (r.left + radius)) / radius, y = (e.clientY - (r.top + r.height / 2)) / radius;
    const l = Math.hypot(x, y);
    if (l > 1) { x /= l; y /= l; }
    this.pad.x = x;
    this.pad.y = y;
    const reach = radius - this.knob.offsetWidth / 2;
    this.knob.style.transform = `translate(${x * reach}px, ${y * reach}px)`;
  }

  /** Letting go of a stick stops the character (throttle 0), as a stick should. */
  private releasePad(): void {
    if (!this.pad) return;
    this.pad = null;
    this.throttle = 0;
    this.knob.style.transform = '';
    this.joystick.classList.remove('active');
  }

  /** A stick offset (x right, y down, magnitude ≤ 1) → heading relative to the camera (up = away from it) and throttle. */
  private applyStick(x: number, y: number): void {
    const l = Math.hypot(x, y);
    if (l < STICK_DEAD_ZONE) return;
    const view = this.app.viewer.viewHeading();
    const fx = Math.sin(view), fz = Math.cos(view);
    // Screen right on the ground is forward × up = (−fz, fx).
    const dx = fx * -y + -fz * x, dz = fz * -y + fx * x;
    this.heading = Math.atan2(dx, dz);
    this.throttle = Math.min(1, (l - STICK_DEAD_ZONE) / (1 - STICK_DEAD_ZONE));
  }

  private pollGamepad(): void {
    const pads = navigator.getGamepads?.() ?? [];
    let x = 0, y = 0;
    for (const gp of pads) {
      if (gp && gp.connected && gp.axes.length >= 2) {
        x = gp.axes[0];
        y = gp.axes[1];
        break;
      }
    }
    const active = Math.hypot(x, y) >= STICK_DEAD_ZONE;
    if (active) this.applyStick(x, y);
    else if (this.gamepadActive) this.throttle = 0;
    this.gamepadActive = active;
  }

  private tick(now: number): void {
    if (!this.running) return;
    this.frameRequest = requestAnimationFrame((t) => this.tick(t));
    const dt = Math.min(Math.max((now - this.lastTick) / 1000, 0), 0.1);
    this.lastTick = now;
    const turn = (this.held.has('left') ? 1 : 0) - (this.held.has('right') ? 1 : 0);
    // Left turns the character to its own left: from +z toward +x, a growing heading.
    if (turn) this.heading = angleDifference(this.heading + turn * TURN_RATE * dt, 0);
    const faster = (this.held.has('up') ? 1 : 0) - (this.held.has('down') ? 1 : 0);
    if (faster) this.setSpeed(this.cruise + faster * SPEED_RATE * dt);
    this.pollGamepad();
    if (this.pad) this.applyStick(this.pad.x, this.pad.y);

    const root = this.app.viewer.rootPosition();
    const length = 0.35 + 0.3 * this.targetSpeed;
    const shown = root ? `${root.x},${root.z},${this.heading},${length}` : '';
    if (root && shown !== this.arrowShown) {
      this.arrow.setLength(length);
      this.arrow.place(root.x, root.z, this.heading);
      this.app.viewer.invalidate();
    }
    this.arrowShown = shown;
    const { speed: achieved, heading: facing } = this.achieved();
    this.chase(dt, facing, now);
    if (now - this.readoutAt > 100) {
      this.readoutAt = now;
      this.showReadout(achieved, facing);
    }
  }

  /** Achieved speed and facing at the playhead (NaN before the first frames). */
  private achieved(): { speed: number; heading: number } {
    const i = this.frame - this.history.start;
    const ok = i >= 0 && i < this.history.speed.length;
    return { speed: ok ? this.history.speed[i] : NaN, heading: ok ? this.history.heading[i] : NaN };
  }

  private showReadout(achieved: number, facing: number): void {
    const target = this.targetSpeed;
    const d = this.readout.dataset;
    d.targetSpeed = target.toFixed(3);
    d.targetHeading = this.heading.toFixed(4);
    d.speed = Number.isFinite(achieved) ? achieved.toFixed(3) : '';
    d.heading = Number.isFinite(facing) ? facing.toFixed(4) : '';
    this.targetText.textContent = target.toFixed(2);
    this.achievedText.textContent = Number.isFinite(achieved) ? achieved.toFixed(2) : '—';
    this.targetBar.style.width = `${(Math.min(target, MAX_SPEED) / MAX_SPEED) * 100}%`;
    this.achievedBar.style.width = `${Number.isFinite(achieved) ? (Math.min(achieved, MAX_SPEED) / MAX_SPEED) * 100 : 0}%`;
    this.headingText.textContent = `heading ${degrees(this.heading)}° · facing ${Number.isFinite(facing) ? `${degrees(facing)}°` : '—'}`;
  }
}
