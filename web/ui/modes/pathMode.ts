// Path mode: draw a path on the ground (mouse, pen or touch) and the chosen model walks it (the model
// choice, modelChoice.ts): the generator's path follower (web/optimizer) optimises the motion in the
// generator worker, the latent ERD follows the path in closed loop in its worker (a control signal
// from where the character stands, every latent step: web/runtime/latent_erd/latentErdRequests.ts), or the VAE-LSTM
// makes the whole walk for the whole path in one pass (web/runtime/vae_lstm/vaeLstmRequests.ts), as soon as the path
// is drawn; Vary draws a new latent sample for the same path. Compare has a second model walk the same path
// beside the first (the viewer's companion figure), each with its own numbers. The result plays
// with the path as followed (mint) and the character's root trajectory (the viewer's purple trail) on the ground.
// Redrawing replaces the path; a stroke that is too short, or a failed optimisation, keeps what was there.
// A new path drawn while the last one is being walked, or leaving the mode, cancels that optimisation.

import { MAX_PATH_LENGTH, MIN_PATH_LENGTH } from '../../optimizer/path';
import type { Motion } from '../../motion/types';
import type { ModelDescriptor, PathStats } from '../../runtime/descriptor';
import type { Registry } from '../../runtime/registry';
import { GroundLine, TARGET_COLOR } from '../../viewer/groundPath';
import { $, changeTo, element, errorMessage, readSeed, setSliderFill } from '../dom';
import type { ModeHost } from './host';
import { fillSelect } from './modelChoice';
import type { Gait } from '../../optimizer/pathFollower';

type Point = [number, number];

const DEFAULT_FIT = 0.1;
/** Stroke points closer than this to the previous one are skipped (the optimiser drops < 2 cm anyway). */
const MIN_STEP = 0.01;
/** A press that moves less than this many CSS pixels is a click, not a stroke. */
const CLICK_PIXELS = 4;
/** Ground hits further than this from the view's centre are ignored (rays grazing the horizon). */
const MAX_REACH = 80;
/** Views from about 45° up: steep enough to draw on, and to see a path and its walk. */
const RISE = 1;
/** The drawing view with nothing drawn: this far (m) from a point this far ahead of the origin. */
const DRAWING_DISTANCE = 8;
const DRAWING_AHEAD = 1.5;

/** One model's walk along the path. */
interface Walk {
  motion: Motion;
  /** The path as followed (x, z pairs), drawn on the ground with the result. */
  path: Float32Array;
  stats: PathStats;
  /** The model that walked it. */
  model: string;
}

interface Result extends Walk {
  gait: Gait;
  /** The drawn points it was made from. */
  points: Point[];
  /** Compare: the second model's walk of the same path. */
  other?: Walk;
}

/** `motion` held at its last frame up to `frames` frames (so two walks of one path play side by side). */
function holdTo(motion: Motion, frames: number): Motion {
  if (motion.frames >= frames) return motion;
  const n = motion.joints.length * 3;
  const positions = new Float32Array(frames * n);
  positions.set(motion.positions.subarray(0, motion.frames * n));
  const last = motion.positions.subarray((motion.frames - 1) * n, motion.frames * n);
  for (let f = motion.frames; f < frames; f++) positions.set(last, f * n);
  let contacts: Uint8Array | undefined;
  if (motion.contacts) {
    contacts = new Uint8Array(frames * 2);
    contacts.set(motion.contacts.subarray(0, motion.frames * 2));
    for (let f = motion.frames; f < frames; f++) contacts.set(motion.contacts.subarray((motion.frames - 1) * 2, motion.frames * 2), f * 2);
  }
  return { ...motion, frames, positions, ...(contacts ? { contacts } : {}) };
}

