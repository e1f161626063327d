// Page controller: owns the viewer, the panel and the messages; imports dropped/picked files and
// exports the shown motion. One per <motion-playground> element (web/api/element.ts), built inside its
// shadow root; the automation API (web/api/playground.ts) drives the same methods.

import { detectContacts } from '../motion/contacts';
import { exportBVH } from '../motion/bvh';
import { exportGLB } from '../motion/gltf';
import type { RestPose } from '../motion/restPose';
import { capMessage } from '../motion/text';
import type { Motion } from '../motion/types';
import type { PlaybackState } from '../viewer/playback';
import { Viewer, type FreeArea } from '../viewer/viewer';
import type { ModelInfo } from '../model/manifest';
import type { ModelClientBase, ModelDescriptor } from '../runtime/descriptor';
import { Registry } from '../runtime/registry';
import type { ModelSkeleton } from '../runtime/worker/workerClient';
import { ImportClient } from '../runtime/import/importClient';
import { baseName, type FileImportOutcome } from '../runtime/import/motionFiles';
import { ImportIndicator } from './files';
import { $, downloadBlob, errorMessage, type DomScope } from './dom';
import { Capture } from './capture';
import { ExportMenu } from './exportMenu';
import { BusyIndicator, ModelHost, pageThreads, withClient } from './modelHost';
import { CleanupPanel } from './cleanupPanel';
import { CHARACTER_FILE, CharacterInput } from './characterInput';
import { droppedFolderFiles, loadPack, showCard, type PackSource } from './packInput';
import { looksLikePack } from '../runtime/packs/pack';
import { DanceMode } from './modes/danceMode';
import type { ModeHost } from './modes/host';
import type { LiveChunk, LiveMode } from './modes/liveMode';
import { ModelChoice } from './modes/modelChoice';
import { StyleChoice } from './modes/styleChoice';
import { PathMode } from './modes/pathMode';
import { RandomWalk } from './modes/randomWalk';
import { SteerMode } from './modes/steerMode';
import { Panel } from './panel';
import { Toasts } from './toast';

import { MODES, modeModels, type Mode } from './viewState';
export type { Mode };

/** What the page tells its element (which turns them into DOM events). */
export interface AppEvents {
  /** A new motion is shown: a clip, a path walk, or a new live stream. */
  motion(name: string): void;
  /** An error message was shown. */
  error(reason: string): void;
}

export class App implements ModeHost {
  readonly viewer: Viewer;
  readonly panel: Panel;
  readonly toasts: Toasts;
  /** The user's own character, drawn instead of the mannequin once loaded (characterInput.ts). */
  readonly characters: CharacterInput;
  private readonly busy = new BusyIndicator($('model-status'));
  /** The models the page runs (empty until the manifest is loaded: `useModels`). */
  private models = new Registry();
  private modelsArrived!: (registry: Registry) => void;
  private readonly modelsReady = new Promise<Registry>((resolve) => (this.modelsArrived = resolve));
  /** Each model's client, loaded on first use and shared by the API and the modes. */
  private readonly hosts = new Map<string, ModelHost<ModelClientBase, ModelSkeleton>>();
  /** Parses imports off the page thread (dropped and picked files, playground.importMotion). */
  readonly importer = new ImportClient();
  private readonly importIndicator = new ImportIndicator();
  private name = '';
  private lastErrorMessage: string | null = null;
  private readonly exportBtn = $<HTMLButtonElement>('export-btn');
  private readonly exportGlbBtn = $<HTMLButtonElement>('export-glb-btn');
  private readonly restPoseSelect = $<HTMLSelectElement>('rest-pose');
  /** The Export menu's "on my character" switch, shown once a character is loaded. */
  private readonly onCharacter = { row: $('export-on-character-row'), box: $<HTMLInputElement>('export-on-character'), name: $('export-on-character-name') };
  /** Snapshot and Record. */
  readonly capture: Capture;
  /** The header's Export menu (exports, snapshot, record). */
  readonly exportMenu: ExportMenu;
  private readonly clipName = $('clip-name');
  private readonly clipMeta = $('clip-meta');
  private readonly modeButtons = new Map(MODES.map((m) => [m, $(`mode-${m}`)]));
  private readonly dropOverlay = $('drop-overlay');
  /** The model Steer and Path modes run (one choice for both, kept across mode switches). */
  readonly controlModel = new ModelChoice($<HTMLSelectElement>('path-model'), $<HTMLSelectElement>('steer-model'));
  /** The walking style Steer and Path modes run a model with styles in (one choice for both, beside the model). */
  readonly controlStyle = new StyleChoice([
    { field: $('path-style-field'), select: $<HTMLSelectElement>('path-style'), styles: () => this.stylesOf(this.controlModel.value) },
    { field: $('steer-style-field'), select: $<HTMLSelectElement>('steer-style'), styles: () => this.stylesOf(this.controlModel.steerable) },
  ]);
  readonly walk: RandomWalk;
  readonly danceMode: DanceMode;
  readonly pathMode: PathMode;
  readonly steerMode: SteerMode;
  /** Clip mode's Clean up panel. */
  readonly cleanup: CleanupPanel;
  /** Called every rendered frame with the playback state (the element's play and pause events). */
  readonly frameListeners: ((s: PlaybackState) => void)[] = [];
  /** The cards of the user's packs loaded so far, by model id. */
  private readonly packCards = new Map<string, { text: string; thumbnail?: string }>();
  /** Origins besides the page's own that URLs of packs may come from (the element's allowed-origins). */
  allowedOrigins: () => readonly string[] = () => [];
  private mode: Mode = 'clip';
  /** The clip shown before another mode (Random walk, Dance, Path, Steer), restored when switching back. */
  private clip: { motion: Motion; name: string } | null = null;
  /** Taken down for good (dispose): nothing starts again. */
  private disposed = false;

