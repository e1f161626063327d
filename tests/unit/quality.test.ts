// Rendering quality (web/viewer/quality.ts): the quality tier from the GL renderer and the URL, and the
// dynamic resolution's steps down and back up.
import { describe, expect, it } from 'vitest';
import { chooseQuality, DynamicResolution, fixedResolution } from '../../web/viewer/quality';

describe('DynamicResolution', () => {
  it('steps down when slow, back up when calm, never straight back', () => {
    const r = new DynamicResolution(0.5, 1, 1);
    let now = 0;
    const run = (fps: number, seconds: number) => {
      let changed = 0;
      for (let i = 0; i < fps * seconds; i++) {
        now += 1000 / fps;
        if (r.sample(1 / fps, now)) changed++;
      }
      return changed;
    };
    run(60, 3);
    expect(r.scale, 'fast enough: full resolution').toBe(1);
    run(30, 1.1);
    expect(r.scale, 'slow: scaled down').toBeLessThan(1);
    const low = r.scale;
    run(30, 10);
    expect(r.scale, 'keeps stepping down to the floor').toBe(0.5);
    run(60, 6);
    expect(r.scale, 'for a while, not back up to a level that was just too slow').toBe(0.5);
    run(60, 12);
    expect(r.scale, 'then recovers step by step').toBeGreaterThan(0.5);
    expect(r.scale).toBeLessThan(low);
    run(60, 60);
    expect(r.scale, 'eventually back to full').toBe(1);
  });

  it('stays at full resolution when fixed', () => {
    const fixed = new DynamicResolution(0.5, 1, 0.75, true);
    expect(fixed.scale).toBe(1);
    expect(fixed.sample(1 / 10, 5000)).toBe(false);
    expect(fixed.scale).toBe(1);
  });

  it('ignores stalls (a hidden tab, loading)', () => {
    const r = new DynamicResolution(0.5, 1, 1);
    let now = 0;
    for (let i = 0; i < 20; i++) expect(r.sample(0.5, (now += 500))).toBe(false);
    expect(r.scale).toBe(1);
  });
});

describe('quality tier', () => {
  it('software GL gets low quality unless the URL says otherwise', () => {
    expect(chooseQuality({ renderer: 'x', software: true }, '')).toBe('low');
    expect(chooseQuality({ renderer: 'x', software: false }, '')).toBe('high');
    expect(chooseQuality({ renderer: 'x', software: true }, '?quality=high')).toBe('high');
    expect(chooseQuality({ renderer: 'x', software: false }, '?quality=low')).toBe('low');
  });

  it('?resolution=full pins the resolution', () => {
    expect(fixedResolution('?resolution=full')).toBe(true);
    expect(fixedResolution('')).toBe(false);
  });
});
