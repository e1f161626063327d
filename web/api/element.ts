// The <motion-playground> custom element, after the conventions of Google's <model-viewer>: the whole
// playground (viewer, modes, panels, workers) in a shadow root, configured by attributes, with events
// and the window.playground API on the element. The page itself is one of these (web/index.html), so
// embeds and the page share one code path. Attributes and link parameters are checked by viewState.ts;
// a bad one fires `error` with the reason and the setting keeps its default.

import css from '../style.css?inline';
import templateHtml from '../ui/playground.html?raw';
import { createPlayground, type GenerateOptions, type Playground } from './playground';
import type { BVHExportOptions } from '../motion/bvh';
import type { GLBExportOptions } from '../motion/gltf';
import type { Motion } from '../motion/types';
import { App } from '../ui/app';
import { buildIn, errorMessage, type DomScope } from '../ui/dom';
import { embedSnippet, FIRST_VIEW, formatViewValue, parseView, parseViewValue, styleAttribute, viewQuery, VIEW_KEYS, type Mode, type ViewKey, type ViewState } from '../ui/viewState';
import { fetchMotionSource, sourceName } from '../runtime/import/motionSource';
import { capMessage, quoteInput } from '../motion/text';
import { prefetchRuntime } from '../runtime/worker/workerClient';
import { DEFAULT_LOOK, type Look } from '../viewer/look';

const OTHER_ATTRIBUTES = ['src', 'character', 'models', 'autoplay', 'camera-controls', 'controls', 'poster', 'loading', 'link'] as const;
const CONTROLS = ['full', 'minimal', 'none'] as const;
type Controls = (typeof CONTROLS)[number];
const LOADING = ['eager', 'lazy'] as const;
type Loading = (typeof LOADING)[number];

/** What the element fires: `error` and `progress` carry a detail, `motion` the shown motion's name. */
export type PlaygroundEventName = 'load' | 'error' | 'progress' | 'play' | 'pause' | 'motion';

export class MotionPlaygroundElement extends HTMLElement {
  static readonly observedAttributes = [...VIEW_KEYS, 'dance-style', 'motion-style', ...OTHER_ATTRIBUTES];

  private readonly shadow: ShadowRoot;
  private frame!: HTMLElement;
  private posterImage!: HTMLImageElement;
  private app: App | null = null;
  /** Aborted when the playground is taken down (teardown): the listeners it put on the page and the shadow root. */
  private lifetime: AbortController | null = null;
  private progressObserver: MutationObserver | null = null;
  /** The clip shown when the element was taken down, shown again when it is put back (Clip mode without `src`). */
  private keptClip: { motion: Motion; name: string } | null = null;
  private api: Playground | null = null;
  private lazyObserver: IntersectionObserver | null = null;
  private readonly started: Promise<void>;
  private markStarted!: () => void;
  /** Set while the element writes its own attributes (reflecting the UI): no re-apply. */
  private reflecting = false;
  private wasPlaying = false;
  private linkTimer = 0;
  /** The bad value of `controls`, `poster` or `loading` whose `error` has fired (badAttribute). */
  private readonly reportedBad = new Map<string, string>();
  /** Bumped for every `src` load: a slower earlier one does not replace a later one. */
  private srcToken = 0;

  constructor() {
    super();
    this.shadow = this.attachShadow({ mode: 'open' });
    this.renderTemplate();
    this.started = new Promise((resolve) => (this.markStarted = resolve));
  }

  /** The shadow root's markup, fresh (at first, and when a taken-down element is built again). */
  private renderTemplate(): void {
    const style = document.createElement('style');
    style.textContent = css;
    // The template is the element's own static markup (never anything from a file, attribute or URL).
    const template = document.createElement('template');
    template.innerHTML = templateHtml;
    this.shadow.replaceChildren(style, template.content.cloneNode(true));
    this.frame = this.shadow.querySelector<HTMLElement>('.app')!;
    this.posterImage = this.shadow.querySelector<HTMLImageElement>('.poster')!;
  }

  // ---------- lifecycle ----------

