// Clip mode's Clean up panel (issue 16; docs/models/cleanup.md): clean the shown clip with one of the methods in a
// model worker (map and lowpass in the generator's, manifold in the latent ERD's), with a progress bar and Cancel;
// then the cleaned motion plays as the main figure with the input beside it (grey, the viewer's companion), their
// numbers in a small table (motion/motionStats.ts), one joint's bend angle over time for both (anglePlot.ts) and
// Export BVH of the cleaned motion. The noise tool makes a clean clip noisy (motion/noise.ts) to try it on; the
// clean original stays in memory, so the numbers include the joint error to it and Restore shows it again.
// A failure (a skeleton that cannot be mapped, noise the skeleton cannot take) is shown as the page's message and
// leaves the scene as it was.
//
// For tests: #cleanup-status carries data-state ("clip", "noisy", "cleaning", "cleaned"), data-method (of the
// cleaned motion shown), data-runs (clean-ups finished) and data-noise-seed; #cleanup-readout data-ready when its
// numbers are filled in; the angle plot's canvas its point counts (anglePlot.ts).

import { exportBVH } from '../motion/bvh';
import { bendAngles, bendJoints, cleanupNumbers, type CleanupNumbers } from '../motion/motionStats';
import { addNoise } from '../motion/noise';
import { CANONICAL_JOINTS, mapSkeleton, type CanonicalJoint } from '../motion/skeletonMap';
import type { Motion } from '../motion/types';
import { isCancelled } from '../runtime/worker/cancellation';
import type { CleanupMethod, CleanupStats } from '../runtime/cleanup/cleanup';
import { baseName } from '../runtime/import/motionFiles';
import type { PlaybackState } from '../viewer/playback';
import { AnglePlot } from './anglePlot';
import { $, $all, currentScope, downloadText, errorMessage, setSliderFill } from './dom';
import type { ModeHost } from './modes/host';

/** What each method does, in one line under the select. */
export const METHOD_HINTS: Record<CleanupMethod, string> = {
  map: 'the most likely motion under the generator, close to the input (Wang et al. §5.4); planted feet pinned',
  manifold: 'projected onto the motion autoencoder’s manifold in overlapping 4 s windows (Holden et al.)',
  lowpass: 'zero-phase Butterworth filter on the joint positions at 6 Hz: the usual baseline',
};

const METHOD_NAMES: Record<CleanupMethod, string> = { map: 'MAP', manifold: 'manifold', lowpass: 'low-pass' };

/** What the angle select calls the canonical points (the joint placed there, by the skeleton map). */
const POINT_NAMES: Partial<Record<CanonicalJoint, string>> = {
  LeftLeg: 'left knee', RightLeg: 'right knee', LeftFoot: 'left ankle', RightFoot: 'right ankle',
  LeftUpLeg: 'left hip', RightUpLeg: 'right hip', LeftForeArm: 'left elbow', RightForeArm: 'right elbow',
  LeftArm: 'left shoulder', RightArm: 'right shoulder', LeftHand: 'left wrist', RightHand: 'right wrist',
  Neck: 'neck', Head: 'head',
};

interface Cleaned {
  motion: Motion & { contacts: Uint8Array };
  method: CleanupMethod;
  stats: CleanupStats;
  numbers?: CleanupNumbers;
  /** Bend angles per joint index. */
  angles: Map<number, Float32Array>;
}

/** What the panel knows about the clip in Clip mode. */
interface Session {
  /** The user's clip (the clean original once noise was added). */
  clip: Motion;
  name: string;
  /** The noisy version made with the noise tool, shown as the input; null: the clip itself is the input. */
  noisy: { motion: Motion; label: string } | null;
  cleaned: Cleaned | null;
  /** The input's numbers (computed when first shown). */
  inputNumbers?: CleanupNumbers;
  /** Bend angles per joint index, of the input and the original (cleared when the input changes). */
  angles: Map<string, Float32Array>;
  /** The joint plotted by default, and the joints that can be (with the select's labels). */
  joints: { joint: number; label: string }[];
  defaultJoint: number;
  /** The seed of the next Add noise (1 for a new clip, so the first noisy copy of a clip is always the same). */
  noiseSeed: number;
}

