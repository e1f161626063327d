// Dance mode: a dance model (the sampled acLSTM, the deterministic one for comparison, or a dropped dance pack) dances endlessly in
// its worker (LiveMode) at the model's 30 fps, shown at the display's rate; the viewer shows the last ~20 s of the fitted skeleton, and a small
// plot shows the pose change per second against real dance (a frozen dance's curve falls to the freeze
// line within seconds: it stops moving).

import { PoseChangeMeter } from '../../motion/poseChange';
import { DanceClient, type DanceInitResult, type DanceMotion } from '../../runtime/aclstm/danceClient';
import type { Registry } from '../../runtime/registry';
import { $ } from '../dom';
import { PoseChangePlot } from '../poseChangePlot';
import { fillSelect, showProvenance } from './modelChoice';
import type { ModeHost } from './host';
import { LiveMode, type LiveStream } from './liveMode';

export class DanceMode extends LiveMode<DanceMotion> {
  private readonly model = $<HTMLSelectElement>('dance-model');
  private readonly style = $<HTMLSelectElement>('dance-style');
  private readonly seed = $<HTMLSelectElement>('dance-seed');
  private readonly plot = new PoseChangePlot($<HTMLCanvasElement>('dance-plot'));
  private meter: PoseChangeMeter | null = null;
  /** Frames measured so far in this dance (the pose-change meter's input). */
  private measured = 0;
  private info: DanceInitResult | null = null;
  private client: { id: string; client: DanceClient } | null = null;
  private seedName = '';

  constructor(app: ModeHost) {
    // 1 s chunks at the models' 30 fps, at least 1.5 s ahead, 20 s kept.
    super(app, $('dance-status'), { chunk: 30, ahead: 45, keep: 600, label: 'Dance', name: 'dance' });
    this.model.addEventListener('change', () => this.restartIfActive());
    this.style.addEventListener('change', () => {
      if (this.info) this.listSeeds(this.info, 0);
      this.restartIfActive();
    });
    this.seed.addEventListener('change', () => this.restartIfActive());
    $('dance-restart').addEventListener('click', () => this.restartIfActive());
  }

  /** Lists the registry's dance models in the model picker. */
  list(registry: Registry): void {
    fillSelect(this.model, registry, registry.ids('dance'));
  }

  /** Picks the dance model a view names (the stream restarts with it once the mode is on). */
  selectModel(id: string): void {
    this.model.value = id;
    showProvenance(this.model);
  }

  private get modelLabel(): string {
    return this.model.selectedOptions[0]?.textContent ?? this.model.value;
  }

  /** The style selector lists the model's styles (kept if they are the same). */
  private listStyles(info: DanceInitResult): void {
    const current = [...this.style.options].map((o) => o.value);
    if (current.join() === info.styles.join()) return;
    const keep = info.styles.includes(this.style.value) ? this.style.value : info.styles[0];
    this.style.replaceChildren(...info.styles.map((s) => new Option(s, s)));
    this.style.value = keep;
  }

  /**
   * The style and seed the next dance starts with (a link, the element's attributes), before the model
   * has listed its own: kept when the model has the style; the seed counts modulo the style's seed motions (a sampled
   * model keeps it: listSeeds).
   */
  preset(style: string | undefined, seed: number | undefined): void {
    if (style !== undefined) this.style.replaceChildren(new Option(style, style));
    if (seed !== undefined) {
      this.seed.replaceChildren(new Option(String(seed), String(seed)));
      this.seed.dataset.style = this.style.value;
    }
    this.restartIfActive();
  }

  /** The style and seed motion shown in the selectors (the seed as the API's `seed`). */
  get choice(): { model: string; style: string; seed: number } {
    return { model: this.model.value, style: this.style.value, seed: Number(this.seed.value) || 0 };
  }

  /**
   * The seed selector lists the seed motions of the selected style; option value = the API's `seed`. A sampled
   * model's seed also seeds its draws (every seed is its own dance), so a larger seed (a link's) is kept as one more
   * option instead of being taken modulo the seed motions.
   */
  private listSeeds(info: DanceInitResult, selected: number): void {
    const names = info.seeds.filter((s) => s.style === this.style.value).map((s) => s.name);
    const options = names.map((name, i) => new Option(name, String(i)));
    const keep = info.sampled && names.length > 0 && selected >= names.length;
    if (keep) options.push(new Option(`${names[selected % names.length]} · seed ${selected}`, String(selected)));
    this.seed.replaceChildren(...options);
    this.seed.value = String(keep ? selected : names.length ? selected % names.length : 0);
    this.seed.dataset.style = this.style.value;
  }

  protected async open(signal: AbortSignal): Promise<LiveStream<DanceMotion>> {
    await this.app.whenModels(); // the picker lists the dance models once they are known
    signal.throwIfAborted();
    const id = this.model.value;
    if (!id) throw new Error('no dance model is listed in models/index.json');
    const { client } = await this.app.host(id).load();
    signal.throwIfAborted();
    if (!(client instanceof DanceClient)) throw new Error(`model "${id}" cannot dance`);
    const info = client.initResult;
    this.client = { id, client };
    this.info = info;
    this.listStyles(info);
    this.listSeeds(info, this.seed.dataset.style === this.style.value ? Number(this.seed.value) || 0 : 0);
    const style = this.style.value;
    const stream = await client.startStream({ style, seed: Number(this.seed.value) || 0 }, { signal });
    this.seedName = stream.seedName;
    this.meter = new PoseChangeMeter(info.joints.length, info.fps);
    this.measured = 0;
    this.plot.reset(info.realPoseChange[style]);
    this.app.setLiveLabel('Dance', `${this.modelLabel} · ${style} · ${info.fps} fps · live`);
    return { skeleton: info, pull: (frames) => client.pull(frames, { signal }) };
  }

  protected forget(): void {
    if (this.client) this.app.host(this.client.id).reset(this.client.client);
  }

  /** Measures the network's own points (as the evaluation does), not the fitted ones. */
  protected received(chunk: DanceMotion): void {
    if (!this.meter || !this.info) return;
    const step = Math.round(this.info.fps);
    const done = Math.floor(Math.max(this.measured - 1, 0) / step);
    const values = this.meter.push(chunk.predicted);
    this.measured += chunk.frames;
    // Second k is complete at stream frame (k + 1) · step.
    this.plot.add(values, values.map((_, i) => (done + i + 1) * step));
  }

  protected describe(frame: number, fps: number): string {
    this.plot.draw(frame);
    return `frame ${frame} · ${(frame / fps).toFixed(1)} s · ${this.seedName}`;
  }
}
