// Random walk mode: the generator runs endlessly in its worker (LiveMode), the viewer shows the last
// ~20 s with the predicted foot contacts. With **refine** the refiner runs behind it (same worker) and the
// figure shows the refined, foot-locked frames; **side by side** also draws the raw frames of the same
// samples (grey, to the left). A readout shows the foot sliding of what is drawn over the last seconds.

import { lowFootSample } from '../../motion/footSkating';
import type { Motion } from '../../motion/types';
import { GeneratorClient, type GeneratedMotion } from '../../runtime/generator/generatorClient';
import type { InitResult } from '../../runtime/generator/protocol';
import { CompanionAligner } from '../../viewer/sideBySide';
import type { Registry } from '../../runtime/registry';
import { $, changeTo, readSeed } from '../dom';
import { fillSelect } from './modelChoice';
import type { ModeHost } from './host';
import { LiveMode, type LiveStream } from './liveMode';
import { StyleChoice } from './styleChoice';

const DEFAULT_TEMPERATURE = 0.5;
/** Seconds of motion up to the playhead the skating readout averages over. */
export const SKATING_SECONDS = 5;
const LABELS = { main: 'refined + foot lock', companion: 'raw' };
/** The sliding readout's reference for the shipped models (docs/models/refiner.md, held-out CMU walks). */
const CMU_HELD_OUT_SLIDING = 'real held-out walks: 0.26 m/s';

/** A pulled chunk as the window shows it: with refine, positions and contacts are the refined ones and `raw` the generator's. */
type WalkChunk = GeneratedMotion & { raw?: { positions: Float32Array; contacts: Uint8Array; rootHeading: Float32Array } };

/** The raw frames' window behind a refined walk: as generated (for measuring) and as drawn beside it. */
interface RawWindow {
  frames: number;
  positions: Float32Array;
  drawn: Float32Array;
  contacts: Uint8Array;
}

export class RandomWalk extends LiveMode<WalkChunk> {
  private seedName = '';
  private seedsListed = false;
  private client: { id: string; client: GeneratorClient } | undefined;
  /** The running stream refines (fixed per stream, like the other settings). */
  private refining = false;
  private raw: RawWindow | null = null;
  /** The running model's sliding references (InitResult's), for the readout. */
  private slidingReference: Pick<InitResult, 'heldOutSliding' | 'heldOutSlidingByStyle'> | null = null;
  private aligner: CompanionAligner | null = null;
  private walkSkeleton: { fps: number; joints: string[]; parents: number[] } | null = null;

  /** The model that walks (the first listed that can, unless another is chosen). */
  readonly model = $<HTMLSelectElement>('walk-model');
  private readonly temperature = $<HTMLInputElement>('walk-temperature');
  private readonly temperatureOut = $('walk-temperature-out');
  private readonly seedState = $<HTMLSelectElement>('walk-seed-state');
  private readonly seed = $<HTMLInputElement>('walk-seed');
  private readonly refine = $<HTMLInputElement>('walk-refine');
  /** A model with styles walks in this one (shown only for such a model); a change blends the running walk into it. */
  readonly style = new StyleChoice([{ field: $('walk-style-field'), select: $<HTMLSelectElement>('walk-style'), styles: () => this.app.stylesOf(this.model.value) }]);
  /** The running stream's style (a model with styles), for the status line. */
  private streamStyle: string | undefined;
  /** The user's own refine choice, kept while a model without a refiner (a pack) has refine off. */
  private refineWanted = false;
  private readonly sideBySide = $<HTMLInputElement>('walk-side-by-side');
  private readonly skating = $('walk-skating');
  private readonly skatingRaw = $('walk-skating-raw');
  private readonly skatingRefined = $('walk-skating-refined');
  private readonly skatingReference = $('walk-skating-reference');