  connectedCallback(): void {
    this.showControls();
    this.showPoster();
    if (this.app || this.lazyObserver) return;
    if (this.loadingMode() === 'lazy' && 'IntersectionObserver' in window) {
      // Nothing is fetched (onnxruntime-web, models) until the element comes near the viewport.
      this.lazyObserver = new IntersectionObserver((entries) => {
        if (entries.some((e) => e.isIntersecting)) this.start();
      }, { rootMargin: '200px' });
      this.lazyObserver.observe(this);
    } else {
      this.start();
    }
  }

  disconnectedCallback(): void {
    // Taken off the page: everything it started stops, unless it was only moved (connected again in this task,
    // when it keeps its state).
    queueMicrotask(() => {
      if (!this.isConnected) this.teardown();
    });
  }

  /**
   * Stops everything the element started (issue 43): its live mode, a path optimisation or clean-up under way,
   * the frame loop, every worker, the WebGL context, the observers and the listeners on the page. The API keeps
   * answering with the last state; put back on the page, the element builds its playground again from its
   * attributes (a clip shown in Clip mode is shown again).
   */
  private teardown(): void {
    this.lazyObserver?.disconnect();
    this.lazyObserver = null;
    const app = this.app;
    if (!app) return;
    this.app = null;
    this.lifetime?.abort();
    this.lifetime = null;
    this.progressObserver?.disconnect();
    this.progressObserver = null;
    clearTimeout(this.linkTimer);
    this.srcToken++;
    const motion = app.currentMode === 'clip' && !this.hasAttribute('src') ? app.current : null;
    this.keptClip = motion ? { motion, name: this.shadow.getElementById('clip-name')?.textContent || 'motion' } : null;
    app.dispose();
  }

  attributeChangedCallback(name: string, before: string | null, after: string | null): void {
    if (this.reflecting || before === after) return;
    if (name === 'controls') return this.showControls();
    if (name === 'poster') return this.showPoster();
    if (name === 'loading') return void this.loadingMode(); // a bad value is reported; it counts when the element connects
    if (name === 'camera-controls' && this.app) this.app.viewer.controls.enabled = after !== null;
    if (!this.app || !this.api) return; // applied when it starts
    if (name === 'look') {
      // Removing the attribute goes back to the default look; a bad value fires `error` and changes nothing.
      const r = after === null ? { value: DEFAULT_LOOK } : parseViewValue('look', after);
      if ('error' in r) this.fire('error', { reason: `attribute ${r.error}` });
      else this.showLook(r.value as Look);
      return;
    }
    if (name === 'src') {
      void this.loadSource();
      return;
    }
    if (name === 'character') {
      if (after === null) this.app.clearCharacter();
      else void this.loadCharacterAttribute();
      return;
    }
    if (name === 'models') {
      if (after !== null) void this.loadModelsAttribute();
      return;
    }
    if ((VIEW_KEYS as readonly string[]).includes(name) || name === 'dance-style' || name === 'motion-style') void this.api.ready.then(() => this.applyView(this.attributeView(), false));
  }

