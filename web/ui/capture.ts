// Snapshot (a PNG of the view) and Record (a WebM of the canvas, MediaRecorder, for a chosen length or until
// stopped). The footer's Snapshot and Record buttons; one per app. While recording the viewer draws every
// frame (it otherwise draws only on change), so a paused scene still gives a video of the chosen length.
import type { PlaybackState } from '../viewer/playback';
import type { Viewer } from '../viewer/viewer';
import { $, downloadBlob, errorMessage } from './dom';

/** The first WebM type this browser's MediaRecorder can write ('' when none). */
export function webmType(): string {
  if (typeof MediaRecorder === 'undefined') return '';
  for (const type of ['video/webm;codecs=vp9', 'video/webm;codecs=vp8', 'video/webm']) {
    if (MediaRecorder.isTypeSupported(type)) return type;
  }
  return '';
}

export interface CaptureHost {
  readonly viewer: Viewer;
  /** Runs every viewer frame. */
  readonly frameListeners: Array<(s: PlaybackState) => void>;
  /** The base of download names ("salsa-seed-3"). */
  exportName(): string;
  reportError(message: string): void;
  note(message: string): void;
}

export class Capture {
  private readonly snapshotBtn = $<HTMLButtonElement>('snapshot-btn');
  private readonly recordBtn = $<HTMLButtonElement>('record-btn');
  private readonly secondsSelect = $<HTMLSelectElement>('record-seconds');
  private readonly status = $('record-status');
  private readonly dot = $('record-dot');
  private recorder: MediaRecorder | null = null;
  private stopTimer = 0;
  private startedAt = 0;
  private seconds = 0;

  constructor(private readonly host: CaptureHost) {
    this.snapshotBtn.addEventListener('click', () => void this.snapshot());
    this.recordBtn.addEventListener('click', () => (this.recorder ? this.stop() : this.start()));
    host.frameListeners.push(() => this.frame());
    if (!webmType()) {
      this.recordBtn.disabled = true;
      this.recordBtn.title = 'This browser cannot record WebM video (no MediaRecorder for video/webm)';
    }
  }

  get recording(): boolean {
    return this.recorder !== null;
  }

  /** Saves the view as `<name>.png`. */
  async snapshot(): Promise<void> {
    const canvas = this.host.viewer.canvas;
    this.host.viewer.renderNow(); // the drawing buffer is not kept between frames: draw and read in one task
    const blob = await new Promise<Blob | null>((resolve) => canvas.toBlob(resolve, 'image/png'));
    if (!blob) {
      this.host.reportError('Snapshot failed: the browser gave no image of the view');
      return;
    }
    downloadBlob(`${this.host.exportName()}.png`, blob);
  }

  /** Starts recording for the chosen length (0: until stopped). */
  start(): void {
    const type = webmType();
    if (!type || this.recorder) return;
    const canvas = this.host.viewer.canvas;
    let recorder: MediaRecorder;
    try {
      recorder = new MediaRecorder(canvas.captureStream(30), { mimeType: type, videoBitsPerSecond: 4_000_000 });
    } catch (e) {
      this.host.reportError(`Recording could not start: ${errorMessage(e)}`);
      return;
    }
    const chunks: Blob[] = [];
    const name = this.host.exportName();
    recorder.ondataavailable = (e) => {
      if (e.data.size > 0) chunks.push(e.data);
    };
    recorder.onstop = () => {
      this.recorder = null;
      this.setIdle();
      if (chunks.length === 0) {
        this.host.reportError('Recording failed: the browser recorded no video');
        return;
      }
      downloadBlob(`${name}.webm`, new Blob(chunks, { type: 'video/webm' }));
      this.status.dataset.state = 'saved';
      this.status.textContent = `saved ${name}.webm`;
    };
    recorder.onerror = () => this.host.reportError('Recording failed in the browser');
    this.seconds = Number(this.secondsSelect.value) || 0;
    this.recorder = recorder;
    this.startedAt = performance.now();
    recorder.start(1000);
    if (this.seconds > 0) this.stopTimer = window.setTimeout(() => this.stop(), this.seconds * 1000);
    this.recordBtn.textContent = 'Stop';
    this.recordBtn.setAttribute('aria-pressed', 'true');
    this.secondsSelect.disabled = true;
    this.status.dataset.state = 'recording';
    this.dot.hidden = false;
    this.host.viewer.invalidate();
  }

  /** Stops recording and saves what was recorded. */
  stop(): void {
    clearTimeout(this.stopTimer);
    if (this.recorder && this.recorder.state !== 'inactive') this.recorder.stop();
  }

  private frame(): void {
    if (!this.recorder) return;
    this.host.viewer.invalidate(); // keep frames coming into the capture stream
    const elapsed = (performance.now() - this.startedAt) / 1000;
    this.status.textContent = `● ${Math.floor(elapsed)} s${this.seconds ? ` of ${this.seconds} s` : ''}`;
  }

  private setIdle(): void {
    this.recordBtn.textContent = 'Record';
    this.recordBtn.setAttribute('aria-pressed', 'false');
    this.secondsSelect.disabled = false;
    this.status.dataset.state = 'idle';
    this.dot.hidden = true;
  }
}