  constructor(app: ModeHost) {
    // 1 s chunks at 30 fps, at least 1.5 s ahead, 20 s kept.
    super(app, $('walk-status'), { chunk: 30, ahead: 45, keep: 600, label: 'Random walk', name: 'random-walk' });
    this.temperature.value = String(DEFAULT_TEMPERATURE);
    this.showTemperature();
    this.temperature.addEventListener('input', () => this.showTemperature());
    this.temperature.addEventListener('change', () => this.restartIfActive());
    this.seedState.addEventListener('change', () => this.restartIfActive());
    this.model.addEventListener('change', () => {
      // Another model has other seed states.
      this.seedState.replaceChildren(this.seedState.options[0]);
      this.seedsListed = false;
      this.showRefinerAvailability(this.refinerMissing(this.model.value));
      this.style.refresh();
      this.restartIfActive();
    });
    this.style.onChange(() => this.switchStyle());
    this.seed.addEventListener('change', () => this.restartIfActive());
    $('walk-restart').addEventListener('click', () => this.restartIfActive());
    this.refine.addEventListener('change', () => {
      this.refineWanted = this.refine.checked;
      if (!this.refine.checked) {
        this.sideBySide.checked = false;
        this.showCompanion();
      }
      this.restartIfActive();
    });
    this.sideBySide.addEventListener('change', () => {
      // Side by side needs the refined stream; a refined stream already carries the raw frames.
      if (this.sideBySide.checked && !this.refine.checked) {
        this.refine.checked = this.refineWanted = true;
        this.restartIfActive();
      } else {
        this.showCompanion();
        this.updateStatus(true);
      }
    });
  }

  /**
   * The walk's settings, as a view (link, attributes) carries them: the model only when it is not the default walker
   * (links to the default walk stay as they were), the style only for a model with styles.
   */
  get viewSettings(): { model?: string; style?: string; temperature: number; seed: number; refine: boolean } {
    const model = this.model.value;
    const style = this.style.for(this.app.stylesOf(model));
    const listedDefault = this.app.registry.defaultFor('walk')?.info.id;
    return {
      ...(model && model !== listedDefault ? { model } : {}),
      ...(style ? { style } : {}),
      temperature: Number(this.temperature.value),
      seed: Number(this.seed.value) || 0,
      refine: this.refine.checked,
    };
  }

  /**
   * Sets what a view gives (left out: kept), as if the user had: the stream restarts with them, except a style, which
   * the running walk blends into. `model` and `style` are checked by the caller (element.ts) against the registry.
   */
  preset(view: { model?: string; style?: string; temperature?: number; seed?: number; refine?: boolean }): void {
    if (view.temperature !== undefined) changeTo(this.temperature, String(view.temperature));
    if (view.seed !== undefined) changeTo(this.seed, String(view.seed));
    if (view.refine !== undefined) changeTo(this.refine, view.refine);
    // After refine: a model without a refiner then turns refine off (the wish is kept for a model with one).
    if (view.model !== undefined && view.model !== this.model.value) changeTo(this.model, view.model);
    if (view.style !== undefined) this.style.set(view.style);
    this.showRefinerAvailability(this.refinerMissing(this.model.value));
  }

  /**
   * Why model `id` has no refiner behind it, or '' when it has one: a user's pack (its files are its own), or a model
   * with styles (the refiner learnt from the CMU-only generator's output; none is trained for it yet).
   */
  private refinerMissing(id: string): string {
    const info = this.app.registry.find(id)?.info;
    if (info?.files !== undefined) return 'Your model has no refiner';
    if (info?.styles?.length) return 'No refiner is trained for this model yet: it walks raw';
    return '';
  }

  /**
   * The readout's reference: the CMU held-out walks for the shipped models, a style generator's held-out walks of the
   * running style, a pack's own held-out clips (its card).
   */
  private showSlidingReference(): void {
    const info = this.slidingReference;
    if (!info) return;
    const styled = this.streamStyle ? info.heldOutSlidingByStyle?.[this.streamStyle] : undefined;
    this.skatingReference.textContent =
      info.heldOutSliding !== undefined ? `your held-out clips: ${info.heldOutSliding.toFixed(2)} m/s`
      : styled !== undefined ? `real held-out ${this.streamStyle} walks: ${styled.toFixed(2)} m/s`
      : CMU_HELD_OUT_SLIDING;
  }

  /** A new style for the running walk: its stream blends into it over about a second from its next frame. */
  private switchStyle(): void {
    const running = this.client;
    if (!this.running || !running || running.id !== this.model.value) return; // the next walk starts in it
    const style = this.style.for(this.app.stylesOf(running.id));
    if (!style || style === this.streamStyle) return;
    this.streamStyle = style;
    this.showSlidingReference();
    running.client.switchStyle(style).catch((e: unknown) => this.app.reportError(`Random walk: ${e instanceof Error ? e.message : String(e)}`));
    this.updateStatus(true);
  }

