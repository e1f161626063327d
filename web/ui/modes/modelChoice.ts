// Which model Steer and Path modes run: the generator with the MAP optimiser (the default) or the latent
// ERD. One choice for both modes, shown by a select in each mode's controls (#steer-model and #path-model,
// options "generator" and "latent-erd" in index.html): changing either changes both, and it stays as set
// across mode switches.

export type ControlModelId = 'generator' | 'latent-erd';

/** How a mode's title line names the model (lower case, short). */
export const CONTROL_MODEL_SHORT: Record<ControlModelId, string> = {
  generator: 'generator',
  'latent-erd': 'latent ERD',
};

export class ModelChoice {
  private current: ControlModelId = 'generator';
  private readonly listeners: ((model: ControlModelId) => void)[] = [];

  constructor(private readonly selects: HTMLSelectElement[]) {
    for (const select of selects) {
      select.value = this.current;
      select.addEventListener('change', () => this.set(select.value === 'latent-erd' ? 'latent-erd' : 'generator'));
    }
  }

  get value(): ControlModelId {
    return this.current;
  }

  set(model: ControlModelId): void {
    for (const select of this.selects) select.value = model;
    if (model === this.current) return;
    this.current = model;
    for (const listener of this.listeners) listener(model);
  }

  /** Called after every change. */
  onChange(listener: (model: ControlModelId) => void): void {
    this.listeners.push(listener);
  }
}