  /** Builds the playground (once): its UI in the shadow root, its workers, the API, the view. */
  private start(): void {
    if (this.app) return;
    this.lazyObserver?.disconnect();
    this.lazyObserver = null;
    if (this.api) {
      // Built before and taken down (taken off the page, now back): a fresh UI for a fresh playground.
      this.renderTemplate();
      this.showControls();
      this.showPoster();
      this.wasPlaying = false;
    }
    const lifetime = (this.lifetime = new AbortController());
    const { signal } = lifetime;
    const kept = this.keptClip;
    this.keptClip = null;
    const scope: DomScope = { root: this.shadow, frame: this.frame, ownsEvent: (e) => this.ownsEvent(e), signal };
    const app = buildIn(scope, () => new App(scope, {
      motion: (name) => {
        if (signal.aborted) return;
        if (this.frame.dataset.context !== 'lost') this.posterImage.hidden = true; // no context: the poster stays
        this.fire('motion', { name, frames: app.current?.frames ?? 0 });
        this.linkSoon();
      },
      error: (reason) => {
        if (!signal.aborted) this.fire('error', { reason });
      },
    }));
    this.app = app;
    this.watchContext(app, signal);
    this.api = createPlayground(app);
    app.characters.allowedOrigins = () => allowedOrigins(this.getAttribute('allowed-origins'));
    app.allowedOrigins = () => allowedOrigins(this.getAttribute('allowed-origins'));
    const version = this.shadow.getElementById('version');
    if (version) version.textContent = `v${this.api.version}`;
    app.viewer.controls.enabled = this.hasAttribute('camera-controls');
    app.frameListeners.push((s) => {
      if (s.playing !== this.wasPlaying) {
        this.wasPlaying = s.playing;
        this.fire(s.playing ? 'play' : 'pause');
      }
    });
    this.watchProgress();
    this.shadow.addEventListener('change', () => this.linkSoon(), { signal });
    for (const m of ['clip', 'walk', 'dance', 'path', 'steer']) this.shadow.getElementById(`mode-${m}`)?.addEventListener('click', () => this.linkSoon());
    this.installShare();
    this.markStarted();
    this.preloadFirstModel(app);
    void this.api.ready.then(async () => {
      if (signal.aborted) return; // taken off the page before its model list came
      const fromLink = this.hasAttribute('link') ? this.linkView() : null;
      const attrs = this.attributeView();
      // No mode from the attributes or the link (none, or a bad one) and no src: the first view (something
      // alive), under whatever settings were given.
      const given = { ...attrs, ...(fromLink ?? {}) };
      const view: ViewState = given.mode === undefined && !this.hasAttribute('src') ? { ...FIRST_VIEW, ...given } : given;
      if (this.hasAttribute('src') && view.mode === undefined) view.mode = 'clip';
      this.applyView(view, true);
      if (kept && app.currentMode === 'clip' && !this.hasAttribute('src')) {
        app.show(kept.motion, kept.name);
        if (!this.hasAttribute('autoplay')) app.viewer.pause();
      }
      await Promise.all([this.hasAttribute('src') ? this.loadSource() : undefined, this.loadCharacterAttribute(), this.loadModelsAttribute()]);
      if (!signal.aborted) this.fire('load');
    });
  }

  /**
   * The viewer's WebGL context: one that cannot be made, or that the browser takes (too many on the page),
   * fires `error` with the reason and shows the poster (when there is one) until it comes back.
   */
  private watchContext(app: App, signal: AbortSignal): void {
    app.viewer.onContextLost = (reason) => {
      if (signal.aborted) return;
      if (this.posterImage.getAttribute('src')) this.posterImage.hidden = false;
      this.frame.dataset.context = 'lost';
      this.fire('error', { reason });
    };
    app.viewer.onContextRestored = () => {
      if (signal.aborted) return;
      delete this.frame.dataset.context;
      this.posterImage.hidden = app.current != null || !this.posterImage.getAttribute('src');
    };
  }