/** A walk's numbers in one line: error, progress, time to compute, foot sliding; and a limit its model states. */
function statsLine(w: Walk, gait: Gait, registry: Registry): string {
  const s = w.stats;
  const secs = (w.motion.frames - 1) / w.motion.fps;
  const sliding = Number.isFinite(s.sliding) ? ` · sliding ${s.sliding.toFixed(2)} m/s` : '';
  const stated = registry.find(w.model)?.descriptor.followPath?.limit?.(gait, secs);
  const limit = stated ? ` · ${stated}` : '';
  return `${registry.shortName(w.model)}: error mean ${(s.meanError * 100).toFixed(1)} cm · max ${(s.maxError * 100).toFixed(1)} cm · ${Math.round(s.arcProgress * 100)} % of the path · ` +
    `${(s.optimizeMs / 1000).toFixed(1)} s for ${secs.toFixed(1)} s of motion${sliding}${limit}`;
}

function pathLength(points: Point[]): number {
  let length = 0;
  for (let i = 1; i < points.length; i++) length += Math.hypot(points[i][0] - points[i - 1][0], points[i][1] - points[i - 1][1]);
  return length;
}

const flat = (points: Point[]) => Float32Array.from(points.flat());

export class PathMode {
  private readonly gait = $<HTMLSelectElement>('path-gait');
  private readonly fit = $<HTMLInputElement>('path-fit');
  private readonly fitOut = $('path-fit-out');
  private readonly seed = $<HTMLInputElement>('path-seed');
  private readonly speed = $<HTMLInputElement>('path-speed');
  private readonly speedOut = $('path-speed-out');
  private readonly compare = $<HTMLSelectElement>('path-compare');
  private readonly varyBtn = $<HTMLButtonElement>('path-vary');
  private readonly goBtn = $<HTMLButtonElement>('path-go');
  private readonly clearBtn = $<HTMLButtonElement>('path-clear');
  private readonly progress = $<HTMLProgressElement>('path-progress');
  private readonly status = $('path-status');
  private readonly hint = $('path-hint');
  private readonly line = new GroundLine(TARGET_COLOR, 0.05, 0.75);

  private active = false;
  /** The optimisation under way (aborted when it is no longer wanted), or null. */
  private optimising: AbortController | null = null;
  /** The drawn path (empty: none). */
  private points: Point[] = [];
  private result: Result | null = null;
  /** The stroke being drawn. */
  private stroke: { id: number; points: Point[]; x: number; y: number; moved: boolean; follow: boolean } | null = null;
  private followBefore = true;
  /** A path was given (setPath) and is walked when the mode is entered. */
  private walkPending = false;

  constructor(private readonly app: ModeHost) {
    app.viewer.scene.add(this.line.mesh);
    this.fit.value = String(DEFAULT_FIT);
    this.showFit();
    this.fit.addEventListener('input', () => this.showFit());
    this.showSpeed();
    this.speed.addEventListener('input', () => this.showSpeed());
    this.gait.addEventListener('change', () => {
      // The gait's usual speed, as the models that take a speed ask for it when given none.
      const speeds = this.app.registry.with('followPath').map((m) => m.descriptor.followPath!.defaultSpeed).find((s) => s !== undefined);
      if (speeds) this.speed.value = String(speeds[this.params().gait]);
      this.showSpeed();
    });
    // Only the generator has a fit tolerance (the optimiser's), only the others a speed: the slider of the
    // other kind is off while a model is chosen. The VAE-LSTM walks a drawn path at once.
    app.controlModel.onChange(() => {
      this.showState();
      if (this.follower()?.immediate && this.points.length && !this.current()) void this.go();
    });
    // Another style for a model with styles: a walked path is walked again in it.
    app.controlStyle.onChange(() => {
      if (this.active && this.app.stylesOf(this.app.controlModel.value).length && this.points.length && this.current() && !this.busy) void this.go();
    });
    this.compare.addEventListener('change', () => this.showState());
    this.varyBtn.addEventListener('click', () => this.vary());
    this.goBtn.addEventListener('click', () => void this.go());
    this.clearBtn.addEventListener('click', () => this.clear());

    // Capture phase on the stage, so a drawing press turns the orbit controls off before they see it.
    const canvas = app.viewer.canvas;
    canvas.parentElement!.addEventListener('pointerdown', (e) => this.onDown(e), { capture: true });
    canvas.addEventListener('pointermove', (e) => this.onMove(e));
    canvas.addEventListener('pointerup', (e) => this.onUp(e, false));
    canvas.addEventListener('pointercancel', (e) => this.onUp(e, true));
    canvas.addEventListener('lostpointercapture', (e) => this.onUp(e, true));
  }