  /** Build it inside `buildIn(scope, …)` (dom.ts): its parts look up their elements in `scope` as they are made. */
  constructor(
    private readonly scope: DomScope,
    private readonly events: AppEvents,
  ) {
    this.viewer = new Viewer($('stage'));
    this.viewer.setFreeAreaSource(freeAreaOf($('stage'), scope.root));
    this.panel = new Panel(this.viewer);
    this.toasts = new Toasts($('toasts'));
    this.characters = new CharacterInput(this.viewer);
    this.viewer.onFrame = (s) => {
      this.panel.update(s);
      if (this.mode === 'clip') this.cleanup?.frame(s);
      for (const listener of this.frameListeners) listener(s);
    };

    const input = $<HTMLInputElement>('file-input');
    for (const id of ['open-btn', 'empty-open']) $(id).addEventListener('click', () => input.click());
    input.addEventListener('change', () => {
      const files = [...(input.files ?? [])];
      input.value = '';
      if (files.length) void this.handleFiles(files);
    });
    this.exportBtn.addEventListener('click', () => this.exportCurrent('bvh'));
    this.exportGlbBtn.addEventListener('click', () => this.exportCurrent('glb'));
    this.capture = new Capture(this);
    this.exportMenu = new ExportMenu();
    this.installDropZone();

    this.walk = new RandomWalk(this);
    this.danceMode = new DanceMode(this);
    this.pathMode = new PathMode(this);
    this.steerMode = new SteerMode(this);
    this.controlModel.onChange(() => this.controlStyle.refresh());
    this.cleanup = new CleanupPanel(this);
    for (const m of MODES) {
      this.modeButtons.get(m)!.addEventListener('click', () => this.setMode(m));
      const live = this.liveMode(m);
      if (live) live.onFailed = () => this.setMode('clip');
    }
  }

  get currentMode(): Mode {
    return this.mode;
  }

  /** The models the page runs, as listed so far. */
  get registry(): Registry {
    return this.models;
  }

  /** The models, once the manifest is loaded (or has failed to: then none). */
  whenModels(): Promise<Registry> {
    return this.modelsReady;
  }

  /** The manifest's models (public/models/index.json): the pickers list them by what they can do. */
  useModels(models: readonly ModelInfo[]): void {
    this.models = new Registry(models);
    this.controlModel.list(this.models);
    this.walk.list(this.models);
    this.danceMode.list(this.models);
    this.pathMode.list(this.models);
    this.controlStyle.refresh();
    this.modelsArrived(this.models);
  }

  /** The walking styles of model `id` (its manifest entry's `styles`; none for a model without, or not listed). */
  stylesOf(id: string): readonly string[] {
    return this.models.find(id)?.info.styles ?? [];
  }

  /**
   * Loads a user's model pack (ui/packInput.ts) once the manifest is in, lists it in the pickers and resolves to its
   * model id; a refused pack rejects with a short message and changes nothing.
   */
  async loadModels(source: PackSource): Promise<string> {
    await this.modelsReady;
    return loadPack(source, {
      registryIds: () => this.models.listedIds(),
      addModel: (info, card) => this.addModel(info, card),
      pageHref: () => location.href,
      allowedOrigins: () => this.allowedOrigins(),
    });
  }

