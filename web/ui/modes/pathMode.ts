// Path mode: draw a path on the ground (mouse, pen or touch) and the chosen model walks it (the model
// choice, modelChoice.ts): the generator's path follower (web/optimizer) optimises the motion in the
// generator worker, or the latent ERD follows the path in closed loop in its worker (a control signal
// from where the character stands, every latent step: web/runtime/latentErdRequests.ts). The result plays
// with the path as followed (mint) and the character's root trajectory (the viewer's purple trail) on the ground.
// Redrawing replaces the path; a stroke that is too short, or a failed optimisation, keeps what was there.
// A new path drawn while the last one is being walked, or leaving the mode, cancels that optimisation.

import * as THREE from 'three';
import { MAX_PATH_LENGTH, MIN_PATH_LENGTH } from '../../optimizer/path';
import type { Motion } from '../../motion/types';
import type { FollowedPath, GeneratorClient } from '../../runtime/generatorClient';
import type { LatentErdClient } from '../../runtime/latentErdClient';
import { GroundLine, TARGET_COLOR } from '../../viewer/groundPath';
import { $, element, errorMessage, readSeed, setSliderFill } from '../dom';
import type { ModeHost } from './host';
import { CONTROL_MODEL_SHORT, type ControlModelId } from './modelChoice';
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

interface Result {
  motion: Motion;
  /** The path as followed (x, z pairs), drawn on the ground with the result. */
  path: Float32Array;
  stats: FollowedPath['stats'];
  gait: Gait;
  /** The model that walked it. */
  model: ControlModelId;
  /** The drawn points it was made from. */
  points: Point[];
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
  private readonly raycaster = new THREE.Raycaster();
  private readonly plane = new THREE.Plane(new THREE.Vector3(0, 1, 0), 0);
  private readonly hit = new THREE.Vector3();

  constructor(private readonly app: ModeHost) {
    app.viewer.scene.add(this.line.mesh);
    this.fit.value = String(DEFAULT_FIT);
    this.showFit();
    this.fit.addEventListener('input', () => this.showFit());
    // The latent ERD has no fit tolerance (no optimiser): its slider is off while it is chosen.
    app.controlModel.onChange(() => this.showState());
    this.goBtn.addEventListener('click', () => void this.go());
    this.clearBtn.addEventListener('click', () => this.clear());

    // Capture phase on the stage, so a drawing press turns the orbit controls off before they see it.
    const canvas = app.viewer.renderer.domElement;
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
    viewer.controls.mouseButtons.RIGHT = THREE.MOUSE.ROTATE;
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
  }

  leave(): void {
    this.active = false;
    this.cancelOptimisation();
    this.cancelStroke();
    this.line.clear();
    const viewer = this.app.viewer;
    viewer.controls.mouseButtons.RIGHT = THREE.MOUSE.PAN;
    viewer.setLayers({ follow: this.followBefore });
    this.app.syncLayers();
    viewer.invalidate();
  }

  /** Looks down at the ground ahead of the origin (the camera's compass direction kept), not following. */
  private drawingView(): void {
    const { camera, controls } = this.app.viewer;
    const dir = camera.position.clone().sub(controls.target).setY(0);
    if (dir.lengthSq() < 1e-6) dir.set(0.6, 0, 0.8);
    dir.normalize().setY(RISE).normalize();
    this.app.viewer.setLayers({ follow: false });
    controls.target.set(0, 0, DRAWING_AHEAD);
    camera.position.copy(controls.target).addScaledVector(dir, DRAWING_DISTANCE);
    controls.update();
    this.app.viewer.invalidate();
  }

  private showFit(): void {
    const v = Number(this.fit.value);
    this.fitOut.textContent = `${v.toFixed(2)} m`;
    setSliderFill(this.fit, (v - Number(this.fit.min)) / (Number(this.fit.max) - Number(this.fit.min)));
  }

  private params(): { gait: Gait; seed: number; fitSigma: number } {
    const seed = readSeed(this.seed);
    const fitSigma = Math.min(Math.max(Number(this.fit.value) || DEFAULT_FIT, 0.05), 0.5);
    return { gait: this.gait.value === 'run' ? 'run' : 'walk', seed, fitSigma };
  }

  // ---------- drawing ----------