  /**
   * When the view about to be shown is Random walk: starts fetching the onnxruntime wasm at once, beside the model
   * list, and loading the walk model (its worker and files) as soon as the list names it, rather than after
   * `ready`: the first generated frame comes sooner (npm run bench -- first-frame). Only a guess from the
   * attributes and link, read silently (applyView reports their errors later); a failed load is retried when the
   * mode asks for the model.
   */
  private preloadFirstModel(app: App): void {
    if (this.hasAttribute('src')) return;
    const quiet = (get: (k: ViewKey) => string | null) => parseView(get).view.mode;
    const params = new URLSearchParams(location.search || location.hash.replace(/^#/, ''));
    const mode = (this.hasAttribute('link') ? quiet((k) => params.get(k)) : undefined) ?? quiet((k) => this.getAttribute(k)) ?? FIRST_VIEW.mode;
    if (mode !== 'walk') return;
    prefetchRuntime();
    void app.whenModels().then((registry) => {
      const walker = registry.defaultFor('walk');
      if (walker) app.host(walker.info.id).load().catch(() => undefined);
    });
  }

  // ---------- views: attributes, links, the UI ----------

  /** The view the attributes ask for (bad ones fire `error` and are left out). */
  private attributeView(): ViewState {
    const { view, errors } = parseView((k) => (k === 'style' ? this.styleAttribute() : this.getAttribute(k)), this.app?.modeModels());
    for (const reason of errors) this.fire('error', { reason: `attribute ${reason}` });
    return view;
  }

  /**
   * The view's style: `motion-style` (a walking style: Random walk, Path, Steer), `dance-style` (Dance), or `style`
   * when it holds a bare style name (`style="salsa"`), since `style` is also HTML's inline CSS attribute (a value
   * with a colon is CSS and left to the browser). The element writes the one of its mode (styleAttribute in viewState.ts).
   */
  private styleAttribute(): string | null {
    const named = this.getAttribute('motion-style') ?? this.getAttribute('dance-style');
    if (named !== null) return named;
    const style = this.getAttribute('style');
    return style !== null && /^\s*[a-z][a-z0-9_-]*\s*$/.test(style) ? style.trim() : null;
  }

  /** The view in the page's URL (query or hash), when the element keeps the link. */
  private linkView(): ViewState {
    const params = new URLSearchParams(location.search || location.hash.replace(/^#/, ''));
    const { view, errors } = parseView((k) => params.get(k), this.app?.modeModels());
    for (const reason of errors) {
      this.app?.reportError(`Link: ${reason}; using the default`);
    }
    return view;
  }

  /** Applies a view to the UI: each mode's settings first, then the mode (so a stream starts with them). */
  private applyView(view: ViewState, initial: boolean): void {
    const app = this.app!;
    const models = this.api!.models();
    const mode: Mode = view.mode ?? (initial ? 'clip' : app.currentMode);
    if (mode === 'walk') {
      const model = view.model ?? app.walk.model.value;
      app.walk.preset({ ...view, style: this.checkedStyle(view.style, model) });
    } else if (mode === 'dance') {
      if (view.model !== undefined) app.danceMode.selectModel(view.model);
      const id = app.danceMode.choice.model;
      const styles = models.find((m) => m.id === id)?.styles ?? [];
      let style = view.style;
      if (style !== undefined && styles.length && !styles.includes(style)) {
        this.fire('error', { reason: `style=${quoteInput(style)}: ${id} dances ${styles.join(', ')}` });
        style = undefined;
      }
      app.danceMode.preset(style, view.seed);
    } else if (mode === 'path' || mode === 'steer') {
      if (view.model !== undefined) app.controlModel.set(view.model);
      const style = this.checkedStyle(view.style, mode === 'path' ? app.controlModel.value : app.controlModel.steerable);
      if (style !== undefined) app.controlStyle.set(style);
      if (mode === 'path' && view.seed !== undefined) app.pathMode.presetSeed(view.seed);
      if (mode === 'path' && view.path) app.pathMode.setPath(view.path);
    }
    if (view.look !== undefined) this.showLook(view.look);
    if (view.mode !== undefined || initial) app.setMode(mode);
    if (!this.hasAttribute('autoplay') && mode === 'clip') app.viewer.pause();
    this.linkSoon();
  }

  /**
   * A view's walking style for model `id`: kept when the model lists it; else `error` fires with the reason (a model
   * without styles, or a style it does not have) and the style shown stays as it was (undefined).
   */
  private checkedStyle(style: string | undefined, id: string): string | undefined {
    if (style === undefined) return undefined;
    const styles = this.app!.stylesOf(id);
    if (styles.includes(style)) return style;
    this.fire('error', { reason: `style=${quoteInput(style)}: ${styles.length ? `${id} walks ${styles.join(', ')}` : `${id || 'the model'} has no styles`}` });
    return undefined;
  }

  private showLook(look: Look): void {
    if (!this.app) return;
    this.app.viewer.setLook(look);
    this.app.panel.syncLayers();
    this.linkSoon();
  }

  /** The view shown now, as a link or the attributes would say it: each mode says its own settings. */
  get view(): ViewState {
    const app = this.app;
    if (!app) return this.attributeView();
    const mode = app.currentMode;
    const view: ViewState = { mode };
    if (mode === 'walk') {
      Object.assign(view, app.walk.viewSettings);
    } else if (mode === 'dance') {
      const { model, style, seed } = app.danceMode.choice;
      Object.assign(view, { model, ...(style ? { style } : {}), seed });
    } else if (mode === 'path') {
      const style = app.controlStyle.for(app.stylesOf(app.controlModel.value));
      Object.assign(view, { model: app.controlModel.value, ...(style ? { style } : {}), seed: app.pathMode.seedValue });
      const path = app.pathMode.path;
      if (path.length >= 2) view.path = path;
    } else if (mode === 'steer') {
      view.model = app.controlModel.steerable;
      const style = app.controlStyle.for(app.stylesOf(view.model));
      if (style) view.style = style;
    }
    if (!view.model) delete view.model; // no model chosen yet: the model list has not arrived (or listed none)
    // The look only when it is not the default (links stay as they were), or when the attribute says it.
    const look = app.viewer.currentLook;
    if (look !== DEFAULT_LOOK || this.hasAttribute('look')) view.look = look;
    return view;
  }

  /** Keeps the URL (with `link`) and the attributes in step with the view, a moment after a change. */
  private linkSoon(): void {
    clearTimeout(this.linkTimer);
    this.linkTimer = window.setTimeout(() => {
      const view = this.view;
      this.reflecting = true;
      try {
        for (const key of VIEW_KEYS) {
          if (key === 'path' && !this.hasAttribute('path')) continue; // a drawn path stays out of the attributes
          const attribute = key === 'style' ? styleAttribute(view.mode) : key; // `style` is the inline CSS attribute
          if (key === 'style') this.removeAttribute(styleAttribute(view.mode === 'dance' ? 'walk' : 'dance')); // the other mode's
          const v = view[key];
          if (v === undefined) this.removeAttribute(attribute);
          else this.setAttribute(attribute, formatViewValue(key, v));
        }
      } finally {
        this.reflecting = false;
      }
      if (this.hasAttribute('link')) history.replaceState(history.state, '', `${location.pathname}?${linkQuery(view)}`);
    }, 50);
  }

  /** The link to this view (the page's address with the view in its query). */
  get shareLink(): string {
    return `${location.origin}${location.pathname}?${linkQuery(this.view)}`;
  }

  /** The snippet that embeds this view on another site. */
  get embedCode(): string {
    const moduleUrl = new URL('motion-playground.js', new URL('./', location.href)).href;
    return embedSnippet(this.view, moduleUrl);
  }

  private installShare(): void {
    const share = this.shadow.getElementById('share-btn') as HTMLButtonElement;
    const embed = this.shadow.getElementById('embed-btn') as HTMLButtonElement;
    const dialog = this.shadow.getElementById('share-dialog') as HTMLDialogElement;
    const text = this.shadow.getElementById('share-text') as HTMLTextAreaElement;
    const title = this.shadow.getElementById('share-title')!;
    const copy = this.shadow.getElementById('share-copy') as HTMLButtonElement;
    const open = (heading: string, value: string) => {
      title.textContent = heading;
      text.value = value; // as text: a joint or file name with markup stays text
      copy.textContent = 'Copy';
      if (!dialog.open) dialog.showModal();
      text.select();
    };
    share.addEventListener('click', () => {
      const link = this.shareLink;
      open('Link to this view', link);
      void this.copyText(link, copy);
    });
    embed.addEventListener('click', () => open('Embed this view', this.embedCode));
    copy.addEventListener('click', () => void this.copyText(text.value, copy));
    this.shadow.getElementById('share-close')!.addEventListener('click', () => dialog.close());
  }

  private async copyText(value: string, button: HTMLButtonElement): Promise<void> {
    try {
      await navigator.clipboard.writeText(value);
      button.textContent = 'Copied';
      this.frame.dataset.copied = value;
    } catch {
      button.textContent = 'Select and copy'; // no clipboard permission: the text is selected in the box
    }
  }

  // ---------- src ----------

  /** Plays the BVH at `src` (same origin or an allowed one, size-limited); a failure keeps what is shown. */
  private async loadSource(): Promise<void> {
    const src = this.getAttribute('src');
    if (!src || !this.app) return;
    const token = ++this.srcToken;
    try {
      const text = await fetchMotionSource(src, location.href, allowedOrigins(this.getAttribute('allowed-origins')));
      const motion = await this.app.importer.importText(text, 'bvh');
      if (token !== this.srcToken) return;
      this.app.show(motion, sourceName(src));
      if (!this.hasAttribute('autoplay')) this.app.viewer.pause();
    } catch (e) {
      if (token === this.srcToken) this.app.reportError(`src: ${errorMessage(e)}`);
    }
  }

  // ---------- character ----------

  /**
   * Loads the character the `character` attribute names, else (on the page, with `link`) the URL's `character=`
   * parameter: a .glb, .gltf or .vrm under the same rules as `src`. A failure fires `error` and keeps what is shown.
   */
  private async loadCharacterAttribute(): Promise<void> {
    const app = this.app;
    if (!app) return;
    const fromLink = this.hasAttribute('link') ? new URLSearchParams(location.search || location.hash.replace(/^#/, '')).get('character') : null;
    const url = this.getAttribute('character') ?? fromLink;
    if (!url) return;
    const what = this.hasAttribute('character') ? 'character' : 'Link: character';
    try {
      await app.loadCharacter(url);
    } catch (e) {
      if (this.app === app && !(e instanceof Error && e.name === 'SupersededError')) app.reportError(`${what}: ${errorMessage(e)}`);
    }
  }

  /**
   * Loads the model pack the `models` attribute names (the URL of its .json), else (with `link`) the URL's `models=`
   * parameter, under the same rules as `src`. A refused pack fires `error`; the shipped models stay.
   */
  private async loadModelsAttribute(): Promise<void> {
    const app = this.app;
    if (!app) return;
    const fromLink = this.hasAttribute('link') ? new URLSearchParams(location.search || location.hash.replace(/^#/, '')).get('models') : null;
    const url = this.getAttribute('models') ?? fromLink;
    if (!url) return;
    try {
      const id = await app.loadModels(url);
      if (this.app === app) app.note(app.packLoadedNote(id));
    } catch (e) {
      if (this.app === app) app.reportError(`${this.hasAttribute('models') ? 'models' : 'Link: models'}: ${errorMessage(e)}`);
    }
  }

  // ---------- presentation ----------

  private showControls(): void {
    const text = this.getAttribute('controls');
    let controls: Controls = 'full';
    if (text === null || (CONTROLS as readonly string[]).includes(text)) {
      controls = (text ?? 'full') as Controls;
      this.reportedBad.delete('controls');
    } else {
      this.badAttribute('controls', text, `controls=${quoteInput(text)}: must be one of ${CONTROLS.join(', ')}`);
    }
    for (const c of CONTROLS) this.frame.classList.toggle(`controls-${c}`, c === controls);
  }

  private showPoster(): void {
    const src = this.getAttribute('poster');
    if (src !== this.reportedBad.get('poster')) this.reportedBad.delete('poster');
    if (!src) {
      this.posterImage.hidden = true;
      this.posterImage.removeAttribute('src');
      return;
    }
    let url: URL;
    try {
      url = new URL(src, document.baseURI);
    } catch {
      this.badAttribute('poster', src, `poster=${quoteInput(src)}: not a URL`);
      return;
    }
    if (url.protocol !== 'https:' && url.protocol !== 'http:' && url.protocol !== 'data:') {
      this.badAttribute('poster', src, `poster: ${url.protocol} URLs are not allowed`);
      return;
    }
    this.posterImage.src = url.href;
    this.posterImage.hidden = this.app?.current != null;
  }

  /**
   * The `loading` attribute: `eager` (the default) or `lazy`; any other value fires `error` with the allowed
   * values and counts as `eager`.
   */
  private loadingMode(): Loading {
    const text = this.getAttribute('loading');
    if (text === null || (LOADING as readonly string[]).includes(text)) {
      this.reportedBad.delete('loading');
      return (text ?? 'eager') as Loading;
    }
    this.badAttribute('loading', text, `loading=${quoteInput(text)}: must be one of ${LOADING.join(', ')}`);
    return 'eager';
  }

  /**
   * Fires `error` ("attribute <reason>") for a bad value of `name` (controls, poster, loading), once per value: the
   * value is checked when it changes and again as the element connects or rebuilds its UI, which must not say it
   * twice. A good value clears it, so the same bad value set again is reported again.
   */
  private badAttribute(name: string, value: string, reason: string): void {
    if (this.reportedBad.get(name) === value) return;
    this.reportedBad.set(name, value);
    this.fire('error', { reason: `attribute ${reason}` });
  }

  /** Progress bars and the model indicator inside the shadow root, as `progress` events. */
  private watchProgress(): void {
    const kinds: Record<string, string> = { 'path-progress': 'path', 'cleanup-progress': 'cleanup', 'import-progress': 'import', 'model-status': 'model' };
    this.progressObserver = new MutationObserver((records) => {
      for (const r of records) {
        const el = r.target as HTMLElement;
        const what = kinds[el.id];
        if (!what) continue;
        if (el instanceof HTMLProgressElement) this.fire('progress', { what, fraction: el.value / (el.max || 1) });
        else this.fire('progress', { what, loading: !el.hidden });
      }
    });
    this.progressObserver.observe(this.shadow, { subtree: true, attributes: true, attributeFilter: ['value', 'hidden'] });
  }

  /** Keys and drops: from inside this element, or on the bare page when this is its only playground. */
  private ownsEvent(e: Event): boolean {
    if (e.composedPath().includes(this)) return true;
    const t = e.target;
    return (t === document.body || t === document.documentElement || t === document || t === window) && document.querySelectorAll('motion-playground').length === 1;
  }

  private fire(type: PlaygroundEventName, detail?: object): void {
    // An error's reason is at most MAX_MESSAGE characters, whatever the file name, URL or attribute it quotes.
    if (type === 'error' && detail && 'reason' in detail) detail = { ...detail, reason: capMessage(String(detail.reason)) };
    this.dispatchEvent(new CustomEvent(type, { detail }));
  }

  // ---------- properties and methods ----------

  /** The automation API (docs/api.md) of this element; the page's is also window.playground. */
  get playground(): Playground {
    if (!this.api) this.start();
    return this.api!;
  }

  /** Resolves once the element has started (lazy: once scrolled near) and its model list is loaded. */
  get ready(): Promise<void> {
    return this.started.then(() => this.api!.ready);
  }

  play(): void {
    this.playground.play();
  }

  pause(): void {
    this.playground.pause();
  }

  /** The playhead in seconds (setting it seeks). */
  get currentTime(): number {
    const s = this.app?.viewer.state();
    return s && s.fps ? s.frame / s.fps : 0;
  }

  set currentTime(seconds: number) {
    const s = this.playground.state();
    if (s.fps) this.playground.seek(seconds * s.fps);
  }

  /**
   * playground.generate(options). Left out: 10 s from the element's view — in Dance mode the dance model,
   * style and seed; otherwise the generator with the view's seed, temperature and refine. Shows nothing.
   */
  generate(options?: GenerateOptions): Promise<Motion> {
    const api = this.playground; // starts a lazy element
    if (options !== undefined) return api.generate(options);
    // The view's models are known once the model list is.
    return api.ready.then(() => {
      const view = this.view;
      const frames = 300;
      if (view.mode === 'dance' && view.model) return api.generate({ model: view.model, seed: view.seed ?? 0, frames, ...(view.style ? { style: view.style } : {}) });
      const walk: ViewState = view.mode === 'walk' ? view : {};
      // The Random walk model (left out when none is listed: generate then says which models there are), in its style.
      const walker = walk.model ?? this.app?.registry.defaultFor('walk')?.info.id;
      const style = walk.style ? { style: walk.style } : {};
      return api.generate({ ...(walker ? { model: walker } : {}), seed: walk.seed ?? 0, refine: walk.refine ?? false, frames, ...(walk.temperature !== undefined ? { temperature: walk.temperature } : {}), ...style } as GenerateOptions);
    });
  }

  /** BVH text of `motion`, or of the shown motion when left out. */
  exportBVH(motion?: Motion | null, options?: BVHExportOptions): string {
    return this.playground.exportBVH(motion ?? this.shownMotion(), options);
  }

  /** GLB bytes of `motion`, or of the shown motion when left out. */
  exportGLB(motion?: Motion | null, options?: GLBExportOptions): Uint8Array<ArrayBuffer> {
    return this.playground.exportGLB(motion ?? this.shownMotion(), options);
  }

  private shownMotion() {
    const m = this.playground.current();
    if (!m) throw new Error('nothing is shown to export');
    return m;
  }
}

/** The page's query with `view` in it: other parameters (threads, stats) are kept, the view's own replaced. */
function linkQuery(view: ViewState): string {
  const kept = new URLSearchParams(location.search);
  for (const key of VIEW_KEYS) kept.delete(key);
  const rest = kept.toString();
  const own = viewQuery(view);
  return rest && own ? `${own}&${rest}` : own || rest;
}

/** The allowed-origins attribute: origins `src` may also be fetched from, space separated. */
function allowedOrigins(text: string | null): string[] {
  return (text ?? '').split(/\s+/).filter(Boolean);
}

/** Reflected properties: each attribute as a property of the same (camel-cased) name. */
const STRING_PROPERTIES: Record<string, string> = { mode: 'mode', model: 'model', danceStyle: 'dance-style', motionStyle: 'motion-style', src: 'src', character: 'character', controls: 'controls', poster: 'poster', loading: 'loading', path: 'path' };
const NUMBER_PROPERTIES = ['seed', 'temperature'];
const BOOLEAN_PROPERTIES: Record<string, string> = { autoplay: 'autoplay', cameraControls: 'camera-controls', link: 'link' };

for (const [prop, attr] of Object.entries(STRING_PROPERTIES)) {
  Object.defineProperty(MotionPlaygroundElement.prototype, prop, {
    get(this: HTMLElement) {
      return this.getAttribute(attr);
    },
    set(this: HTMLElement, v: string | null) {
      if (v === null || v === undefined) this.removeAttribute(attr);
      else this.setAttribute(attr, String(v));
    },
  });
}
for (const prop of NUMBER_PROPERTIES) {
  Object.defineProperty(MotionPlaygroundElement.prototype, prop, {
    get(this: HTMLElement) {
      const text = this.getAttribute(prop);
      if (text === null) return null;
      const r = parseViewValue(prop as ViewKey, text);
      return 'value' in r ? r.value : null;
    },
    set(this: HTMLElement, v: number | null) {
      if (v === null || v === undefined) this.removeAttribute(prop);
      else this.setAttribute(prop, String(v));
    },
  });
}
Object.defineProperty(MotionPlaygroundElement.prototype, 'refine', {
  get(this: HTMLElement) {
    const text = this.getAttribute('refine');
    return text === null ? null : text !== 'false';
  },
  set(this: HTMLElement, v: boolean | null) {
    if (v === null || v === undefined) this.removeAttribute('refine');
    else this.setAttribute('refine', String(Boolean(v)));
  },
});
for (const [prop, attr] of Object.entries(BOOLEAN_PROPERTIES)) {
  Object.defineProperty(MotionPlaygroundElement.prototype, prop, {
    get(this: HTMLElement) {
      return this.hasAttribute(attr);
    },
    set(this: HTMLElement, v: boolean) {
      this.toggleAttribute(attr, Boolean(v));
    },
  });
}

/** Defines <motion-playground> (once) and returns its class. */
export function defineMotionPlayground(): typeof MotionPlaygroundElement {
  if (!customElements.get('motion-playground')) customElements.define('motion-playground', MotionPlaygroundElement);
  return customElements.get('motion-playground') as typeof MotionPlaygroundElement;
}

declare global {
  interface HTMLElementTagNameMap {
    'motion-playground': MotionPlaygroundElement;
  }
}