  /** The users' packs loaded so far, as manifest entries (after the manifest's own). */
  packModels(): ModelInfo[] {
    return [...this.packCards.keys()].flatMap((id) => this.models.find(id)?.info ?? []);
  }

  private addModel(info: ModelInfo, card: { text: string; thumbnail?: string }): void {
    this.models.add(info);
    this.packCards.set(info.id, card);
    const chosen = this.controlModel.value;
    this.controlModel.list(this.models);
    this.controlModel.set(chosen);
    this.walk.list(this.models);
    this.danceMode.list(this.models);
    this.pathMode.list(this.models);
    this.controlStyle.refresh();
    for (const id of ['walk-model', 'dance-model', 'path-model', 'steer-model']) this.cardButton(this.scope.root.getElementById(id) as HTMLSelectElement);
  }

  /** What to tell the user once pack `id` is loaded: where to find it. */
  packLoadedNote(id: string): string {
    const modes = modeModels(this.models);
    const where = [
      ['Random walk', modes.walk],
      ['Dance', modes.dance],
      ['Path', modes.path],
      ['Steer', modes.steer],
    ].flatMap(([name, ids]) => ((ids as string[]).includes(id) ? [name as string] : []));
    const list = where.length > 1 ? `${where.slice(0, -1).join(', ')} or ${where[where.length - 1]}` : where[0] ?? 'the model pickers';
    return `Your model ${id} is loaded: choose it in ${list}.`;
  }

  /** A "card" button beside a picker, shown while it has a pack chosen: opens the pack's card. */
  private cardButton(select: HTMLSelectElement): void {
    if (select.nextElementSibling?.classList.contains('pack-card-btn')) return;
    const button = document.createElement('button');
    button.type = 'button';
    button.className = 'pack-card-btn';
    button.textContent = 'card';
    button.title = "Your model's card: its data, training and measured numbers";
    const show = () => (button.hidden = !this.packCards.has(select.value));
    select.addEventListener('change', show);
    this.controlModel.onChange(show);
    button.addEventListener('click', () => {
      const card = this.packCards.get(select.value);
      if (card) showCard(this.scope.root, this.scope.frame, select.value, card);
    });
    select.after(button);
    show();
  }

  /** Which models each mode shows (links and attributes are checked against it). */
  modeModels(): ReturnType<typeof modeModels> {
    return modeModels(this.models);
  }

  /** Model `id`'s client, loaded on first use (a listed model; else it throws). */
  host(id: string): ModelHost<ModelClientBase, ModelSkeleton> {
    let host = this.hosts.get(id);
    if (!host) {
      const model = this.models.find(id);
      if (!model) throw new Error(`model "${id}" is not listed in models/index.json`);
      host = new ModelHost(() => model.descriptor.createClient(model.info, pageThreads()), this.busy);
      this.hosts.set(id, host);
      if (this.disposed) host.dispose(); // taken down: its loads reject, no worker starts
    }
    return host;
  }

  /**
   * Runs `use` with model `id`'s client (loaded on first use) and descriptor. A worker that failed (not a
   * request it refused) is forgotten, so the next call starts a new one.
   */
  withModel<T>(id: string, use: (client: ModelClientBase, descriptor: ModelDescriptor) => Promise<T>): Promise<T> {
    const host = this.host(id);
    return withClient(host, (client) => use(client, this.models.find(id)!.descriptor));
  }

  /**
   * Off the page (its element removed): the frame loop stops and a live stream ends, so a removed element costs
   * nothing. `resume` starts both again (a live mode restarts its stream from its settings).
   */
  suspend(): void {
    this.viewer.setRunning(false);
    this.liveMode(this.mode)?.stop();
  }

  resume(): void {
    if (this.disposed) return;
    this.viewer.setRunning(true);
    void this.liveMode(this.mode)?.begin();
  }

  /**
   * Taken down for good (its element was removed from the page, web/api/element.ts): the live stream ends, a path
   * optimisation or clean-up under way is aborted, every model's worker and the import worker are stopped and the
   * viewer lets go of its WebGL context, frame loop and observers. Listeners on window and document go with the
   * scope's signal, which the element aborts. Nothing of it starts again: the element builds a new App.
   */
  dispose(): void {
    if (this.disposed) return;
    this.disposed = true;
    for (const m of MODES) this.liveMode(m)?.stop();
    if (this.mode === 'path') this.pathMode.leave();
    if (this.mode === 'clip') this.cleanup.leave();
    for (const host of this.hosts.values()) host.dispose();
    this.importer.dispose();
    this.viewer.dispose();
  }