  /** The ground point under a pointer, or null (sky, or too far away). */
  private groundAt(e: PointerEvent): Point | null {
    const viewer = this.app.viewer;
    const rect = viewer.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1, -((e.clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, viewer.camera);
    if (!this.raycaster.ray.intersectPlane(this.plane, this.hit)) return null;
    const t = viewer.controls.target;
    if (Math.hypot(this.hit.x - t.x, this.hit.z - t.z) > MAX_REACH) return null;
    return [this.hit.x, this.hit.z];
  }

  private onDown(e: PointerEvent): void {
    if (!this.active || this.stroke || !e.isPrimary || e.button !== 0 || e.ctrlKey || e.metaKey || e.altKey) return;
    const p = this.groundAt(e);
    if (!p) return; // off the ground: let the controls turn the view
    const viewer = this.app.viewer;
    viewer.controls.enabled = false;
    viewer.renderer.domElement.setPointerCapture(e.pointerId);
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
  }

  private endStroke(s: NonNullable<PathMode['stroke']>): void {
    this.stroke = null;
    const viewer = this.app.viewer;
    viewer.controls.enabled = true;
    if (s.follow) viewer.setLayers({ follow: true });
    const canvas = viewer.renderer.domElement;
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

  private async go(): Promise<void> {
    if (this.busy) return;
    const points = this.points;
    if (!points.length) {
      this.app.reportError('Path: draw a path on the ground first (drag on the floor).');
      return;
    }
    const { gait, seed, fitSigma } = this.params();
    const model = this.app.controlModel.value;
    const run = (this.optimising = new AbortController());
    this.progress.value = 0;
    this.showState();
    let client: GeneratorClient | LatentErdClient | undefined;
    try {
      const onProgress = (fraction: number) => {
        this.progress.value = fraction;
        this.status.textContent = `${model === 'latent-erd' ? 'the latent ERD follows the path' : `finding a ${gait} along the path`}… ${Math.round(fraction * 100)} %`;
      };
      let r: Pick<FollowedPath, 'fps' | 'frames' | 'joints' | 'parents' | 'positions' | 'contacts' | 'path' | 'stats'>;
      if (model === 'latent-erd') {
        const erd = (client = (await this.app.latentErd.load()).client);
        r = await erd.followPath({ points, gait, seed, stroke: true }, { signal: run.signal, onProgress });
      } else {
        const generator = (client = (await this.app.generator.load()).client);
        r = await generator.followPath({ points, gait, seed, fitSigma, stroke: true }, { signal: run.signal, onProgress });
      }
      if (run.signal.aborted) return;
      const motion: Motion = { fps: r.fps, frames: r.frames, joints: r.joints, parents: r.parents, positions: r.positions, contacts: r.contacts };
      this.result = { motion, path: r.path, stats: r.stats, gait, points, model };
      this.optimising = null;
      // Not cancelled by a new path or by leaving the mode: the result is for the drawn path, in Path mode.
      this.display(this.result);
    } catch (e) {
      // Cancelled: whatever cancelled it has already set the state, and the walk is not wanted.
      if (run.signal.aborted) return;
      this.optimising = null;
      const message = errorMessage(e);
      // A request the worker refused leaves the worker fine; anything else (a crash) needs a new one.
      if (client && !message.startsWith(`${model} followPath:`)) {
        if (model === 'latent-erd') this.app.latentErd.reset(client as LatentErdClient);
        else this.app.generator.reset(client as GeneratorClient);
      }
      this.app.reportError(`Path: ${message}`);
    }
    this.showState();
  }

  private display(r: Result): void {
    const viewer = this.app.viewer;
    this.app.showInMode(r.motion, `path-${r.gait}`);
    const secs = (r.motion.frames - 1) / r.motion.fps;
    this.app.setLiveLabel('Path', `${CONTROL_MODEL_SHORT[r.model]} · ${r.gait} · ${r.motion.frames} frames · ${secs.toFixed(1)} s · ${viewer.footprintCount} steps`);
    this.line.set(r.points === this.points ? r.path : flat(this.points));
    viewer.frameGround(r.path, RISE);
    // Look a little lower, so the walk sits above the control bar.
    const { camera, controls } = viewer;
    const drop = camera.position.distanceTo(controls.target) * 0.08;
    controls.target.y -= drop;
    camera.position.y -= drop;
    controls.update();
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
    this.fit.disabled = model === 'latent-erd';
    if (model === 'latent-erd') this.fit.title = 'The latent ERD follows the path in closed loop, with no optimiser: it has no fit tolerance';
    else this.fit.removeAttribute('title');
    this.hint.hidden = this.points.length > 0 || r !== null || this.stroke !== null;
    this.status.replaceChildren();
    if (this.busy) {
      this.status.textContent = 'starting…';
    } else if (current) {
      const s = r.stats;
      const secs = (r.motion.frames - 1) / r.motion.fps;
      this.status.append(
        `${r.model === 'latent-erd' ? 'latent ERD · ' : ''}error mean ${(s.meanError * 100).toFixed(1)} cm · max ${(s.maxError * 100).toFixed(1)} cm · ${Math.round(s.arcProgress * 100)} % of the path · ` +
          `${(s.optimizeMs / 1000).toFixed(1)} s for ${secs.toFixed(1)} s of motion`,
        legend('path', 'drawn path'),
        legend('walked', 'walked (root)'),
      );
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
