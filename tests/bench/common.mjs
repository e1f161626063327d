// What the benchmark families share: the measuring windows and viewport, display frame timing, a model client's
// raw step rate, a live mode's display and stream rate, and the summary line of a live mode.
import { openPlayground } from '../support/browser.mjs';

export const SECONDS = Number(process.env.BENCH_SECONDS ?? 5);
export const WARMUP_SECONDS = Number(process.env.BENCH_WARMUP ?? 4);
export const VIEWPORT = { width: 1280, height: 720 };

/**
 * Display frame timing in the page: rAF intervals over `seconds`. With `clock`, also the playback
 * clock's rate against the page's clock: playback seconds advanced per second (unwrapped at the loop
 * point, times the speed's inverse; 1 = real time), sampled at every display frame.
 */
export async function measureFrames(page, seconds, { clock = false } = {}) {
  const { stamps: t, playback } = await page.evaluate(
    ({ ms, clock }) =>
      new Promise((resolve) => {
        const stamps = [];
        const start = performance.now();
        let advanced = 0, last = null, first = null, end = null;
        const step = (now) => {
          stamps.push(now);
          if (clock) {
            const s = window.playground.state();
            const duration = s.frames > 1 ? (s.frames - 1) / s.fps : 0;
            if (last) advanced += (s.time >= last.time ? s.time - last.time : s.time + duration - last.time) / s.speed;
            last = s;
            first ??= now;
            end = now;
          }
          if (now - start < ms) requestAnimationFrame(step);
          else resolve({ stamps, playback: clock ? advanced / ((end - first) / 1000) : undefined });
        };
        requestAnimationFrame(step);
      }),
    { ms: seconds * 1000, clock },
  );
  const dts = [];
  for (let i = 1; i < t.length; i++) dts.push(t[i] - t[i - 1]);
  const sorted = [...dts].sort((a, b) => a - b);
  const pct = (p) => sorted[Math.min(sorted.length - 1, Math.floor((p / 100) * sorted.length))];
  const span = t[t.length - 1] - t[0];
  return {
    frames: dts.length,
    mean_fps: +(dts.length / (span / 1000)).toFixed(2),
    mean_frame_ms: +(span / dts.length).toFixed(2),
    p50_frame_ms: +pct(50).toFixed(2),
    p95_frame_ms: +pct(95).toFixed(2),
    p99_frame_ms: +pct(99).toFixed(2),
    max_frame_ms: +sorted[sorted.length - 1].toFixed(2),
    long_frames: dts.filter((d) => d > 25).length, // > 1.5 refresh intervals at 60 Hz
    ...(clock ? { playback_rate: +playback.toFixed(3), target_playback_rate: 1 } : {}),
  };
}


/**
 * Raw step throughput of a model client (`client`: its module, export and options) via its `benchmark`,
 * in a page opened with `?threads=N` in Clip mode with nothing loaded (so no Random walk streams beside it). With
 * `generate`, also the end-to-end rate of `generate` (steps, decoding and, for the dance models, the skeleton fit)
 * after a short warm-up call.
 */
export async function modelBenchmark(ctx, { client, threads, batch, steps, generate }) {
  const { context, page, problems } = await openPlayground(ctx.browser, `${ctx.url}?mode=clip&threads=${threads}`, VIEWPORT);
  try {
    const r = await page.evaluate(
      async ({ client, threads, batch, steps, generate }) => {
        const module = await import(client.module);
        const c = new module[client.name]({ ...client.options, threads });
        try {
          const info = await c.init();
          await c.benchmark(batch, Math.min(100, steps)); // warm-up
          const b = await c.benchmark(batch, steps);
          let generateFps;
          if (generate) {
            await c.generate({ ...generate, frames: 60 });
            const started = performance.now();
            await c.generate(generate);
            generateFps = (generate.frames * 1000) / (performance.now() - started);
          }
          return { ...b, loadMs: info.loadMs, generateFps, isolated: globalThis.crossOriginIsolated };
        } finally {
          c.dispose();
        }
      },
      { client, threads, batch, steps, generate },
    );
    return {
      threads: r.threads,
      threads_requested: threads,
      isolated: r.isolated,
      batch: r.batch,
      steps: r.steps,
      steps_per_s: Math.round(r.stepsPerSecond),
      ms_per_call: +r.msPerCall.toFixed(3),
      particle_steps_per_s: Math.round(r.particleStepsPerSecond),
      ...(r.generateFps === undefined ? {} : { generate_frames: generate.frames, generate_frames_per_s: Math.round(r.generateFps) }),
      load_ms: Math.round(r.loadMs),
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}


/**
 * Display frame rate while a live mode streams (default threads), plus how far its stream got per second.
 * `model`: Steer mode's model choice (#steer-model) to set first.
 */
export async function liveModeBenchmark(ctx, button, statusId, model, query = '') {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url + query, VIEWPORT);
  const streamFrame = () => page.evaluate((id) => Number($ui(id).dataset.frame), statusId);
  try {
    await page.click(button);
    if (model) {
      await page.selectOption('#steer-model', model); // restarts the stream with that model
      await page.waitForFunction((m) => $ui('steer-status').dataset.model === m, model, { timeout: 60_000 });
    }
    await page.waitForFunction((id) => Number($ui(id).dataset.frame) > 0, statusId, { timeout: 60_000 });
    await page.waitForTimeout(WARMUP_SECONDS * 1000);
    const f0 = await streamFrame();
    const frames = await measureFrames(page, SECONDS);
    const f1 = await streamFrame();
    const stats = await page.evaluate(() => window.playground.stats());
    const modelFps = await page.evaluate(() => window.playground.current().fps);
    return {
      viewport: `${VIEWPORT.width}x${VIEWPORT.height}`,
      ...frames,
      target_fps: 60,
      stream_frames_per_s: +((f1 - f0) / SECONDS).toFixed(1),
      target_stream_frames_per_s: modelFps, // the stream keeps up with real time
      look: stats.look,
      character_vertices: stats.characterVertices,
      ...displayFields(stats, problems),
    };
  } finally {
    await context.close();
  }
}

/** What every display benchmark reports about the renderer and page health. */
export function displayFields(stats, problems) {
  return {
    pixel_ratio: +stats.pixelRatio.toFixed(3),
    quality: stats.quality,
    renderer: stats.renderer,
    page_errors: problems.length,
  };
}


/** The summary of a liveModeBenchmark result. */
export function liveModeSummary(r) {
  return (
    `${r.mean_fps} fps mean (target 60), p95 frame ${r.p95_frame_ms} ms, ${r.long_frames}/${r.frames} frames > 25 ms,` +
    ` stream ${r.stream_frames_per_s} frames/s (target ${r.target_stream_frames_per_s}) — ${r.quality} quality at pixel ratio ${r.pixel_ratio}`
  );
}
