// Character family (issue 40): Random walk drawn as the project's mannequin, against the stick figure, at both
// qualities. The goal is 60 fps with a 30k-vertex character; the mannequin's vertex count is reported.
import { openPlayground } from '../support/browser.mjs';
import { liveModeBenchmark, liveModeSummary, VIEWPORT } from './common.mjs';

/**
 * The time to draw one frame in each look, Random walk paused at full resolution: renders back to back, each
 * ended by a one-pixel readPixels (which waits for the GPU process to finish the frame), so it is the drawing
 * alone, not the display's frame rate that a loaded machine also moves. Reaches into the element's viewer (bench
 * only: no API draws a frame on demand).
 */
async function renderCostBenchmark(ctx, query = '') {
  const { context, page, problems } = await openPlayground(ctx.browser, `${ctx.url}?mode=walk&resolution=full${query}`, VIEWPORT);
  try {
    await page.waitForFunction(() => (window.playground.current()?.frames ?? 0) > 20, null, { timeout: 120_000 });
    const ms = await page.evaluate(() => {
      window.playground.pause();
      const viewer = document.querySelector('motion-playground').app.viewer;
      const gl = viewer.renderer.getContext(), pixel = new Uint8Array(4);
      const draw = () => {
        viewer.renderNow();
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      };
      const out = { skeleton: [], character: [], both: [] };
      for (let round = 0; round < 3; round++) {
        for (const look of Object.keys(out)) {
          window.playground.setView({ look });
          draw(); // the first frame of a look compiles what it needs
          const started = performance.now();
          for (let i = 0; i < 10; i++) draw();
          out[look].push((performance.now() - started) / 10);
        }
      }
      // The median of the three rounds (rounds alternate looks, so a busy moment hits every look alike).
      return Object.fromEntries(Object.entries(out).map(([look, v]) => [look, +v.sort((a, b) => a - b)[1].toFixed(2)]));
    });
    const stats = await page.evaluate(() => window.playground.stats());
    return {
      viewport: `${VIEWPORT.width}x${VIEWPORT.height}`,
      skeleton_ms: ms.skeleton,
      character_ms: ms.character,
      both_ms: ms.both,
      character_vertices: stats.look === 'both' ? stats.characterVertices : undefined,
      pixel_ratio: +stats.pixelRatio.toFixed(3),
      quality: stats.quality,
      renderer: stats.renderer,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

const renderSummary = (r) =>
  `one frame drawn in ${r.skeleton_ms} ms as the stick figure, ${r.character_ms} ms as the character, ${r.both_ms} ms both — ${r.quality} quality, ${r.character_vertices} character vertices, pixel ratio ${r.pixel_ratio}, ${r.viewport}`;

const summary = (r) => `${liveModeSummary(r)}, look ${r.look}, ${r.character_vertices} character vertices`;

export const BENCHMARKS = [
  {
    name: 'random-walk-character',
    description: 'Random walk drawn as the mannequin (the default look), default quality (software GL: matcap shading, blob shadow) — target 60 fps',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status', undefined, '?look=character'),
    summary,
  },
  {
    name: 'random-walk-character-high',
    description: 'Random walk drawn as the mannequin, ?quality=high (lit, shadow map, MSAA) — target 60 fps with a GPU',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status', undefined, '?look=character&quality=high'),
    summary,
  },
  {
    name: 'character-render-ms',
    description: 'the time to draw one frame of paused Random walk in each look, default quality, full resolution (drawing only, robust to a loaded machine)',
    run: (ctx) => renderCostBenchmark(ctx),
    summary: renderSummary,
  },
  {
    name: 'character-render-ms-high',
    description: 'the same at ?quality=high (the lit mannequin with its shadow map, MSAA)',
    run: (ctx) => renderCostBenchmark(ctx, '&quality=high'),
    summary: renderSummary,
  },
  {
    name: 'random-walk-skeleton',
    description: 'Random walk drawn as the stick figure (?look=skeleton), default quality: the baseline for the two above',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status', undefined, '?look=skeleton'),
    summary,
  },
];
