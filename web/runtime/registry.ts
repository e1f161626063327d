// The models the page can run: every entry of public/models/index.json (or any later source of models)
// whose kind has a descriptor (web/runtime/<model>/descriptor.ts). Adding a kind of model means adding its
// folder with a descriptor.ts: the registry finds it, and the API, the pickers and the modes list it by
// what it can do. Entries of kinds without one (the refiner, the autoencoder: parts of other models) are
// listed by `models()` but offered nowhere.

import type { ModelInfo } from '../model/manifest';
import type { Capability, ModelDescriptor } from './descriptor';

/** Every descriptor beside this file, one per model folder (Vite bundles them; vitest runs the same). */
const FOUND = import.meta.glob<{ descriptor: ModelDescriptor }>('./*/descriptor.ts', { eager: true });

/** The descriptors, by kind (a kind described twice is a mistake in the folders). */
export function descriptorsByKind(found: Record<string, { descriptor: ModelDescriptor }> = FOUND): Map<string, ModelDescriptor> {
  const byKind = new Map<string, ModelDescriptor>();
  for (const [file, { descriptor }] of Object.entries(found)) {
    if (byKind.has(descriptor.kind)) throw new Error(`two descriptors of kind "${descriptor.kind}" (${file})`);
    byKind.set(descriptor.kind, descriptor);
  }
  return byKind;
}

let shipped: Map<string, ModelDescriptor> | undefined;

/** The descriptors of the model folders, found once. */
function shippedKinds(): Map<string, ModelDescriptor> {
  return (shipped ??= descriptorsByKind());
}

/** A manifest entry the page can run, with its descriptor. */
export interface RegisteredModel {
  info: ModelInfo;
  descriptor: ModelDescriptor;
}

export class Registry {
  private readonly models: RegisteredModel[];

  /** `entries`: the manifest, in its order (the first model with a capability is that capability's default). */
  constructor(entries: readonly ModelInfo[] = [], kinds: Map<string, ModelDescriptor> = shippedKinds()) {
    this.models = entries.flatMap((info) => {
      const descriptor = kinds.get(info.kind);
      return descriptor ? [{ info, descriptor }] : [];
    });
  }

  /** Adds a model not from the manifest (a user's pack), after the listed ones; false for a kind without a descriptor. */
  add(info: ModelInfo, kinds: Map<string, ModelDescriptor> = shippedKinds()): boolean {
    const descriptor = kinds.get(info.kind);
    if (descriptor) this.models.push({ info, descriptor });
    return descriptor !== undefined;
  }

  /** Every registered model's id. */
  listedIds(): string[] {
    return this.models.map((m) => m.info.id);
  }

  /** The models that can do `capability`, in manifest order. */
  with(capability: Capability): RegisteredModel[] {
    return this.models.filter((m) => m.descriptor.capabilities.includes(capability));
  }

  /** The ids of the models that can do `capability`. */
  ids(capability: Capability): string[] {
    return this.with(capability).map((m) => m.info.id);
  }

  /** The model with this id, or undefined. */
  find(id: string): RegisteredModel | undefined {
    return this.models.find((m) => m.info.id === id);
  }

  /** The default model for `capability`: the first listed that has it, or undefined. */
  defaultFor(capability: Capability): RegisteredModel | undefined {
    return this.with(capability)[0];
  }

  /** Whether model `id` can do `capability`. */
  can(id: string, capability: Capability): boolean {
    return this.find(id)?.descriptor.capabilities.includes(capability) ?? false;
  }

  /**
   * How titles name model `id`: its descriptor's short name; the id itself for a model that is not registered, a
   * user's pack, and a second model of a kind that its descriptor's labels do not name (the style generator beside
   * the generator), so two models of one kind are told apart.
   */
  shortName(id: string): string {
    const m = this.find(id);
    if (!m || m.info.label) return id;
    const unnamed = m.descriptor.labels !== undefined && !Object.hasOwn(m.descriptor.labels, id);
    return unnamed && this.models.some((o) => o !== m && o.descriptor === m.descriptor) ? id : m.descriptor.shortName;
  }

  /** The picker's label of model `id`; a model trained on non-commercial data says so. */
  label(id: string): string {
    const m = this.find(id);
    const label = m?.info.label ?? m?.descriptor.labels?.[id] ?? id;
    return m?.info.commercial === false ? `${label} (non-commercial)` : label;
  }

  /** The picker's tooltip of model `id`: what it was trained on and under what terms ("" when the entry does not say). */
  provenance(id: string): string {
    const info = this.find(id)?.info;
    return [info?.data && `Trained on ${info.data}.`, info?.licence && `Licence: ${info.licence}.`].filter(Boolean).join(' ');
  }
}