  enter(): void {
    this.active = true;
    const viewer = this.app.viewer;
    this.followBefore = viewer.layers().follow;
    // Left drag draws; the right button turns the view instead of panning.
    viewer.setRightDragRotates(true);
    if (this.result) {
      this.display(this.result);
    } else {
      this.app.clearMotion();
      this.app.setLiveLabel('Path', 'draw a path on the ground');
      this.line.set(flat(this.points));
      if (this.points.length) viewer.frameGround(flat(this.points), RISE);
      else this.drawingView();
      this.app.syncLayers();
    }
    this.showState();
    this.walkGiven();
  }

  leave(): void {
    this.active = false;
    this.cancelOptimisation();
    this.cancelStroke();
    this.line.clear();
    const viewer = this.app.viewer;
    viewer.setRightDragRotates(false);
    viewer.setLayers({ follow: this.followBefore });
    this.app.syncLayers();
    viewer.invalidate();
  }

  /** Looks down at the ground ahead of the origin (the camera's compass direction kept), not following. */
  private drawingView(): void {
    this.app.viewer.lookAtGround(0, DRAWING_AHEAD, DRAWING_DISTANCE, RISE);
  }

  private showFit(): void {
    const v = Number(this.fit.value);
    this.fitOut.textContent = `${v.toFixed(2)} m`;
    setSliderFill(this.fit, (v - Number(this.fit.min)) / (Number(this.fit.max) - Number(this.fit.min)));
  }

  private showSpeed(): void {
    const v = Number(this.speed.value);
    this.speedOut.textContent = `${v.toFixed(1)} m/s`;
    setSliderFill(this.speed, (v - Number(this.speed.min)) / (Number(this.speed.max) - Number(this.speed.min)));
  }

  private params(): { gait: Gait; seed: number; fitSigma: number; speed: number } {
    const seed = readSeed(this.seed);
    const fitSigma = Math.min(Math.max(Number(this.fit.value) || DEFAULT_FIT, 0.05), 0.5);
    const speed = Math.min(Math.max(Number(this.speed.value) || 1.2, 0.4), 3.2);
    return { gait: this.gait.value === 'run' ? 'run' : 'walk', seed, fitSigma, speed };
  }

  /** Lists the registry's path followers in Compare's picker (the model picker is the shared ModelChoice). */
  list(registry: Registry): void {
    fillSelect(this.compare, registry, registry.ids('followPath'));
    this.showState();
  }

  /** How the chosen model (or `model`) follows paths, or undefined before the models are listed. */
  private follower(model = this.app.controlModel.value): NonNullable<ModelDescriptor['followPath']> | undefined {
    return this.app.registry.find(model)?.descriptor.followPath;
  }

  /** The model Compare adds beside the chosen one, or null (off, or the same model). */
  private compareModel(): string | null {
    const v = this.compare.value;
    return v && v !== this.app.controlModel.value && this.app.registry.can(v, 'followPath') ? v : null;
  }

  /** Whether the shown walk is of the drawn path. */
  private current(): boolean {
    return this.result !== null && this.result.points === this.points;
  }

  // ---------- drawing ----------

  /** The ground point under a pointer, or null (sky, or too far away). */
  private groundAt(e: PointerEvent): Point | null {
    return this.app.viewer.groundAt(e.clientX, e.clientY, MAX_REACH);
  }