const fmt = (v: number, digits: number) => (Number.isFinite(v) ? v.toFixed(digits) : '—');

export class CleanupPanel {
  private readonly card = $('cleanup-card');
  private readonly toggle = $<HTMLButtonElement>('cleanup-toggle');
  private readonly body = $('cleanup-body');
  private readonly method = $<HTMLSelectElement>('cleanup-method');
  private readonly hint = $('cleanup-method-hint');
  private readonly jitter = $<HTMLInputElement>('cleanup-jitter');
  private readonly outliers = $<HTMLInputElement>('cleanup-outliers');
  private readonly drift = $<HTMLInputElement>('cleanup-drift');
  private readonly noiseBtn = $<HTMLButtonElement>('cleanup-add-noise');
  private readonly restoreBtn = $<HTMLButtonElement>('cleanup-restore');
  private readonly goBtn = $<HTMLButtonElement>('cleanup-go');
  private readonly cancelBtn = $<HTMLButtonElement>('cleanup-cancel');
  private readonly progress = $<HTMLProgressElement>('cleanup-progress');
  private readonly status = $('cleanup-status');
  private readonly readout = $('cleanup-readout');
  private readonly jointSelect = $<HTMLSelectElement>('cleanup-joint');
  private readonly exportBtn = $<HTMLButtonElement>('cleanup-export');
  private readonly jitterOut = $('cleanup-jitter-out');
  private readonly outliersOut = $('cleanup-outliers-out');
  private readonly driftOut = $('cleanup-drift-out');
  /** The readout's cells by id (cleanup-input-jerk …). */
  private readonly cells = new Map($all('#cleanup-readout td').map((td) => [td.id, td]));
  private readonly originalLegend = $all('#cleanup-body .legend-original')[0];
  private readonly plot = new AnglePlot($<HTMLCanvasElement>('cleanup-plot'), $('cleanup-playhead'));

  private session: Session | null = null;
  /** The clean-up under way, or null. */
  private running: { abort: AbortController; session: Session; text: string } | null = null;
  private runs = 0;
  /** The joint the user picked (by name), kept for the next clip that has it. */
  private pickedJoint: string | null = null;
  private lastFrame = -1;

  constructor(private readonly host: ModeHost) {
    this.toggle.addEventListener('click', () => this.setExpanded(!this.expanded));
    this.method.addEventListener('change', () => this.showHint());
    for (const slider of [this.jitter, this.outliers, this.drift]) slider.addEventListener('input', () => this.showNoise());
    this.noiseBtn.addEventListener('click', () => this.addNoise());
    this.restoreBtn.addEventListener('click', () => this.restore());
    this.goBtn.addEventListener('click', () => void this.cleanUp());
    this.cancelBtn.addEventListener('click', () => this.cancel());
    this.exportBtn.addEventListener('click', () => this.exportCleaned());
    this.jointSelect.addEventListener('change', () => {
      const s = this.session;
      if (s) this.pickedJoint = s.clip.joints[Number(this.jointSelect.value)] ?? null;
      this.showPlot();
    });
    const plotSize = new ResizeObserver(() => this.plot.draw());
    plotSize.observe($('cleanup-plot'));
    currentScope().signal?.addEventListener('abort', () => plotSize.disconnect());
    this.showHint();
    this.showNoise();
    this.render();
  }

  get expanded(): boolean {
    return !this.body.hidden;
  }

  setExpanded(open: boolean): void {
    this.body.hidden = !open;
    this.toggle.setAttribute('aria-expanded', String(open));
    this.card.classList.toggle('open', open);
    this.render();
  }

  /**
   * Clip mode shows `motion` (an import, the API's show, or the clip restored on coming back to Clip mode). One the
   * panel made (the cleaned motion, the noisy input) keeps the panel's state, and the cleaned one gets its input
   * beside it again; any other is a new clip.
   */
  clipShown(motion: Motion, name: string): void {
    const s = this.session;
    if (s && s.cleaned && motion === s.cleaned.motion) {
      this.cancel();
      this.showCompanion(s, s.cleaned);
      this.render();
      return;
    }
    if (s && s.noisy && motion === s.noisy.motion) {
      this.cancel();
      this.render();
      return;
    }
    this.cancel();
    this.session = this.newSession(motion, name);
    this.render();
  }