  get isDisposed(): boolean {
    return this.disposed;
  }

  private liveMode(mode: Mode): LiveMode<LiveChunk> | null {
    return mode === 'walk' ? this.walk : mode === 'dance' ? this.danceMode : mode === 'steer' ? this.steerMode : null;
  }

  /**
   * Clip mode shows the imported clip; Random walk, Dance and Steer modes stream from their models
   * (loaded on first use); Path mode shows walks along drawn paths. Leaving any of them for Clip
   * restores the clip shown before.
   */
  setMode(mode: Mode): void {
    if (mode === this.mode || this.disposed) return;
    const previous = this.mode;
    this.mode = mode;
    for (const m of MODES) this.modeButtons.get(m)!.setAttribute('aria-pressed', String(mode === m));
    for (const m of MODES) this.scope.frame.classList.toggle(`${m}-mode`, mode === m);
    this.liveMode(previous)?.stop();
    if (previous === 'clip') this.cleanup.leave();
    if (previous === 'path') this.pathMode.leave();
    if (mode === 'clip') {
      this.exportBtn.title = 'Download the shown motion as BVH';
      const clip = this.clip;
      this.clip = null;
      if (clip) this.show(clip.motion, clip.name);
      else this.clearMotion();
      return;
    }
    if (previous === 'clip') {
      const m = this.viewer.current;
      this.clip = m ? { motion: m, name: this.name } : null;
    }
    if (mode === 'path') {
      this.exportBtn.title = 'Download the walk along the path as BVH';
      this.pathMode.enter();
      return;
    }
    if (mode === 'walk') {
      const walker = this.models.defaultFor('walk');
      this.setLiveLabel('Random walk', walker ? `${walker.descriptor.shortName} · 30 fps · live` : 'loading…');
      this.exportBtn.title = 'Download the last 20 s of the walk as BVH';
    } else if (mode === 'steer') {
      const steered = this.controlModel.steerable;
      this.setLiveLabel('Steer', steered ? `${this.models.shortName(steered)} · 30 fps · live control` : 'loading…');
      this.exportBtn.title = 'Download the last 20 s of steering as BVH';
    } else {
      this.setLiveLabel('Dance', 'loading…');
      this.exportBtn.title = 'Download the last 20 s of the dance as BVH';
    }
    void this.liveMode(mode)!.begin();
  }

  /** The title line in a live mode. */
  setLiveLabel(name: string, meta: string): void {
    this.clipName.textContent = name;
    this.clipMeta.textContent = ` ${meta}`;
  }

  /** A live mode: shows the current window of streamed frames (`dropped` < 0: a new stream); `name` names exports. */
  showLive(motion: Motion, dropped: number, name: string): void {
    this.viewer.setLive(motion, motion.contacts, dropped);
    this.name = name;
    this.exportBtn.disabled = this.exportGlbBtn.disabled = false;
    this.scope.frame.classList.add('has-motion');
    if (dropped < 0) this.events.motion(name);
  }

  syncLayers(): void {
    this.panel.syncLayers();
  }

  /** An empty stage ("No motion"). */
  clearMotion(): void {
    this.viewer.clear();
    this.name = '';
    this.exportBtn.disabled = this.exportGlbBtn.disabled = true;
    this.scope.frame.classList.remove('has-motion');
    this.clipName.textContent = 'No motion';
    this.clipMeta.textContent = '';
  }

  get current(): Motion | null {
    return this.viewer.current;
  }

  get lastError(): string | null {
    return this.lastErrorMessage;
  }

  /** Shows an error to the user and remembers it for `playground.lastError()`, cut to MAX_MESSAGE characters. */
  reportError(text: string): void {
    const message = capMessage(text);
    this.lastErrorMessage = message;
    this.toasts.show(message, 'error');
    this.events.error(message);
  }

  note(message: string): void {
    this.toasts.show(message, 'info');
  }

  /** Shows an already validated motion in Clip mode. Contacts are detected when the motion has none. */
  show(motion: Motion, name = 'motion'): void {
    if (this.mode !== 'clip') {
      // Showing a clip ends the other mode; the new clip replaces the one remembered from before it.
      this.clip = null;
      this.setMode('clip');
    }
    this.showInMode(motion, name);
    this.cleanup.clipShown(motion, name);
  }