  private onDown(e: PointerEvent): void {
    if (!this.active || this.stroke || !e.isPrimary || e.button !== 0 || e.ctrlKey || e.metaKey || e.altKey) return;
    const p = this.groundAt(e);
    if (!p) return; // off the ground: let the controls turn the view
    const viewer = this.app.viewer;
    viewer.controls.enabled = false;
    viewer.canvas.setPointerCapture(e.pointerId);
    // The camera holds still while drawing.
    const follow = viewer.layers().follow;
    if (follow) viewer.setLayers({ follow: false });
    this.stroke = { id: e.pointerId, points: [p], x: e.clientX, y: e.clientY, moved: false, follow };
    this.hint.hidden = true;
    this.line.set(flat(this.stroke.points));
    viewer.invalidate();
    e.preventDefault();
  }

  private onMove(e: PointerEvent): void {
    const s = this.stroke;
    if (!s || e.pointerId !== s.id) return;
    if (Math.hypot(e.clientX - s.x, e.clientY - s.y) >= CLICK_PIXELS) s.moved = true;
    let added = false;
    for (const ev of e.getCoalescedEvents?.() ?? [e]) {
      const p = this.groundAt(ev);
      if (!p) continue;
      const last = s.points[s.points.length - 1];
      if (Math.hypot(p[0] - last[0], p[1] - last[1]) < MIN_STEP) continue;
      s.points.push(p);
      added = true;
    }
    if (added) {
      this.line.set(flat(s.points));
      this.app.viewer.invalidate();
    }
  }

  private onUp(e: PointerEvent, cancelled: boolean): void {
    const s = this.stroke;
    if (!s || e.pointerId !== s.id) return;
    this.endStroke(s);
    if (cancelled) {
      this.restoreLine();
      return;
    }
    const length = pathLength(s.points);
    if (!s.moved && length < MIN_PATH_LENGTH) {
      // A click: nothing drawn.
      this.restoreLine();
      if (!this.points.length) this.app.note('Drag on the ground to draw a path (right-drag turns the view).');
      return;
    }
    if (length < MIN_PATH_LENGTH || length > MAX_PATH_LENGTH) {
      this.restoreLine();
      const kept = this.points.length ? ' The previous path is kept.' : '';
      this.app.reportError(
        length < MIN_PATH_LENGTH
          ? `Path: that stroke is ${length.toFixed(2)} m long; draw at least ${MIN_PATH_LENGTH} m.${kept}`
          : `Path: that stroke is ${length.toFixed(0)} m long; at most ${MAX_PATH_LENGTH} m can be walked.${kept}`,
      );
      return;
    }
    this.points = s.points;
    // The walk being optimised is for the path just replaced.
    this.cancelOptimisation();
    this.showState();
    // A model whose walk takes a fraction of a second (the VAE-LSTM) walks it as soon as it is drawn.
    if (this.follower()?.immediate) void this.go();
  }

  private endStroke(s: NonNullable<PathMode['stroke']>): void {
    this.stroke = null;
    const viewer = this.app.viewer;
    viewer.controls.enabled = true;
    if (s.follow) viewer.setLayers({ follow: true });
    const canvas = viewer.canvas;
    if (canvas.hasPointerCapture(s.id)) canvas.releasePointerCapture(s.id);
  }

  private cancelStroke(): void {
    if (!this.stroke) return;
    this.endStroke(this.stroke);
    this.restoreLine();
  }

  /** The line for what is kept: the followed path of the shown result if it is the drawn one, else the drawn path. */
  private restoreLine(): void {
    const r = this.result;
    this.line.set(r && r.points === this.points ? r.path : flat(this.points));
    this.hint.hidden = this.points.length > 0 || r !== null;
    this.app.viewer.invalidate();
  }

  /** The seed of the next walk (Vary counts it up). */
  get seedValue(): number {
    return Number(this.seed.value) || 0;
  }

  /** Sets the seed a view gives, as if the user had. */
  presetSeed(seed: number): void {
    changeTo(this.seed, String(seed));
  }