  /** Clip mode is left: a clean-up under way is no longer wanted. */
  leave(): void {
    this.cancel();
  }

  /** Every rendered frame: the plot's playhead follows the timeline. */
  frame(s: PlaybackState): void {
    if (s.frame === this.lastFrame || this.body.hidden) return;
    this.lastFrame = s.frame;
    this.plot.setFrame(s.frame);
  }

  private newSession(clip: Motion, name: string): Session {
    const joints = bendJoints(clip.parents).map(({ joint }) => ({ joint, label: clip.joints[joint] }));
    let defaultJoint = joints[0]?.joint ?? -1;
    try {
      const { source } = mapSkeleton(clip, 1);
      for (const [point, what] of Object.entries(POINT_NAMES)) {
        const j = source[CANONICAL_JOINTS.indexOf(point as CanonicalJoint)];
        const entry = joints.find((e) => e.joint === j);
        if (entry) entry.label = `${what} (${clip.joints[j]})`;
      }
      const knee = source[CANONICAL_JOINTS.indexOf('LeftLeg')];
      if (joints.some((e) => e.joint === knee)) defaultJoint = knee;
    } catch {
      // Not mappable: the joints keep their own names; a knee by name, if any, is the default.
      defaultJoint = joints.find((e) => /knee|leg|tibia|femur|shin/i.test(e.label))?.joint ?? defaultJoint;
    }
    return { clip, name, noisy: null, cleaned: null, angles: new Map(), joints, defaultJoint, noiseSeed: 1 };
  }

  private input(s: Session): Motion {
    return s.noisy?.motion ?? s.clip;
  }

  private base(s: Session): string {
    return baseName(s.name) || 'motion';
  }

  private get busy(): boolean {
    return this.running !== null;
  }

  // ---------- noise tool ----------

  private noiseOptions(): { jitter: number; outliers: number; drift: number } {
    const value = (el: HTMLInputElement) => Math.min(Math.max(Number(el.value) || 0, Number(el.min)), Number(el.max));
    return { jitter: value(this.jitter) / 100, outliers: value(this.outliers) / 100, drift: value(this.drift) };
  }

  private showNoise(): void {
    const o = this.noiseOptions();
    this.jitterOut.textContent = `${+(o.jitter * 100).toFixed(1)} cm`;
    this.outliersOut.textContent = `${+(o.outliers * 100).toFixed(1)} %`;
    this.driftOut.textContent = `${o.drift.toFixed(2)} m/s`;
    for (const el of [this.jitter, this.outliers, this.drift]) {
      setSliderFill(el, (Number(el.value) - Number(el.min)) / (Number(el.max) - Number(el.min)));
    }
  }

  /** Add noise: the clean clip with new noise (another seed each time) replaces the shown one. */
  private addNoise(): void {
    const s = this.session;
    if (!s || this.busy) return;
    const o = this.noiseOptions();
    let motion: Motion;
    try {
      motion = addNoise(s.clip, { ...o, seed: s.noiseSeed }).motion;
    } catch (e) {
      this.host.reportError(`Clean up: ${errorMessage(e)}`);
      return;
    }
    const parts = [`jitter ${+(o.jitter * 100).toFixed(1)} cm`, `${+(o.outliers * 100).toFixed(1)} % outlier frames`];
    if (o.drift > 0) parts.push(`foot drift ${o.drift.toFixed(2)} m/s`);
    s.noisy = { motion, label: parts.join(' · ') };
    s.cleaned = null;
    s.inputNumbers = undefined;
    s.angles.clear();
    this.status.dataset.noiseSeed = String(s.noiseSeed++);
    this.host.showInMode(motion, `${this.base(s)}-noisy`);
    this.render();
  }

  /** Restore: the user's clip as it was, without the noise and the clean-up. */
  private restore(): void {
    const s = this.session;
    if (!s || this.busy || (!s.noisy && !s.cleaned)) return;
    if (s.noisy) {
      s.inputNumbers = undefined;
      s.angles.clear();
    }
    s.noisy = null;
    s.cleaned = null;
    this.host.showInMode(s.clip, s.name);
    this.render();
  }

  // ---------- cleaning ----------

