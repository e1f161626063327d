// Which model Steer and Path modes run: the generator with the MAP optimiser (the default), the latent ERD,
// or (Path only) the VAE-LSTM. One choice for both modes, shown by a select in each mode's controls
// (#steer-model and #path-model in index.html): changing either changes both, and it stays as set across
// mode switches. A model one mode cannot run (the VAE-LSTM makes whole paths, it cannot be steered live) is
// missing from that mode's select; while it is chosen, that mode runs the last model it can (`steerable`).

export type ControlModelId = 'generator' | 'latent-erd' | 'vae-lstm';
/** The models that take live control. */
export type SteerModelId = Exclude<ControlModelId, 'vae-lstm'>;

export const CONTROL_MODELS: readonly ControlModelId[] = ['generator', 'latent-erd', 'vae-lstm'];

/** How a mode's title line names the model (lower case, short). */
export const CONTROL_MODEL_SHORT: Record<ControlModelId, string> = {
  generator: 'generator',
  'latent-erd': 'latent ERD',
  'vae-lstm': 'VAE-LSTM',
};

export function isControlModel(value: string): value is ControlModelId {
  return (CONTROL_MODELS as readonly string[]).includes(value);
}

export class ModelChoice {
  private current: ControlModelId = 'generator';
  private lastSteerable: SteerModelId = 'generator';
  private readonly listeners: ((model: ControlModelId) => void)[] = [];

  constructor(private readonly selects: HTMLSelectElement[]) {
    for (const select of selects) {
      select.value = this.current;
      select.addEventListener('change', () => this.set(isControlModel(select.value) ? select.value : 'generator'));
    }
  }

  get value(): ControlModelId {
    return this.current;
  }

  /** The model Steer runs: the choice, or while that is the VAE-LSTM the last steerable one. */
  get steerable(): SteerModelId {
    return this.lastSteerable;
  }

  set(model: ControlModelId): void {
    // A select without this model keeps showing the model its mode runs.
    const shown = model === 'vae-lstm' ? this.lastSteerable : model;
    for (const select of this.selects) select.value = [...select.options].some((o) => o.value === model) ? model : shown;
    if (model === this.current) return;
    this.current = model;
    if (model !== 'vae-lstm') this.lastSteerable = model;
    for (const listener of this.listeners) listener(model);
  }

  /** Called after every change. */
  onChange(listener: (model: ControlModelId) => void): void {
    this.listeners.push(listener);
  }
}