  /** Shows a motion like `show` but stays in the current mode (Path mode's results); `name` names exports. */
  showInMode(motion: Motion, name: string): void {
    let contacts = motion.contacts;
    if (!contacts) {
      try {
        contacts = detectContacts(motion);
      } catch {
        contacts = undefined; // footprints are decoration: a motion without feet just has none
      }
    }
    this.viewer.setMotion(motion, contacts);
    this.name = name;
    this.exportBtn.disabled = this.exportGlbBtn.disabled = false;
    this.scope.frame.classList.add('has-motion');
    const secs = (motion.frames - 1) / motion.fps;
    this.clipName.textContent = name;
    this.clipMeta.textContent =
      `${motion.joints.length} joints · ${motion.frames} frames · ${+motion.fps.toFixed(2)} fps · ${secs.toFixed(1)} s` +
      (this.viewer.footprintCount ? ` · ${this.viewer.footprintCount} steps` : '');
    this.events.motion(name);
  }

  /** The base of download names: the shown motion's name without its extension ("motion" when it has none). */
  exportName(): string {
    return baseName(this.name) || 'motion';
  }

  /**
   * Downloads the shown motion as BVH or GLB with the footer's rest pose. A T-pose the skeleton cannot be
   * given (legs or arms that cannot be named) falls back to the clip's own rest pose, with a note saying so.
   */
  exportCurrent(format: 'bvh' | 'glb'): void {
    const m = this.current;
    if (!m) return;
    if (this.characters.current && this.onCharacter.box.checked) return void this.exportOnCharacter(m, format);
    const write = (restPose: RestPose) =>
      format === 'bvh'
        ? new Blob([exportBVH(m, { restPose })], { type: 'text/plain' })
        : new Blob([exportGLB(m, { restPose, name: this.exportName() })], { type: 'model/gltf-binary' });
    const chosen = this.restPoseSelect.value as RestPose;
    try {
      let blob: Blob;
      try {
        blob = write(chosen);
      } catch (e) {
        if (chosen !== 'tpose' || !/T-pose/.test(errorMessage(e))) throw e;
        blob = write('clip');
        this.note(`${errorMessage(e)}; exported with the clip's own rest pose instead`);
      }
      downloadBlob(`${this.exportName()}.${format}`, blob);
    } catch (e) {
      this.reportError(`Export failed: ${errorMessage(e)}`);
    }
  }

  /** Downloads `m` on the user's character: its skeleton (BVH) or its mesh, skin and materials animated (GLB). */
  private async exportOnCharacter(m: Motion, format: 'bvh' | 'glb'): Promise<void> {
    const name = `${this.exportName()}-${this.characters.current!.name}`;
    try {
      const blob = format === 'bvh'
        ? new Blob([this.characters.exportBVH(m)], { type: 'text/plain' })
        : new Blob([await this.characters.exportGLB(m, name)], { type: 'model/gltf-binary' });
      downloadBlob(`${name}.${format}`, blob);
    } catch (e) {
      this.reportError(`Export failed: ${errorMessage(e)}`);
    }
  }

  /**
   * Loads a character (a dropped or picked .glb, .gltf or .vrm, an attribute's URL, the API's source); a failure is
   * shown and keeps the character and motion shown. Resolves with what loadCharacter resolves to; rejects as shown.
   */
  async loadCharacter(...args: Parameters<CharacterInput['load']>): ReturnType<CharacterInput['load']> {
    const info = await this.characters.load(...args);
    this.onCharacter.row.hidden = false;
    this.onCharacter.name.textContent = info.name;
    return info;
  }

  /** Back to the mannequin (the Export menu's "on my character" goes with the character). */
  clearCharacter(): void {
    this.characters.clear();
    this.onCharacter.row.hidden = true;
    this.onCharacter.box.checked = false;
  }