  private showTemperature(): void {
    this.temperatureOut.textContent = Number(this.temperature.value).toFixed(2);
  }

  private params(model: string): { seed: number; temperature: number; seedIndex?: number; refine: boolean; style?: string } {
    const seed = readSeed(this.seed);
    const temperature = Math.min(Math.max(Number(this.temperature.value) || 0, 0), 2);
    const idx = this.seedState.value === '' ? undefined : Number(this.seedState.value);
    const style = this.style.for(this.app.stylesOf(model));
    return { seed, temperature, ...(idx === undefined ? {} : { seedIndex: idx }), refine: this.refine.checked && !this.refinerMissing(model), ...(style ? { style } : {}) };
  }

  /**
   * A model without a refiner trained for it (a user's pack, a model with styles; `why`): refine and side by side are
   * off and disabled while it is chosen, and the user's own refine choice comes back with a model that has one.
   */
  private showRefinerAvailability(why: string): void {
    const noRefiner = why !== '';
    this.refine.disabled = this.sideBySide.disabled = noRefiner;
    this.refine.title = this.sideBySide.title = why;
    const refine = this.refineWanted && !noRefiner;
    if (this.refine.checked === refine) return;
    this.refine.checked = refine;
    if (!refine) this.sideBySide.checked = false;
    this.showCompanion();
  }

  /** Lists the registry's walking models in the model picker. */
  list(registry: Registry): void {
    fillSelect(this.model, registry, registry.ids('walk'));
    this.style.refresh();
  }

  protected async open(signal: AbortSignal): Promise<LiveStream<WalkChunk>> {
    // The first listed model that walks (the generator: a stream with the refiner behind it on request).
    const registry = await this.app.whenModels();
    signal.throwIfAborted();
    const walker = (this.model.value && registry.can(this.model.value, 'walk') ? registry.find(this.model.value) : undefined) ?? registry.defaultFor('walk');
    if (!walker) throw new Error('no model for Random walk is listed in models/index.json');
    const id = walker.info.id;
    this.showRefinerAvailability(this.refinerMissing(id));
    const { client } = await this.app.host(id).load();
    signal.throwIfAborted();
    if (!(client instanceof GeneratorClient)) throw new Error(`model "${id}" cannot stream a random walk`);
    const info = client.initResult;
    this.client = { id, client };
    if (!this.seedsListed) {
      for (const [i, name] of info.seeds.entries()) this.seedState.add(new Option(name, String(i)));
      this.seedsListed = true;
    }
    const params = this.params(id);
    const stream = await client.startStream(params, { signal });
    this.seedName = stream.seedName;
    this.streamStyle = stream.style;
    this.refining = params.refine;
    this.walkSkeleton = info;
    this.raw = null;
    this.aligner = params.refine ? new CompanionAligner(info.joints.length, info.fps) : null;
    const name = registry.shortName(id);
    this.slidingReference = info;
    this.showSlidingReference();
    this.app.setLiveLabel('Random walk', params.refine ? `${name} + refiner · 30 fps · live` : `${name} · 30 fps · live`);
    const pull = async (frames: number): Promise<WalkChunk> => {
      const m = await client.pull(frames, { signal });
      if (!params.refine) return m;
      if (!m.refined) throw new Error('the generator worker sent no refined frames');
      return { ...m, positions: m.refined.positions, contacts: m.refined.contacts, raw: { positions: m.positions, contacts: m.contacts, rootHeading: m.rootHeading } };
    };
    return { skeleton: info, pull };
  }

  protected forget(): void {
    if (this.client) this.app.host(this.client.id).reset(this.client.client);
  }