  private cancel(): void {
    const run = this.running;
    if (!run) return;
    this.running = null;
    run.abort.abort();
    this.render();
  }

  private async cleanUp(): Promise<void> {
    const s = this.session;
    if (!s || this.busy) return;
    const method = this.method.value as CleanupMethod;
    const input = this.input(s);
    if (method !== 'lowpass') {
      try {
        mapSkeleton(input, 1); // an unmappable skeleton fails here, naming its missing joints, before any model loads
      } catch (e) {
        this.host.reportError(`Clean up: ${errorMessage(e)}`);
        return;
      }
    }
    const run = (this.running = { abort: new AbortController(), session: s, text: 'starting…' });
    this.progress.value = 0;
    this.render();
    try {
      const cleaner = (await this.host.whenModels()).with('cleanup').find((m) => m.descriptor.cleanup!.methods.includes(method));
      if (!cleaner) throw new Error(`no model that cleans up with ${METHOD_NAMES[method]} is listed in models/index.json`);
      const id = cleaner.info.id;
      run.text = `loading the ${cleaner.descriptor.cleanup!.loading}…`;
      this.render();
      await this.host.host(id).load();
      if (run.abort.signal.aborted) return;
      run.text = `cleaning with ${METHOD_NAMES[method]}…`;
      this.render();
      const r = await this.host.withModel(id, (client, descriptor) => descriptor.cleanup!.run(client, { motion: input, options: { method } }, {
        signal: run.abort.signal,
        onProgress: (fraction) => {
          if (this.running !== run) return;
          this.progress.value = fraction;
          this.status.textContent = `cleaning with ${METHOD_NAMES[method]}… ${Math.round(fraction * 100)} %`;
        },
      }));
      if (this.running !== run || this.session !== s) return;
      this.running = null;
      s.cleaned = { motion: { ...r.motion, joints: [...r.motion.joints], parents: [...r.motion.parents] }, method, stats: r.stats, angles: new Map() };
      this.runs++;
      this.display(s, s.cleaned);
    } catch (e) {
      if (this.running !== run) return; // cancelled: whatever cancelled it has set the panel's state
      this.running = null;
      if (isCancelled(e)) {
        this.render();
        return;
      }
      // A worker that failed is started afresh next time (withModel); the worker's "<model> denoise: " prefix is dropped.
      this.host.reportError(`Clean up: ${errorMessage(e).replace(/^\S+ denoise: (denoise: )?/, '')}`);
    }
    this.render();
  }

  private display(s: Session, c: Cleaned): void {
    this.host.showInMode(c.motion, `${this.base(s)}-${c.method}`);
    this.showCompanion(s, c);
  }

  private showCompanion(s: Session, c: Cleaned): void {
    this.host.viewer.setCompanion({
      motion: this.input(s),
      labels: { main: `cleaned · ${METHOD_NAMES[c.method]}`, companion: s.noisy ? 'input · noisy' : 'input' },
    });
  }

  private exportCleaned(): void {
    const s = this.session;
    const c = s?.cleaned;
    if (!s || !c) return;
    try {
      downloadText(`${this.base(s)}-${c.method}.bvh`, exportBVH(c.motion), 'text/plain');
    } catch (e) {
      this.host.reportError(`Export failed: ${errorMessage(e)}`);
    }
  }

  // ---------- what the panel shows ----------

  private showHint(): void {
    this.hint.textContent = METHOD_HINTS[this.method.value as CleanupMethod] ?? '';
  }

