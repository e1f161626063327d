// Clean-up family (issue 16): playground.denoise with each method on a 10 s held-out walk.
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { corpusText, openPlayground, ROOT } from '../support/browser.mjs';
import { VIEWPORT } from './common.mjs';

// Clean-up speed (issue 16): a held-out CMU walk of the generator (generator.json training.valid_files), cut
// to exactly 10 s, made noisy, then cleaned with each method.
const CLEANUP_CLIP = { amc: 'cmu/amc/105_15.amc.gz', asf: 'cmu/asf/105.asf', startFrame: 0, frames: 1200, fps: 120 };
const CLEANUP_METHODS = ['map', 'manifold', 'lowpass'];
const CLEANUP_NOISE = { jitter: 0.03, outliers: 0.01, seed: 1 };
const CLEANUP_TARGET_REALTIME = 2;

/**
 * playground.denoise on a 10 s clip, per method: one warm-up call (loads the model), then `runs` timed calls.
 * Wall time is performance.now() in the page around the awaited denoise (request, worker, structured clones);
 * compute is the worker's own stats.computeMs. × real time = clip seconds / wall seconds. PASS when the
 * slowest timed call is still ≥ 2× real time.
 */
async function cleanupBenchmark(ctx, { runs = 3 } = {}) {
  const valid = JSON.parse(readFileSync(path.join(ROOT, 'public/models/generator.json'), 'utf8')).training.valid_files;
  if (!valid.includes(CLEANUP_CLIP.amc)) throw new Error(`${CLEANUP_CLIP.amc} is not among the generator's held-out files`);
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  try {
    const amc = corpusText(CLEANUP_CLIP.amc);
    const asf = corpusText(CLEANUP_CLIP.asf);
    const r = await page.evaluate(
      async ({ amc, asf, cut, methods, noise, runs }) => {
        const pg = window.playground;
        const full = await pg.importMotion(amc, 'amc', asf);
        if (full.fps !== cut.fps) throw new Error(`clip is at ${full.fps} fps, expected ${cut.fps}`);
        if (full.frames < cut.startFrame + cut.frames) throw new Error(`clip has ${full.frames} frames, fewer than ${cut.startFrame + cut.frames}`);
        const J = full.joints.length;
        const clip = {
          fps: full.fps,
          frames: cut.frames,
          joints: full.joints,
          parents: full.parents,
          positions: full.positions.slice(cut.startFrame * J * 3, (cut.startFrame + cut.frames) * J * 3),
        };
        const noisy = pg.addNoise(clip, noise);
        const out = { joints: J, sourceFrames: full.frames, methods: {} };
        for (const method of methods) {
          const timed = async () => {
            const started = performance.now();
            const m = await pg.denoise(noisy, { method });
            const wallMs = performance.now() - started;
            if (m.frames !== cut.frames) throw new Error(`denoise ${method} returned ${m.frames} frames, expected ${cut.frames}`);
            return { wallMs, computeMs: m.stats.computeMs };
          };
          const warmup = await timed();
          const calls = [];
          for (let i = 0; i < runs; i++) calls.push(await timed());
          out.methods[method] = { warmup, calls };
        }
        return out;
      },
      { amc, asf, cut: CLEANUP_CLIP, methods: CLEANUP_METHODS, noise: CLEANUP_NOISE, runs },
    );
    const seconds = CLEANUP_CLIP.frames / CLEANUP_CLIP.fps;
    const median = (xs) => {
      const s = [...xs].sort((a, b) => a - b);
      return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
    };
    const rows = CLEANUP_METHODS.map((method) => {
      const { warmup, calls } = r.methods[method];
      const wall = calls.map((c) => c.wallMs), compute = calls.map((c) => c.computeMs);
      const factors = wall.map((ms) => seconds / (ms / 1000));
      const row = {
        method,
        warmup_wall_ms: Math.round(warmup.wallMs),
        wall_ms: wall.map((x) => Math.round(x)),
        compute_ms: compute.map((x) => Math.round(x)),
        wall_ms_min: Math.round(Math.min(...wall)),
        wall_ms_median: Math.round(median(wall)),
        compute_ms_min: Math.round(Math.min(...compute)),
        compute_ms_median: Math.round(median(compute)),
        realtime_min: +Math.min(...factors).toFixed(2),
        realtime_median: +median(factors).toFixed(2),
      };
      return { ...row, pass: row.realtime_min >= CLEANUP_TARGET_REALTIME };
    });
    const c = CLEANUP_CLIP;
    return {
      clip: `${c.amc} (held out), frames ${c.startFrame}–${c.startFrame + c.frames - 1} of ${r.sourceFrames} at ${c.fps} fps = ${seconds} s, ${r.joints} joints`,
      noise: CLEANUP_NOISE,
      runs,
      target_realtime: CLEANUP_TARGET_REALTIME,
      rows,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

/** The cleanup benchmark's table (markdown, indented for the summary). */
function cleanupTable(r) {
  const lines = [
    '    | method | wall ms min / median | worker computeMs min / median | × real time min / median | ≥ 2× (slowest call) | warm-up wall ms (loads the model) |',
    '    |---|---|---|---|---|---|',
  ];
  for (const x of r.rows) {
    lines.push(
      `    | ${x.method} | ${x.wall_ms_min} / ${x.wall_ms_median} | ${x.compute_ms_min} / ${x.compute_ms_median} | ${x.realtime_min} / ${x.realtime_median} | ${x.pass ? 'PASS' : 'FAIL'} | ${x.warmup_wall_ms} |`,
    );
  }
  return lines.join('\n');
}

export const BENCHMARKS = [
  {
    name: 'cleanup',
    description: 'playground.denoise (map, manifold, lowpass) on a 10 s held-out CMU walk with 3 cm jitter + 1% outliers: one warm-up call, then 3 timed — target ≥ 2× real time (issue 16)',
    run: (ctx) => cleanupBenchmark(ctx),
    summary: (r) =>
      `${r.rows.map((x) => `${x.method} ${x.realtime_min}× real time (slowest of ${r.runs}) ${x.pass ? 'PASS' : 'FAIL'}`).join(', ')} (target ≥ ${r.target_realtime}×)` +
      `\n    clip: ${r.clip}; noise ${JSON.stringify(r.noise)}\n${cleanupTable(r)}`,
  },
];
