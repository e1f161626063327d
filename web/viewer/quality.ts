// Rendering quality: software-GL detection and dynamic resolution.
//
// Under software GL (SwiftShader in headless Chromium, llvmpipe on GPU-less Linux) every pixel is
// expensive: the viewer turns MSAA off there and lets the render resolution float so the display keeps
// its refresh rate. With a GPU it renders with MSAA at up to 2× device pixels, still scaling down if a
// weak GPU cannot keep up. `?quality=high|low|auto` in the page URL overrides the choice, and
// `?resolution=full` turns the dynamic resolution off.

export type Quality = 'high' | 'low';

export interface GLInfo {
  renderer: string;
  software: boolean;
}

const SOFTWARE = /swiftshader|llvmpipe|softpipe|software|basic render|mesa offscreen/i;

/** Renderer string of the browser's WebGL2 implementation (a throwaway context). */
export function probeGL(): GLInfo {
  let renderer = 'unknown';
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (gl) {
      const ext = gl.getExtension('WEBGL_debug_renderer_info');
      renderer = String(gl.getParameter(ext ? ext.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
      gl.getExtension('WEBGL_lose_context')?.loseContext();
    }
  } catch {
    // keep "unknown"
  }
  return { renderer, software: SOFTWARE.test(renderer) };
}

/** `?resolution=full` pins the render resolution (reproducible screenshots); otherwise it floats. */
export function fixedResolution(search = location.search): boolean {
  return new URLSearchParams(search).get('resolution') === 'full';
}

export function chooseQuality(gl: GLInfo, search = location.search): Quality {
  const q = new URLSearchParams(search).get('quality');
  if (q === 'high' || q === 'low') return q;
  return gl.software ? 'low' : 'high';
}

/**
 * Adjusts a render scale (fraction of the full pixel ratio) from measured frame intervals: down by 15%
 * when a one-second window runs clearly below the display's refresh rate, back up by 12% after a few
 * calm seconds, never straight back to a scale that was just too slow.
 */
export class DynamicResolution {
  scale: number;
  private acc = 0;
  private frames = 0;
  private refresh = 60;
  private lastChange = 0;
  private ceiling = Infinity;
  private ceilingUntil = 0;

  constructor(readonly min: number, readonly max: number, start: number, private readonly fixed = false) {
    this.scale = fixed ? max : Math.min(Math.max(start, min), max);
  }

  /** Feeds one frame interval (seconds) at time `now` (ms); returns true when the scale changed. */
  sample(dt: number, now: number): boolean {
    if (this.fixed || !(dt > 0) || dt > 0.25) return false; // stalls (hidden tab, loading) say nothing about rendering
    this.acc += dt;
    this.frames++;
    if (this.acc < 1) return false;
    const fps = this.frames / this.acc;
    this.acc = 0;
    this.frames = 0;
    // The display's refresh rate is the best rate seen (about 60 on most screens, 120+ on some).
    this.refresh = Math.max(Math.min(fps, 240), this.refresh * 0.999);
    if (fps < this.refresh * 0.88 && this.scale > this.min) {
      this.ceiling = this.scale;
      this.ceilingUntil = now + 15_000;
      this.scale = Math.max(this.min, this.scale * 0.85);
      this.lastChange = now;
      return true;
    }
    if (fps >= this.refresh * 0.97 && this.scale < this.max && now - this.lastChange > 3000) {
      const next = Math.min(this.max, this.scale * 1.12);
      if (now < this.ceilingUntil && next >= this.ceiling) return false;
      this.scale = next;
      this.lastChange = now;
      return true;
    }
    return false;
  }
}
