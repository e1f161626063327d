// The Clean up panel's joint-angle plot (after Wang, Chai, Xia, Fig. 11): one joint's bend angle over the clip, in
// degrees, for the input (grey), the cleaned motion (accent) and, when noise was added with the panel's tool, the
// clean original (dashed). A thin line (a separate element, moved without redrawing) marks the playhead.
//
// For tests the canvas carries data-input-points, data-cleaned-points and data-original-points (frames with an
// angle, per curve; 0 for a curve not drawn) and data-joint (the joint's name).

export interface AngleCurves {
  joint: string;
  fps: number;
  input: Float32Array;
  cleaned?: Float32Array;
  original?: Float32Array;
}

const INPUT = '#8c93a3';
const ORIGINAL = '#46d9a8';

const finiteCount = (a?: Float32Array) => (a ? a.reduce((n, v) => (Number.isFinite(v) ? n + 1 : n), 0) : 0);

export class AnglePlot {
  private curves: AngleCurves | null = null;
  private size = '';
  private frames = 0;
  /** The canvas's CSS width when last drawn (the playhead is placed by it without reading the layout). */
  private cssWidth = 0;

  constructor(private readonly canvas: HTMLCanvasElement, private readonly playhead: HTMLElement) {}

  set(curves: AngleCurves | null): void {
    this.curves = curves;
    this.frames = curves?.input.length ?? 0;
    const d = this.canvas.dataset;
    d.joint = curves?.joint ?? '';
    d.inputPoints = String(finiteCount(curves?.input));
    d.cleanedPoints = String(finiteCount(curves?.cleaned));
    d.originalPoints = String(finiteCount(curves?.original));
    this.size = '';
    this.draw();
  }

  /** Redraws when the curves changed or the canvas was resized (cheap to call when nothing did). */
  draw(): void {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(c.clientWidth * dpr));
    const h = Math.max(1, Math.round(c.clientHeight * dpr));
    const size = `${w}x${h}`;
    if (size === this.size || c.clientWidth === 0) return;
    this.size = size;
    this.cssWidth = c.clientWidth;
    if (c.width !== w || c.height !== h) {
      c.width = w;
      c.height = h;
    }
    this.render(w / dpr, h / dpr, dpr);
  }

  /** Moves the playhead line to `frame` (hidden with no curves). */
  setFrame(frame: number): void {
    const visible = this.frames > 1;
    this.playhead.hidden = !visible;
    if (!visible) return;
    const { left, width } = this.plotBox(this.cssWidth);
    this.playhead.style.transform = `translateX(${left + (width * Math.min(Math.max(frame, 0), this.frames - 1)) / (this.frames - 1)}px)`;
  }

  private plotBox(W: number): { left: number; width: number } {
    const left = 32, right = 8;
    return { left, width: Math.max(1, W - left - right) };
  }

  private render(W: number, H: number, dpr: number): void {
    const ctx = this.canvas.getContext('2d');
    if (!ctx) return;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    const curves = this.curves;
    if (!curves || curves.input.length < 2) return;
    const css = getComputedStyle(this.canvas);
    const colour = (name: string, fallback: string) => css.getPropertyValue(name).trim() || fallback;
    const muted = colour('--muted', '#8d97ad');
    const accent = colour('--accent-2', '#b3a8ff');

    const { left, width: pw } = this.plotBox(W);
    const top = 8, bottom = 16;
    const ph = H - top - bottom;
    const all = [curves.input, curves.cleaned, curves.original].filter((a): a is Float32Array => a !== undefined);
    let lo = Infinity, hi = -Infinity;
    for (const a of all) for (const v of a) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (!Number.isFinite(lo)) return;
    // Whole tens of degrees around the data, at least 20° tall.
    lo = Math.max(0, Math.floor(lo / 10) * 10);
    hi = Math.max(Math.ceil(hi / 10) * 10, lo + 20);
    const frames = curves.input.length;
    const x = (f: number) => left + (pw * f) / (frames - 1);
    const y = (v: number) => top + ph * (1 - (v - lo) / (hi - lo));

    ctx.font = '10px system-ui, sans-serif';
    ctx.fillStyle = muted;
    ctx.textAlign = 'right';
    ctx.fillText(`${hi}°`, left - 5, top + 7);
    ctx.fillText(`${lo}°`, left - 5, y(lo) + 3);
    ctx.strokeStyle = 'rgba(255, 255, 255, 0.14)';
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(left, top);
    ctx.lineTo(left, y(lo));
    ctx.lineTo(left + pw, y(lo));
    ctx.stroke();
    ctx.textAlign = 'left';
    ctx.fillText('0 s', left, H - 3);
    ctx.textAlign = 'right';
    ctx.fillText(`${((frames - 1) / curves.fps).toFixed(1)} s`, left + pw, H - 3);

    // At most about two points per pixel: long clips are drawn from every k-th frame.
    const step = Math.max(1, Math.floor(frames / (2 * pw)));
    const line = (values: Float32Array, stroke: string, widthPx: number, dash: number[] = []) => {
      ctx.strokeStyle = stroke;
      ctx.lineWidth = widthPx;
      ctx.lineJoin = 'round';
      ctx.setLineDash(dash);
      ctx.beginPath();
      let pen = false;
      for (let f = 0; f < frames; f += step) {
        const v = values[f];
        if (!Number.isFinite(v)) {
          pen = false;
          continue;
        }
        if (pen) ctx.lineTo(x(f), y(v));
        else ctx.moveTo(x(f), y(v));
        pen = true;
      }
      ctx.stroke();
      ctx.setLineDash([]);
    };
    line(curves.input, INPUT, 1.2);
    if (curves.original) line(curves.original, ORIGINAL, 1.2, [3, 3]);
    if (curves.cleaned) line(curves.cleaned, accent, 2);
  }
}
