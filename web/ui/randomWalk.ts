// Random walk mode: the generator runs endlessly in its worker (LiveMode), the viewer shows the last
// ~20 s with the predicted foot contacts.

import type { GeneratedMotion, GeneratorClient } from '../runtime/generatorClient';
import type { App } from './app';
import { $, LiveMode, type LiveStream } from './liveMode';

const DEFAULT_TEMPERATURE = 0.5;

export class RandomWalk extends LiveMode<GeneratedMotion> {
  private seedName = '';
  private seedsListed = false;
  private client: GeneratorClient | undefined;

  private readonly temperature = $<HTMLInputElement>('walk-temperature');
  private readonly temperatureOut = $('walk-temperature-out');
  private readonly seedState = $<HTMLSelectElement>('walk-seed-state');
  private readonly seed = $<HTMLInputElement>('walk-seed');

  constructor(app: App) {
    // 1 s chunks at 30 fps, at least 1.5 s ahead, 20 s kept.
    super(app, $('walk-status'), { chunk: 30, ahead: 45, keep: 600, label: 'Random walk', name: 'random-walk' });
    this.temperature.value = String(DEFAULT_TEMPERATURE);
    this.showTemperature();
    this.temperature.addEventListener('input', () => this.showTemperature());
    this.temperature.addEventListener('change', () => this.restartIfActive());
    this.seedState.addEventListener('change', () => this.restartIfActive());
    this.seed.addEventListener('change', () => this.restartIfActive());
    $('walk-restart').addEventListener('click', () => this.restartIfActive());
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

  protected async open(): Promise<LiveStream<GeneratedMotion>> {
    const { client, info } = await this.app.generator.load();
    this.client = client;
    if (!this.seedsListed) {
      for (const [i, name] of info.seeds.entries()) this.seedState.add(new Option(name, String(i)));
      this.seedsListed = true;
    }
    const stream = await client.startStream(this.params());
    this.seedName = stream.seedName;
    return { skeleton: info, pull: (frames) => client.pull(frames) };
  }

  protected forget(): void {
    this.app.generator.reset(this.client);
  }

  protected received(): void {}

  protected describe(frame: number, fps: number): string {
    return `frame ${frame} · ${(frame / fps).toFixed(1)} s · ${this.seedName} · τ ${this.params().temperature.toFixed(2)}`;
  }
}