  /** The drawn path, [x, z] per point (empty: none). */
  get path(): Point[] {
    return this.points.map(([x, z]) => [x, z]);
  }

  /**
   * A path given rather than drawn (a link, the element's `path` attribute): shown, and walked at once
   * when the mode is on (else when it is entered, by `walkGiven`).
   */
  setPath(points: Point[]): void {
    this.cancelOptimisation();
    this.points = points.map(([x, z]): Point => [x, z]);
    this.result = null;
    this.walkPending = true;
    if (this.active) this.walkGiven();
  }

  /** Walks a given path once the mode is on. */
  private walkGiven(): void {
    if (!this.walkPending) return;
    this.walkPending = false;
    this.line.set(flat(this.points));
    this.hint.hidden = true;
    this.app.viewer.frameGround(flat(this.points), RISE);
    void this.go();
  }

  private clear(): void {
    if (this.busy) return;
    this.points = [];
    this.result = null;
    this.line.clear();
    this.app.clearMotion();
    this.app.setLiveLabel('Path', 'draw a path on the ground');
    this.drawingView();
    this.showState();
  }

  // ---------- optimising ----------

  private get busy(): boolean {
    return this.optimising !== null;
  }

  /** Stops the optimisation under way, if any: its walk is no longer wanted (a new path, or the mode left). */
  private cancelOptimisation(): void {
    const run = this.optimising;
    if (!run) return;
    this.optimising = null;
    run.abort();
    this.showState();
  }

  /** Vary: the next seed, a new walk of the same path (the VAE-LSTM draws a new latent sample). */
  private vary(): void {
    if (this.busy || !this.points.length) return;
    this.seed.value = String((readSeed(this.seed) + 1) % 2 ** 32);
    void this.go();
  }

  /** One model's walk along `points` (loading it on first use; a worker that failed is started afresh next time). */
  private async walk(model: string, points: Point[], signal: AbortSignal, onProgress: (fraction: number) => void): Promise<Walk> {
    const { gait, seed, fitSigma, speed } = this.params();
    const follow = this.follower(model);
    if (!follow) throw new Error(`model "${model}" does not follow paths`);
    // Each model reads the setting it has: the optimiser's fit tolerance, or the speed asked for.
    const own = { ...(follow.options.includes('fitTolerance') ? { fitSigma } : {}), ...(follow.options.includes('speed') ? { speed } : {}) };
    const style = this.app.controlStyle.for(this.app.stylesOf(model));
    const r = await this.app.withModel(model, (client) => follow.run(client, { points, gait, seed, ...own, stroke: true, ...(style ? { style } : {}) }, { signal, onProgress }));
    return { motion: r.motion, path: r.path, stats: r.stats, model };
  }

  private async go(): Promise<void> {
    if (this.busy) return;
    const points = this.points;
    if (!points.length) {
      this.app.reportError('Path: draw a path on the ground first (drag on the floor).');
      return;
    }
    const { gait } = this.params();
    const run = (this.optimising = new AbortController());
    this.progress.value = 0;
    this.showState();
    try {
      await this.app.whenModels(); // a path a link gives is walked once the models are listed
      if (run.signal.aborted) return;
      const model = this.app.controlModel.value;
      if (!model) throw new Error('no model that follows paths is listed in models/index.json');
      const other = this.compareModel();
      const progressOf = (m: string, part: number, parts: number) => (fraction: number) => {
        this.progress.value = (part + fraction) / parts;
        const what = this.follower(m)?.working(gait) ?? 'walking the path';
        this.status.textContent = `${what}… ${Math.round(fraction * 100)} %`;
      };
      const parts = other ? 2 : 1;
      // One after the other, so each one's time to compute is its own.
      const main = await this.walk(model, points, run.signal, progressOf(model, 0, parts));
      const second = other ? await this.walk(other, points, run.signal, progressOf(other, 1, parts)) : undefined;
      if (run.signal.aborted) return;
      this.result = { ...main, gait, points, ...(second ? { other: second } : {}) };
      this.optimising = null;
      // Not cancelled by a new path or by leaving the mode: the result is for the drawn path, in Path mode.
      this.display(this.result);
    } catch (e) {
      // Cancelled: whatever cancelled it has already set the state, and the walk is not wanted.
      if (run.signal.aborted) return;
      this.optimising = null;
      this.app.reportError(`Path: ${errorMessage(e)}`);
    }
    this.showState();
  }

