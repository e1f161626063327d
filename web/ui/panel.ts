// The playback bar (play/pause, timeline, time, speed, layer toggles) and keyboard shortcuts.

import type { Viewer, ViewerLayers } from '../viewer/viewer';
import { LOOKS, type Look } from '../viewer/look';
import type { PlaybackState } from '../viewer/playback';
import { $, $all, currentScope, setSliderFill, type DomScope } from './dom';

export class Panel {
  private readonly playBtn = $<HTMLButtonElement>('play-btn');
  private readonly timeline = $<HTMLInputElement>('timeline');
  private readonly frameOut = $('frame-out');
  private readonly timeOut = $('time-out');
  private readonly speed = $<HTMLInputElement>('speed');
  private readonly speedOut = $('speed-out');
  private readonly fpsOut = $('fps-out');
  private readonly layerButtons = $all<HTMLButtonElement>('[data-layer]');
  private readonly lookButtons = $all<HTMLButtonElement>('[data-look]');
  private readonly scope: DomScope = currentScope();
  private scrubbing = false;
  private wasPlaying = false;
  private shown = { frame: -1, frames: -1, playing: false, speed: -1, fps: -1 };
  private fpsShownAt = 0;
  /** The frame-rate readout only shows with ?stats in the URL. */
  private readonly showFps = new URLSearchParams(location.search).has('stats');
  private domAt = 0;

  constructor(private readonly viewer: Viewer) {
    this.playBtn.addEventListener('click', () => viewer.toggle());
    this.timeline.addEventListener('pointerdown', () => {
      this.scrubbing = true;
      this.wasPlaying = viewer.playback.playing;
      viewer.pause();
    });
    const endScrub = () => {
      if (!this.scrubbing) return;
      this.scrubbing = false;
      if (this.wasPlaying) viewer.play();
    };
    this.timeline.addEventListener('pointerup', endScrub);
    this.timeline.addEventListener('change', endScrub);
    this.timeline.addEventListener('input', () => viewer.seek(Number(this.timeline.value)));
    this.speed.addEventListener('input', () => viewer.setSpeed(Number(this.speed.value)));

    this.layerButtons.forEach((btn) => {
      const layer = btn.dataset.layer as keyof ViewerLayers;
      btn.addEventListener('click', () => {
        viewer.setLayers({ [layer]: !viewer.layers()[layer] });
        this.syncLayers();
      });
    });
    this.lookButtons.forEach((btn) => btn.addEventListener('click', () => this.setLook(btn.dataset.look as Look)));
    $('frame-all').addEventListener('click', () => {
      viewer.frameAll();
      this.syncLayers();
    });
    this.syncLayers();

    window.addEventListener('keydown', (e) => this.onKey(e), { signal: currentScope().signal });
  }

  syncLayers(): void {
    const l = this.viewer.layers();
    this.layerButtons.forEach((btn) => {
      btn.setAttribute('aria-pressed', String(l[btn.dataset.layer as keyof ViewerLayers]));
    });
    const look = this.viewer.currentLook;
    this.lookButtons.forEach((btn) => btn.setAttribute('aria-pressed', String(btn.dataset.look === look)));
  }

  /** Shows the look and tells the element (a `change` in its shadow root: links and attributes follow). */
  private setLook(look: Look): void {
    if (look === this.viewer.currentLook) return;
    this.viewer.setLook(look);
    this.syncLayers();
    this.announceLook();
  }

  /** Tells the element that the look changed (a `change` in its shadow root: links and attributes follow). */
  announceLook(): void {
    this.lookButtons[0]?.dispatchEvent(new Event('change', { bubbles: true }));
  }

  private onKey(e: KeyboardEvent): void {
    if (e.defaultPrevented || e.altKey || e.ctrlKey || e.metaKey || !this.scope.ownsEvent(e)) return;
    const t = (e.composedPath()[0] ?? e.target) as HTMLElement | null; // inside the shadow root, not the host
    if (t && (t.tagName === 'TEXTAREA' || t.tagName === 'SELECT' || (t.tagName === 'INPUT' && (t as HTMLInputElement).type !== 'range'))) return;
    // Arrow keys on a focused slider (speed, the modes' and the Clean up panel's settings) move it, as a slider's should.
    if (t instanceof HTMLInputElement && t.type === 'range' && t !== this.timeline && e.key.startsWith('Arrow')) return;
    const v = this.viewer;
    switch (e.key) {
      case ' ':
        v.toggle();
        break;
      case 'ArrowRight':
        v.step(e.shiftKey ? 10 : 1);
        break;
      case 'ArrowLeft':
        v.step(e.shiftKey ? -10 : -1);
        break;
      case 'Home':
        v.seek(0);
        break;
      case 'End':
        v.seek(v.playback.frames - 1);
        break;
      case 'l':
      case 'L':
        this.setLook(LOOKS[(LOOKS.indexOf(v.currentLook) + 1) % LOOKS.length]);
        break;
      case 'f':
      case 'F':
        v.setLayers({ follow: !v.layers().follow });
        this.syncLayers();
        break;
      default:
        return;
    }
    e.preventDefault();
    // A focused button would otherwise be "clicked" by the space bar as well.
    if (t instanceof HTMLButtonElement) t.blur();
  }

  /** Refreshes the bar; called every rendered frame, touches the DOM only when something changed. */
  update(s: PlaybackState): void {
    const sh = this.shown;
    if (s.frames !== sh.frames || s.fps !== sh.fps) {
      this.timeline.max = String(Math.max(s.frames - 1, 0));
      this.timeline.disabled = s.frames === 0;
      this.playBtn.disabled = s.frames === 0;
      sh.frames = s.frames;
      sh.fps = s.fps;
      sh.frame = -1;
    }
    const now = performance.now();
    // While playing, the readouts refresh at most ~30 times a second: DOM updates cost frame time.
    if (s.frame !== sh.frame && (!s.playing || now - this.domAt > 30)) {
      this.domAt = now;
      if (!this.scrubbing) this.timeline.value = String(s.frame);
      setSliderFill(this.timeline, s.frames > 1 ? s.frame / (s.frames - 1) : 0);
      const last = Math.max(s.frames - 1, 0);
      this.frameOut.textContent = `${s.frame} / ${last}`;
      this.timeOut.textContent = s.frames ? `${(s.frame / s.fps).toFixed(2)} s / ${(last / s.fps).toFixed(2)} s` : '—';
      sh.frame = s.frame;
    }
    if (s.playing !== sh.playing) {
      this.playBtn.classList.toggle('playing', s.playing);
      this.playBtn.setAttribute('aria-label', s.playing ? 'Pause' : 'Play');
      this.playBtn.title = s.playing ? 'Pause (space)' : 'Play (space)';
      sh.playing = s.playing;
    }
    if (s.speed !== sh.speed) {
      this.speed.value = String(s.speed);
      this.speedOut.textContent = `${s.speed.toFixed(2).replace(/0$/, '')}×`;
      sh.speed = s.speed;
    }
    if (this.showFps && now - this.fpsShownAt > 500) {
      this.fpsOut.textContent = `${Math.round(this.viewer.displayFps)} fps`;
      this.fpsShownAt = now;
    }
  }
}
