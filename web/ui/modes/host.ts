// What a mode (Random walk, Dance, Steer, Path) gets from the page: the stage it draws on, the models
// it runs, and the page's title line and messages. The page controller (ui/app.ts) implements it; a mode
// never sees the rest of the page (the import, export and mode switching).

import type { Motion } from '../../motion/types';
import type { ModelClientBase, ModelDescriptor } from '../../runtime/descriptor';
import type { Registry } from '../../runtime/registry';
import type { ModelSkeleton } from '../../runtime/worker/workerClient';
import type { Viewer } from '../../viewer/viewer';
import type { ModelHost } from '../modelHost';
import type { ModelChoice } from './modelChoice';
import type { StyleChoice } from './styleChoice';

/**
 * The parts of the viewer a mode uses: the camera rig (camera, orbit controls, framing), the scene for
 * its ground markers, the canvas for pointer input, the playhead, the shown motion and its companion
 * figure, and the layers (a mode may follow the character or stop following it). Showing a motion goes
 * through the host instead, which also keeps the page's export and title in step.
 */
export type ModeViewer = Pick<
  Viewer,
  | 'controls' | 'frameGround' | 'invalidate' | 'groundAt' | 'setRightDragRotates' | 'lookAtGround' | 'lowerView'
  | 'placeBehind' | 'swingBehind' | 'viewHeading'
  | 'scene' | 'renderer' | 'canvas' | 'playback' | 'current' | 'footprintCount' | 'rootPosition' | 'setCompanion'
  | 'layers' | 'setLayers'
>;

export interface ModeHost {
  readonly viewer: ModeViewer;
  /** The models the page runs, by what they can do. */
  readonly registry: Registry;
  /** The registry once the model list has loaded. */
  whenModels(): Promise<Registry>;
  /** Model `id`'s client, loaded on first use and shared with the API. */
  host(id: string): ModelHost<ModelClientBase, ModelSkeleton>;
  /** Runs `use` with model `id`'s client and descriptor; a failed worker is forgotten (the next use starts a new one). */
  withModel<T>(id: string, use: (client: ModelClientBase, descriptor: ModelDescriptor) => Promise<T>): Promise<T>;
  /** Which model Steer and Path modes run (one choice for both). */
  readonly controlModel: ModelChoice;
  /** The walking style Steer and Path modes run a model with styles in (one choice for both). */
  readonly controlStyle: StyleChoice;
  /** The walking styles of model `id` (its manifest entry's `styles`; empty for a model without). */
  stylesOf(id: string): readonly string[];
  /** Shows a live mode's window of streamed frames (`dropped` < 0: a new stream); `name` names exports. */
  showLive(motion: Motion, dropped: number, name: string): void;
  /** Shows a finished motion (Path mode's walk) without leaving the mode; `name` names exports. */
  showInMode(motion: Motion, name: string): void;
  /** An empty stage. */
  clearMotion(): void;
  /** The title line: the mode's name and what it shows. */
  setLiveLabel(name: string, meta: string): void;
  /** An error message for the user (also `playground.lastError()`). */
  reportError(message: string): void;
  /** A passing note for the user (a hint). */
  note(message: string): void;
  /** The panel's layer toggles show the viewer's layers again, after a mode changed them. */
  syncLayers(): void;
}