  private display(r: Result): void {
    const viewer = this.app.viewer;
    const registry = this.app.registry;
    const frames = Math.max(r.motion.frames, r.other?.motion.frames ?? 0);
    this.app.showInMode(holdTo(r.motion, frames), `path-${r.gait}`);
    if (r.other) {
      viewer.setCompanion({ motion: holdTo(r.other.motion, frames), labels: { main: registry.shortName(r.model), companion: registry.shortName(r.other.model) } });
    }
    const secs = (r.motion.frames - 1) / r.motion.fps;
    const vs = r.other ? ` vs ${registry.shortName(r.other.model)}` : '';
    this.app.setLiveLabel('Path', `${registry.shortName(r.model)}${vs} · ${r.gait} · ${r.motion.frames} frames · ${secs.toFixed(1)} s · ${viewer.footprintCount} steps`);
    this.line.set(r.points === this.points ? r.path : flat(this.points));
    viewer.frameGround(r.path, RISE);
    viewer.lowerView(0.08); // so the walk sits above the control bar
    this.app.syncLayers();
  }

  // ---------- status ----------

  private showState(): void {
    const r = this.result;
    const current = r !== null && r.points === this.points;
    this.goBtn.disabled = this.busy || !this.points.length;
    this.goBtn.textContent = this.busy ? 'Working…' : 'Go';
    this.clearBtn.disabled = this.busy || (!this.points.length && !r);
    this.progress.hidden = !this.busy;
    this.status.dataset.state = this.busy ? 'optimising' : current ? 'done' : this.points.length ? 'drawn' : 'empty';
    const model = this.app.controlModel.value;
    // The model chosen, and the one whose walk is shown.
    this.status.dataset.model = model;
    if (current) this.status.dataset.walkedBy = r.model;
    else delete this.status.dataset.walkedBy;
    if (current && r.other) this.status.dataset.comparedWith = r.other.model;
    else delete this.status.dataset.comparedWith;
    const follow = this.follower();
    const options = follow?.options ?? [];
    this.fit.disabled = !options.includes('fitTolerance');
    if (this.fit.disabled) this.fit.title = `The ${this.app.registry.shortName(model)} has no optimiser: it has no fit tolerance`;
    else this.fit.removeAttribute('title');
    this.speed.disabled = !options.includes('speed');
    this.varyBtn.hidden = !follow?.varies;
    this.varyBtn.disabled = this.busy || !this.points.length;
    this.hint.hidden = this.points.length > 0 || r !== null || this.stroke !== null;
    this.status.replaceChildren();
    if (this.busy) {
      this.status.textContent = 'starting…';
    } else if (current) {
      for (const w of r.other ? [r, r.other] : [r]) {
        const line = element('span', 'path-stats', statsLine(w, r.gait, this.app.registry));
        line.dataset.model = w.model;
        this.status.append(line);
      }
      this.status.append(legend('path', 'drawn path'), legend('walked', 'walked (root)'));
    } else if (this.points.length) {
      this.status.textContent = `path ${pathLength(this.points).toFixed(1)} m · Go walks it${r ? ' (showing the walk along the previous path)' : ''}`;
    } else {
      this.status.textContent = 'drag on the ground to draw a path · right-drag turns the view';
    }
  }
}

function legend(kind: string, text: string): HTMLElement {
  return element('span', `legend legend-${kind}`, text);
}
