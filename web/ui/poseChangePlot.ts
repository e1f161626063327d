// The Dance mode's live plot (after Zhou et al., Fig. 2): pose change per second of the generated
// dance (mean joint speed relative to the root, m/s), with the real dance's median for the style and
// the freeze line at 20 % of it. A second is drawn once the playhead has passed it.
//
// For tests the canvas carries data-seconds (seconds drawn) and data-last (the last one's value, m/s).

/** A dance counts as frozen in a second whose pose change is below this fraction of the real median (docs/models/aclstm.md). */
export const FREEZE_FRACTION = 0.2;
/** Seconds shown at once. */
const WINDOW = 30;

interface Second {
  /** Seconds since the dance started. */
  index: number;
  value: number;
  /** Stream frame at which the second is complete. */
  endFrame: number;
}

export class PoseChangePlot {
  private seconds: Second[] = [];
  private total = 0;
  private median = 0;
  private shown = -1;
  private size = '';

  constructor(private readonly canvas: HTMLCanvasElement) {}

  /** A new dance, compared with real dance whose median pose change is `median` (m/s). */
  reset(median: number): void {
    this.seconds = [];
    this.total = 0;
    this.median = median;
    this.shown = -1;
  }

  /** Adds measured seconds; `endFrames[i]` is the stream frame that completes `values[i]`. */
  add(values: number[], endFrames: number[]): void {
    values.forEach((value, i) => this.seconds.push({ index: this.total++, value, endFrame: endFrames[i] }));
    // Bounded for hours: only the window (and a little slack) is kept.
    if (this.seconds.length > 4 * WINDOW) this.seconds.splice(0, this.seconds.length - 2 * WINDOW);
  }

  /** Redraws if the playhead (stream frame) has completed another second or the canvas was resized. */
  draw(playhead: number): void {
    let n = this.seconds.length;
    while (n > 0 && this.seconds[n - 1].endFrame > playhead) n--;
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(c.clientWidth * dpr));
    const h = Math.max(1, Math.round(c.clientHeight * dpr));
    const size = `${w}x${h}`;
    if (n === this.shown && size === this.size) return;
    this.shown = n;
    this.size = size;
    if (c.width !== w || c.height !== h) {
      c.width = w;
      c.height = h;
    }
    const visible = this.seconds.slice(Math.max(0, n - WINDOW), n);
    c.dataset.seconds = String(visible.length);
    c.dataset.last = visible.length ? visible[visible.length - 1].value.toFixed(4) : '';
    this.render(visible, w / dpr, h / dpr, dpr);
  }

  private render(visible: Second[], W: number, H: number, dpr: number): void {
    const ctx = this.canvas.getContext('2d');
    if (!ctx) return;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    const css = getComputedStyle(this.canvas);
    const colour = (name: string, fallback: string) => css.getPropertyValue(name).trim() || fallback;
    const text = colour('--text', '#e8ecf4');
    const muted = colour('--muted', '#8d97ad');
    const accent = colour('--accent-2', '#b3a8ff');
    const danger = colour('--danger', '#ff5d6c');
    const freeze = FREEZE_FRACTION * this.median;

    const left = 30, right = 8, top = 22, bottom = 16;
    const pw = W - left - right, ph = H - top - bottom;
    const yMax = Math.max(this.median * 1.6, ...visible.map((s) => s.value * 1.1), 0.1);
    const y = (v: number) => top + ph * (1 - Math.min(v, yMax) / yMax);
    const x = (i: number) => left + (pw * (i + 0.5)) / WINDOW;

    ctx.font = '600 11px system-ui, sans-serif';
    ctx.textBaseline = 'alphabetic';
    ctx.fillStyle = text;
    ctx.textAlign = 'left';
    ctx.fillText('pose change per second', 2, 13);
    const last = visible[visible.length - 1];
    if (last) {
      ctx.textAlign = 'right';
      ctx.fillStyle = last.value < freeze ? danger : text;
      ctx.fillText(`${last.value.toFixed(2)} m/s${last.value < freeze ? ' · frozen' : ''}`, W - 2, 13);
    }

    // Axes: 0 and the top value, seconds along the bottom.
    ctx.font = '10px system-ui, sans-serif';
    ctx.fillStyle = muted;
    ctx.textAlign = 'right';
    ctx.fillText('0', left - 5, y(0) + 3);
    ctx.fillText(yMax.toFixed(1), left - 5, top + 7);
    ctx.strokeStyle = 'rgba(255, 255, 255, 0.14)';
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(left, top);
    ctx.lineTo(left, y(0));
    ctx.lineTo(left + pw, y(0));
    ctx.stroke();
    const first = visible.length ? visible[0].index : 0;
    ctx.textAlign = 'left';
    ctx.fillText(`${first} s`, left, H - 3);
    ctx.textAlign = 'right';
    ctx.fillText(`${first + WINDOW} s`, left + pw, H - 3);

    // Real median and the freeze line, labelled at the right.
    const reference = (v: number, stroke: string, label: string) => {
      ctx.strokeStyle = stroke;
      ctx.setLineDash([4, 4]);
      ctx.beginPath();
      ctx.moveTo(left, y(v));
      ctx.lineTo(left + pw, y(v));
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = stroke;
      ctx.textAlign = 'right';
      ctx.fillText(label, left + pw, y(v) - 3);
    };
    reference(this.median, muted, `real median ${this.median.toFixed(2)}`);
    reference(freeze, danger, `freeze (${Math.round(FREEZE_FRACTION * 100)} %)`);

    if (!visible.length) return;
    ctx.strokeStyle = accent;
    ctx.lineWidth = 2;
    ctx.lineJoin = 'round';
    ctx.beginPath();
    visible.forEach((s, i) => (i === 0 ? ctx.moveTo(x(i), y(s.value)) : ctx.lineTo(x(i), y(s.value))));
    ctx.stroke();
    visible.forEach((s, i) => {
      ctx.fillStyle = s.value < freeze ? danger : accent;
      ctx.beginPath();
      ctx.arc(x(i), y(s.value), 2.5, 0, 2 * Math.PI);
      ctx.fill();
    });
  }
}
