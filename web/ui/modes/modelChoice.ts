// Which model Steer and Path modes run: one choice for both, shown by a select in each mode's controls
// (#path-model lists the models that follow paths, #steer-model those that take live control; both filled
// from the registry): changing either changes both, and it stays as set across mode switches. A model one
// mode cannot run (the VAE-LSTM makes whole paths, it cannot be steered live) is missing from that mode's
// select; while it is chosen, that mode runs the last model it can (`steerable`).

import type { Registry } from '../../runtime/registry';

export class ModelChoice {
  /** The chosen model ('' until the models are listed). */
  private current = '';
  private lastSteerable = '';
  private steerIds: string[] = [];
  private readonly listeners: ((model: string) => void)[] = [];
  private readonly selects: HTMLSelectElement[];

  constructor(
    private readonly pathSelect: HTMLSelectElement,
    private readonly steerSelect: HTMLSelectElement,
  ) {
    this.selects = [pathSelect, steerSelect];
    for (const select of this.selects) select.addEventListener('change', () => this.set(select.value));
  }

  /** Lists the registry's models in both selects; the choice starts at the default path follower. */
  list(registry: Registry): void {
    fillSelect(this.pathSelect, registry, registry.ids('followPath'));
    this.steerIds = registry.ids('liveControl');
    fillSelect(this.steerSelect, registry, this.steerIds);
    this.lastSteerable = this.steerIds[0] ?? '';
    this.current = '';
    this.set(registry.ids('followPath')[0] ?? this.lastSteerable);
  }

  get value(): string {
    return this.current;
  }

  /** The model Steer runs: the choice, or while that takes no live control the last one that does. */
  get steerable(): string {
    return this.lastSteerable;
  }

  set(model: string): void {
    // A select without this model keeps showing the model its mode runs.
    for (const select of this.selects) {
      select.value = [...select.options].some((o) => o.value === model) ? model : this.lastSteerable;
      showProvenance(select);
    }
    if (model === this.current) return;
    this.current = model;
    if (this.steerIds.includes(model)) this.lastSteerable = model;
    for (const listener of this.listeners) listener(model);
  }

  /** Called after every change. */
  onChange(listener: (model: string) => void): void {
    this.listeners.push(listener);
  }
}

/** Replaces a select's options with models `ids` (labelled by the registry), after its fixed options (value ""). */
export function fillSelect(select: HTMLSelectElement, registry: Registry, ids: readonly string[]): void {
  const fixed = [...select.options].filter((o) => o.value === '');
  const kept = select.value;
  select.replaceChildren(
    ...fixed,
    ...ids.map((id) => {
      const option = new Option(registry.label(id), id);
      option.title = registry.provenance(id);
      return option;
    }),
  );
  if ([...select.options].some((o) => o.value === kept)) select.value = kept;
  showProvenance(select);
  if (!select.dataset.provenance) {
    select.dataset.provenance = 'shown';
    select.addEventListener('change', () => showProvenance(select));
  }
}

/** The picker's own tooltip: the chosen model's (what it was trained on, its licence). Call after setting its value. */
export function showProvenance(select: HTMLSelectElement): void {
  select.title = select.selectedOptions[0]?.title ?? '';
}