  private render(): void {
    const s = this.session;
    const run = this.running;
    const busy = run !== null;
    this.goBtn.disabled = busy || !s;
    this.goBtn.textContent = busy ? 'Working…' : 'Clean up';
    this.cancelBtn.hidden = !busy;
    this.progress.hidden = !busy;
    this.method.disabled = busy;
    for (const el of [this.jitter, this.outliers, this.drift, this.noiseBtn]) el.disabled = busy || !s;
    this.restoreBtn.disabled = busy || !s || (!s.noisy && !s.cleaned);
    this.exportBtn.disabled = busy || !s?.cleaned;
    const state = busy ? 'cleaning' : s?.cleaned ? 'cleaned' : s?.noisy ? 'noisy' : 'clip';
    const d = this.status.dataset;
    d.state = state;
    d.runs = String(this.runs);
    if (s?.cleaned) d.method = s.cleaned.method;
    else delete d.method;
    if (busy) {
      this.status.textContent = run.text;
    } else if (s?.cleaned) {
      const c = s.cleaned;
      const secs = (c.motion.frames - 1) / c.motion.fps;
      const scheme = c.stats.scheme ? ` · ${c.stats.scheme} names` : '';
      const ms = c.stats.computeMs;
      const took = ms < 100 ? `${Math.max(1, Math.round(ms))} ms` : `${(ms / 1000).toFixed(1)} s`;
      this.status.textContent = `${METHOD_NAMES[c.method]}: ${secs.toFixed(1)} s of motion in ${took}${scheme}`;
    } else if (s?.noisy) {
      this.status.textContent = `noisy input: ${s.noisy.label}`;
    } else {
      this.status.textContent = 'cleans the shown clip; Add noise tries it on a clean one';
    }
    if (!this.body.hidden) {
      this.showNumbers();
      this.showJoints();
      this.showPlot();
    }
  }

  private showNumbers(): void {
    const s = this.session;
    const cell = (id: string, v: number | undefined, digits: number, scale = 1) => {
      const el = this.cells.get(id)!;
      el.textContent = v === undefined ? '—' : fmt(v * scale, digits);
    };
    let input: CleanupNumbers | undefined, cleaned: CleanupNumbers | undefined;
    if (s) {
      const original = s.noisy ? s.clip : undefined;
      const reference = original ?? this.input(s);
      s.inputNumbers ??= cleanupNumbers(this.input(s), { reference, ...(original ? { original } : {}) });
      input = s.inputNumbers;
      if (s.cleaned) cleaned = s.cleaned.numbers ??= cleanupNumbers(s.cleaned.motion, { reference, ...(original ? { original } : {}) });
    }
    for (const [row, n] of [['input', input], ['cleaned', cleaned]] as const) {
      cell(`cleanup-${row}-jerk`, n?.jerk, 0);
      cell(`cleanup-${row}-sliding`, n?.sliding, 2);
      cell(`cleanup-${row}-bones`, n?.boneChange, 2, 100);
      cell(`cleanup-${row}-error`, n?.error, 1, 100);
    }
    this.readout.classList.toggle('with-error', !!s?.noisy);
    this.originalLegend.hidden = !s?.noisy;
    const d = this.readout.dataset;
    d.ready = input ? (cleaned ? 'both' : 'input') : '';
  }

  private showJoints(): void {
    const s = this.session;
    const key = s ? s.joints.map((j) => j.joint).join(',') + s.clip.joints.join(',') : '';
    if (this.jointSelect.dataset.key === key) return;
    this.jointSelect.dataset.key = key;
    this.jointSelect.replaceChildren(...(s?.joints ?? []).map(({ joint, label }) => new Option(label, String(joint))));
    if (!s) return;
    const picked = this.pickedJoint === null ? -1 : s.clip.joints.indexOf(this.pickedJoint);
    const joint = s.joints.some((j) => j.joint === picked) ? picked : s.defaultJoint;
    this.jointSelect.value = String(joint);
  }

  private angles(s: Session, which: 'input' | 'original', motion: Motion, joint: number): Float32Array {
    const key = `${which}:${joint}`;
    let a = s.angles.get(key);
    if (!a) s.angles.set(key, (a = bendAngles(motion, joint)));
    return a;
  }

  private showPlot(): void {
    const s = this.session;
    const joint = Number(this.jointSelect.value);
    if (!s || !s.joints.some((j) => j.joint === joint)) {
      this.plot.set(null);
      return;
    }
    const c = s.cleaned;
    let cleaned: Float32Array | undefined;
    if (c && !(cleaned = c.angles.get(joint))) c.angles.set(joint, (cleaned = bendAngles(c.motion, joint)));
    this.plot.set({
      joint: s.clip.joints[joint],
      fps: s.clip.fps,
      input: this.angles(s, 'input', this.input(s), joint),
      ...(cleaned ? { cleaned } : {}),
      ...(s.noisy ? { original: this.angles(s, 'original', s.clip, joint) } : {}),
    });
    this.lastFrame = -1;
  }
}