  /**
   * Imports dropped or picked files in the import worker: one .bvh, or an .amc with its .asf (dropped
   * together or the .asf first). Large ones show their progress; a failure leaves the scene as it was.
   */
  async handleFiles(files: File[]): Promise<void> {
    if (looksLikePack(files.map((f) => f.name))) return this.dropPack(files); // a model pack (.zip, or .onnx with .json)
    const character = files.find((f) => CHARACTER_FILE.test(f.name));
    if (character) {
      try {
        const info = await this.loadCharacter(character);
        this.note(`Character ${info.name} loaded: ${info.bones.length} bones, ${info.height.toFixed(2)} m tall.`);
      } catch (e) {
        this.reportError(`Character: ${errorMessage(e)}`);
      }
      files = files.filter((f) => f !== character);
      if (!files.length) return;
    }
    const bytes = files.reduce((sum, f) => sum + f.size, 0);
    let outcome: FileImportOutcome;
    try {
      outcome = await this.importIndicator.track(bytes, (onProgress) => this.importer.importFiles(files, onProgress));
    } catch (e) {
      this.reportError(errorMessage(e));
      return;
    }
    if (outcome.kind === 'skeleton') {
      this.note(`Skeleton ${outcome.name} loaded: now drop an .amc motion for it.`);
      return;
    }
    this.show(outcome.motion, outcome.name);
    if (outcome.ignored.length) this.note(`Showing ${outcome.name}; ignored ${outcome.ignored.join(', ')}.`);
  }

  /** A dropped pack: loaded and listed, or refused with its message. */
  private async dropPack(files: File[]): Promise<void> {
    try {
      const id = await this.loadModels(files);
      this.note(this.packLoadedNote(id));
    } catch (e) {
      this.reportError(`Model pack: ${errorMessage(e)}`);
    }
  }

  private installDropZone(): void {
    // On the element's own area: several elements on a page each take the files dropped on them.
    const overlay = this.dropOverlay;
    const zone = this.scope.frame;
    let depth = 0;
    const hasFiles = (e: DragEvent) => !!e.dataTransfer && [...e.dataTransfer.types].includes('Files');
    zone.addEventListener('dragenter', (e) => {
      if (!hasFiles(e)) return;
      e.preventDefault();
      depth++;
      overlay.classList.add('visible');
    });
    zone.addEventListener('dragover', (e) => {
      if (!hasFiles(e)) return;
      e.preventDefault();
      e.dataTransfer!.dropEffect = 'copy';
    });
    zone.addEventListener('dragleave', (e) => {
      if (!hasFiles(e)) return;
      depth = Math.max(0, depth - 1);
      if (depth === 0) overlay.classList.remove('visible');
    });
    zone.addEventListener('drop', (e) => {
      if (!e.dataTransfer) return;
      e.preventDefault();
      depth = 0;
      overlay.classList.remove('visible');
      const items = e.dataTransfer.items;
      const files = [...e.dataTransfer.files];
      void droppedFolderFiles(items).then((walked) => {
        const all = walked ?? files;
        if (looksLikePack(all.map((f) => f.name))) void this.dropPack(all);
        else if (files.length) void this.handleFiles(files);
      });
    });
  }
}

/** The overlays above the stage: those at its top (the top bar and what is in it, the cards) and the control panel below; not the Export menu, a popup. */
const TOP_OVERLAYS = '.topbar *, .skate-card, .plot-card, .steer-card, .path-hint, .cleanup-card';
const BOTTOM_OVERLAYS = '#controls';

/**
 * Where the overlays leave `stage` free, for the viewer's framings: below the lowest top overlay and above the
 * highest bottom one among those over the stage's middle third (where a framed figure stands; a wide stage's
 * cards sit beside it, a phone's span it).
 */
function freeAreaOf(stage: HTMLElement, root: ShadowRoot): () => FreeArea {
  return () => {
    const s = stage.getBoundingClientRect();
    const midLeft = s.left + s.width / 3, midRight = s.right - s.width / 3;
    const shown = (el: Element) => el.checkVisibility({ checkVisibilityCSS: true }) && el.getClientRects().length > 0;
    const overMiddle = (r: DOMRect) => r.width > 0 && r.height > 0 && r.right > midLeft && r.left < midRight;
    let top = 0, bottom = 0;
    for (const el of root.querySelectorAll(TOP_OVERLAYS)) {
      const r = el.getBoundingClientRect();
      if (shown(el) && !el.closest('.export-menu') && overMiddle(r) && r.top < s.top + s.height / 2) top = Math.max(top, r.bottom - s.top);
    }
    for (const el of root.querySelectorAll(BOTTOM_OVERLAYS)) {
      const r = el.getBoundingClientRect();
      if (shown(el) && overMiddle(r) && r.bottom > s.top + s.height / 2) bottom = Math.max(bottom, s.bottom - r.top);
    }
    return { top, right: 0, bottom, left: 0 };
  };
}