  /** Keeps the raw window in step with the shown (refined) one and draws it beside it when asked. */
  protected received(chunk: WalkChunk, first: boolean): void {
    // The walk follows the selector: a style chosen while a walk was (re)starting with another is blended in here,
    // at its next chunk (switchStyle does nothing when they already agree).
    this.switchStyle();
    if (!this.refining || !chunk.raw || !chunk.refined || !this.aligner || !this.walkSkeleton) return;
    const shown = this.app.viewer.current;
    if (!shown) return;
    if (first) {
      this.raw = null;
      this.aligner.reset();
    }
    const stride = this.walkSkeleton.joints.length * 3;
    const before = this.raw?.frames ?? 0;
    // The window dropped as many frames from its start as it now lacks to hold the old frames plus the chunk.
    const drop = Math.max(0, Math.min(before, before + chunk.frames - shown.frames));
    const kept = before - drop;
    const drawn = this.aligner.align(chunk.raw.positions, chunk.raw.rootHeading, chunk.refined.positions, chunk.refined.rootHeading);
    const grow = (old: Float32Array | Uint8Array | undefined, add: Float32Array | Uint8Array, width: number) => {
      const out = add instanceof Float32Array ? new Float32Array((kept + chunk.frames) * width) : new Uint8Array((kept + chunk.frames) * width);
      if (old) out.set(old.subarray(drop * width, before * width));
      out.set(add, kept * width);
      return out;
    };
    this.raw = {
      frames: kept + chunk.frames,
      positions: grow(this.raw?.positions, chunk.raw.positions, stride) as Float32Array,
      drawn: grow(this.raw?.drawn, drawn, stride) as Float32Array,
      contacts: grow(this.raw?.contacts, chunk.raw.contacts, 2) as Uint8Array,
    };
    this.showCompanion();
  }

  /** Draws the raw window beside the refined figure while side by side is on. */
  private showCompanion(): void {
    const shown = this.app.viewer.current;
    const raw = this.raw;
    if (!this.running || !this.sideBySide.checked || !raw || !shown || !this.walkSkeleton || raw.frames !== shown.frames) {
      this.app.viewer.setCompanion(null);
      return;
    }
    this.app.viewer.setCompanion({ motion: this.motionOf(raw.drawn, raw.frames), labels: LABELS });
  }

  private motionOf(positions: Float32Array, frames: number, contacts?: Uint8Array): Motion {
    const sk = this.walkSkeleton!;
    return { fps: sk.fps, frames, joints: sk.joints, parents: sk.parents, positions, ...(contacts ? { contacts } : {}) };
  }

  /**
   * Foot sliding (m/s) over the last SKATING_SECONDS up to the playhead: the lowest foot point's speed while within
   * 4 cm of the floor (footSkating.ts lowFootSample), which needs no contact labels, so raw and refined motion are
   * measured alike; NaN when no foot came near the floor.
   */
  private skatingOf(motion: Motion | null, playhead: number): number {
    if (!motion) return NaN;
    const to = Math.min(playhead + 1, motion.frames);
    const { sum, count } = lowFootSample(motion, to - Math.round(SKATING_SECONDS * motion.fps), to);
    return count ? sum / count : NaN;
  }

  /** The skating readout: what is drawn (raw, refined, or both side by side). */
  private showSkating(): void {
    const playhead = this.app.viewer.playback.frame;
    const shown = this.app.viewer.current;
    const both = this.refining && this.sideBySide.checked && this.raw !== null && this.raw.frames === shown?.frames;
    const main = this.skatingOf(shown, playhead);
    const raw = !this.refining ? main : both ? this.skatingOf(this.motionOf(this.raw!.positions, this.raw!.frames, this.raw!.contacts), playhead) : NaN;
    const refined = this.refining ? main : NaN;
    const text = (v: number) => (Number.isFinite(v) ? v.toFixed(2) : '—');
    this.skatingRaw.textContent = text(raw);
    this.skatingRefined.textContent = text(refined);
    (this.skatingRaw.closest('.skate-line') as HTMLElement).hidden = this.refining && !both;
    (this.skatingRefined.closest('.skate-line') as HTMLElement).hidden = !this.refining;
    this.skating.dataset.raw = Number.isFinite(raw) ? raw.toFixed(4) : '';
    this.skating.dataset.refined = Number.isFinite(refined) ? refined.toFixed(4) : '';
    this.skating.dataset.shown = both ? 'both' : this.refining ? 'refined' : 'raw';
  }

  protected describe(frame: number, fps: number): string {
    this.showSkating();
    const refined = this.refining ? ` · refined${this.sideBySide.checked ? ', side by side' : ''}` : '';
    const style = this.streamStyle ? ` · style ${this.streamStyle}` : '';
    return `frame ${frame} · ${(frame / fps).toFixed(1)} s · ${this.seedName}${style} · τ ${Number(this.temperature.value).toFixed(2)}${refined}`;
  }
}
