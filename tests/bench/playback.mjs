// Playback family: a CMU clip playing in Clip mode at both qualities, and long clips (10k and 100k frames).
import { corpusText, openPlayground } from '../support/browser.mjs';
import { displayFields, measureFrames, SECONDS, VIEWPORT, WARMUP_SECONDS } from './common.mjs';

/** Shows a real clip playing, warms up (shaders, dynamic resolution), then measures. */
async function playbackBenchmark(ctx, query) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url + query, VIEWPORT);
  try {
    const amc = corpusText('cmu/amc/16_11.amc.gz');
    const asf = corpusText('cmu/asf/16.asf');
    await page.evaluate(
      async ({ amc, asf }) => {
        const m = await window.playground.importMotion(amc, 'amc', asf);
        window.playground.show(m, '16_11.amc');
      },
      { amc, asf },
    );
    await page.waitForTimeout(WARMUP_SECONDS * 1000);
    const frames = await measureFrames(page, SECONDS, { clock: true });
    const state = await page.evaluate(() => window.playground.state());
    const stats = await page.evaluate(() => window.playground.stats());
    if (!state.playing) throw new Error('clip stopped playing during the benchmark');
    return {
      clip: 'cmu/amc/16_11 (31 joints, 120 fps)',
      viewport: `${VIEWPORT.width}x${VIEWPORT.height}`,
      ...frames,
      ...displayFields(stats, problems),
    };
  } finally {
    await context.close();
  }
}

/**
 * A long clip playing (default quality, trail and footprints on): CMU 16_11 (a walk, 120 fps) taken at
 * 30 fps and repeated end to end, each repetition starting where the last one ended (the root walks on
 * in a straight line), until `frames` frames; built in the page and shown with playground.show, which
 * detects its contacts (footprints). Warms up, then measures like playback-auto.
 */
async function longClipBenchmark(ctx, frames) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  try {
    const amc = corpusText('cmu/amc/16_11.amc.gz');
    const asf = corpusText('cmu/asf/16.asf');
    const built = await page.evaluate(
      async ({ amc, asf, frames }) => {
        const clip = await window.playground.importMotion(amc, 'amc', asf);
        const step = 4; // 120 → 30 fps
        const J = clip.joints.length, root = clip.parents.indexOf(-1), src = clip.positions;
        const lap = Math.floor(clip.frames / step);
        const at = (f, k) => src[(f * step * J + root) * 3 + k];
        const dx = at(lap - 1, 0) - at(0, 0), dz = at(lap - 1, 2) - at(0, 2);
        const positions = new Float32Array(frames * J * 3);
        for (let f = 0; f < frames; f++) {
          const n = Math.floor(f / lap), from = (f % lap) * step * J * 3, to = f * J * 3;
          for (let k = 0; k < J * 3; k += 3) {
            positions[to + k] = src[from + k] + n * dx;
            positions[to + k + 1] = src[from + k + 1];
            positions[to + k + 2] = src[from + k + 2] + n * dz;
          }
        }
        const started = performance.now();
        window.playground.show({ fps: clip.fps / step, frames, joints: clip.joints, parents: clip.parents, positions }, `16_11 ×${Math.ceil(frames / lap)}`);
        return { showMs: performance.now() - started, laps: frames / lap };
      },
      { amc, asf, frames },
    );
    await page.waitForTimeout(WARMUP_SECONDS * 1000);
    const measured = await measureFrames(page, SECONDS, { clock: true });
    const state = await page.evaluate(() => window.playground.state());
    const stats = await page.evaluate(() => window.playground.stats());
    if (!state.playing) throw new Error('clip stopped playing during the benchmark');
    return {
      clip: `cmu/amc/16_11 at 30 fps repeated ${built.laps.toFixed(1)}× (31 joints, ${frames} frames)`,
      viewport: `${VIEWPORT.width}x${VIEWPORT.height}`,
      show_ms: Math.round(built.showMs),
      ...measured,
      target_fps: 55,
      ...displayFields(stats, problems),
    };
  } finally {
    await context.close();
  }
}


/** The summary of a playback or long-clip result: display frame rate and the playback clock. */
function playbackSummary(r) {
  return (
    `${r.mean_fps} fps mean, p95 frame ${r.p95_frame_ms} ms, ${r.long_frames}/${r.frames} frames > 25 ms,` +
    ` playback ${r.playback_rate}× real time (target 1) — ${r.quality} quality at pixel ratio ${r.pixel_ratio}, ${r.viewport}`
  );
}

export const BENCHMARKS = [
  {
    name: 'playback-auto',
    description: 'one character playing, default quality (software GL → no MSAA, dynamic resolution)',
    run: (ctx) => playbackBenchmark(ctx, ''),
    summary: playbackSummary,
  },
  {
    name: 'playback-high',
    description: 'one character playing, ?quality=high (MSAA, full resolution unless too slow)',
    run: (ctx) => playbackBenchmark(ctx, '?quality=high'),
    summary: playbackSummary,
  },
  ...[10_000, 100_000].map((frames) => ({
    name: `long-clip-${frames / 1000}k`,
    description: `a ${frames.toLocaleString('en')}-frame clip playing (16_11 repeated, 30 fps), default quality, trail and footprints on — target ≥ 55 fps mean`,
    run: (ctx) => longClipBenchmark(ctx, frames),
    summary: playbackSummary,
  })),
];
