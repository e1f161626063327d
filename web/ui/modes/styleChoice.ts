// The walking style a mode runs a model with styles in (issue 39: the style generator's cmu, active, elderly, …):
// one choice shown by one or more selects (Random walk has its own; Path and Steer share one, as they share the
// model), each beside its mode's model picker and shown only while that model lists styles in the manifest
// (its entry's `styles`), with that model's styles. The choice is kept across models: a model that lacks it runs
// in its first style (the default), and the choice comes back with a model that has it.

/** One select of a choice: its field (the label hidden with it) and the styles of the model its mode runs now. */
export interface StyleSelect {
  field: HTMLElement;
  select: HTMLSelectElement;
  styles: () => readonly string[];
}

export class StyleChoice {
  /** The style asked for (by the user or a view); undefined: each model's first. */
  private wanted: string | undefined;
  private readonly listeners: ((style: string) => void)[] = [];

  constructor(private readonly selects: readonly StyleSelect[]) {
    for (const s of selects) s.select.addEventListener('change', () => this.set(s.select.value));
  }

  /** The style a model with `styles` runs in: the choice when it has it, else its first; undefined without styles. */
  for(styles: readonly string[] | undefined): string | undefined {
    if (!styles?.length) return undefined;
    return this.wanted !== undefined && styles.includes(this.wanted) ? this.wanted : styles[0];
  }

  /** The style asked for, whatever the model (undefined until one is chosen). */
  get value(): string | undefined {
    return this.wanted;
  }

  /** Lists each select's model's styles again (after a model changed or the models were listed); hides those without. */
  refresh(): void {
    for (const { field, select, styles } of this.selects) {
      const list = styles();
      field.hidden = list.length === 0;
      if ([...select.options].map((o) => o.value).join('\n') !== list.join('\n')) select.replaceChildren(...list.map((s) => new Option(s, s)));
      select.value = this.for(list) ?? '';
    }
  }

  /** Chooses `style` (the user, or a view): the selects show it where their model has it; listeners hear it. */
  set(style: string): void {
    const changed = style !== this.wanted;
    this.wanted = style;
    this.refresh();
    if (changed) for (const listener of this.listeners) listener(style);
  }

  /** Called after every change of the choice. */
  onChange(listener: (style: string) => void): void {
    this.listeners.push(listener);
  }
}
