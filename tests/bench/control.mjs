// Control family: path following on the five benchmark paths (the generator with the MAP optimiser, the latent ERD,
// the VAE-LSTM), the live control loop's compute per frame, Steer mode's display with each streaming model, and
// Steer mode's keys.
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { openPlayground, ROOT } from '../support/browser.mjs';
import { liveModeBenchmark, liveModeSummary, VIEWPORT } from './common.mjs';

const BENCHMARK_PATHS = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/benchmark_paths.json'), 'utf8')).paths;

/** followPath on each benchmark path (walk, seed 0): optimisation time against the motion's duration. */
async function pathFollowBenchmark(ctx) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  try {
    const rows = {};
    // Warm-up (model load, first wasm calls), as the raw-step benchmarks do.
    await page.evaluate(() => window.playground.followPath({ points: [[0, 0], [0, 1]], seed: 0 }));
    for (const [name, { points }] of Object.entries(BENCHMARK_PATHS)) {
      const r = await page.evaluate(async (points) => {
        const m = await window.playground.followPath({ points, gait: 'walk', seed: 0 });
        return { seconds: m.frames / m.fps, optimizeMs: m.stats.optimizeMs };
      }, points);
      rows[name] = +((r.seconds * 1000) / r.optimizeMs).toFixed(2);
    }
    return { realtime_factor: rows, least_realtime_factor: Math.min(...Object.values(rows)), target_realtime_factor: 2, page_errors: problems.length };
  } finally {
    await context.close();
  }
}

/** The models path following is compared over (followPath's `model`): the latent ERD and the generator with the MAP optimiser. */
const PATH_MODELS = ['latent-erd', 'generator'];
const VAE_PATH_MODELS = ['vae-lstm', 'latent-erd', 'generator'];

/**
 * followPath on each benchmark path (walk, seed 0) with the latent ERD and, in the same run, the generator
 * (the default model): path error, progress, motion and compute time, × real time, and the feet's skating and sliding
 * after the foot lock (stats.skating: mean planted-toe speed; stats.sliding: the lowest foot point near the floor).
 */
async function pathModelsBenchmark(ctx, models = PATH_MODELS) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  try {
    // Warm-up of the models (load, first wasm calls), as the raw-step benchmarks do.
    for (const model of models) await page.evaluate((model) => window.playground.followPath({ model, points: [[0, 0], [0, 1]], seed: 0 }), model);
    const rows = [];
    for (const [name, { points }] of Object.entries(BENCHMARK_PATHS)) {
      for (const model of models) {
        const r = await page.evaluate(
          async ({ points, model }) => {
            const m = await window.playground.followPath({ model, points, gait: 'walk', seed: 0 });
            return { seconds: m.frames / m.fps, ...m.stats };
          },
          { points, model },
        );
        rows.push({
          path: name,
          model,
          mean_error_m: +r.meanError.toFixed(3),
          max_error_m: +r.maxError.toFixed(3),
          progress: +r.arcProgress.toFixed(3),
          motion_s: +r.seconds.toFixed(2),
          compute_s: +(r.optimizeMs / 1000).toFixed(2),
          realtime_factor: +((r.seconds * 1000) / r.optimizeMs).toFixed(1),
          skating_m_per_s: +r.skating.toFixed(3),
          skating_before_lock_m_per_s: +r.skatingBeforeLock.toFixed(3),
          sliding_m_per_s: +r.sliding.toFixed(3),
          sliding_before_lock_m_per_s: +r.slidingBeforeLock.toFixed(3),
        });
      }
    }
    const summary = Object.fromEntries(
      models.map((model) => {
        const g = rows.filter((r) => r.model === model);
        return [model, {
          mean_error_m: +(g.reduce((a, r) => a + r.mean_error_m, 0) / g.length).toFixed(3),
          worst_mean_error_m: Math.max(...g.map((r) => r.mean_error_m)),
          worst_max_error_m: Math.max(...g.map((r) => r.max_error_m)),
          least_progress: Math.min(...g.map((r) => r.progress)),
          least_realtime_factor: Math.min(...g.map((r) => r.realtime_factor)),
          mean_skating_m_per_s: +(g.reduce((a, r) => a + r.skating_m_per_s, 0) / g.length).toFixed(3),
          mean_sliding_m_per_s: +(g.reduce((a, r) => a + r.sliding_m_per_s, 0) / g.length).toFixed(3),
        }];
      }),
    );
    const targets = { 'vae-lstm': { mean_error_m: 0.1, realtime_factor: 100 }, 'latent-erd': { mean_error_m: 0.15, progress: 0.95, realtime_factor: 20 }, generator: { mean_error_m: 0.1, progress: 0.95, realtime_factor: 2 } };
    return { rows, summary, targets, page_errors: problems.length };
  } finally {
    await context.close();
  }
}

/** The models' rows of a paths benchmark side by side (in the order of `models`), one line per path. */
function latentPathsTable(r, models = PATH_MODELS) {
  const cols = ['mean error (m)', 'max error (m)', 'progress', 'motion (s)', 'compute (s)', '× real time', 'skating (m/s)', 'sliding, lowest point (m/s)'];
  const keys = ['mean_error_m', 'max_error_m', 'progress', 'motion_s', 'compute_s', 'realtime_factor', 'skating_m_per_s', 'sliding_m_per_s'];
  const lines = [`    | path | ${cols.map((c) => `${c}: ${models.join(' / ')}`).join(' | ')} |`, `    |---|${cols.map(() => '---').join('|')}|`];
  for (const name of Object.keys(BENCHMARK_PATHS)) {
    const found = models.map((model) => r.rows.find((x) => x.path === name && x.model === model));
    if (found.some((x) => !x)) continue;
    lines.push(`    | ${name} | ${keys.map((k) => found.map((x) => x[k]).join(' / ')).join(' | ')} |`);
  }
  return lines.join('\n');
}

/** simulateControl (the live loop, scripted): compute per model frame while turning and changing speed. */
async function liveControlBenchmark(ctx) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  try {
    const ms = await page.evaluate(async () => {
      await window.playground.simulateControl({ seconds: 0.5, schedule: [{ t: 0, speed: 1, heading: 0 }], seed: 0 }); // warm-up
      const schedule = [{ t: 0, speed: 1.2, heading: 0 }, { t: 2, speed: 1.5, heading: Math.PI / 2 }, { t: 4, speed: 0.8, heading: -Math.PI / 2 }];
      const m = await window.playground.simulateControl({ seconds: 6, schedule, seed: 0 });
      return Array.from(m.computeMs);
    });
    const sorted = [...ms].sort((a, b) => a - b);
    const pct = (p) => +sorted[Math.min(sorted.length - 1, Math.floor((p / 100) * sorted.length))].toFixed(2);
    return { frames: ms.length, p50_ms_per_frame: pct(50), p95_ms_per_frame: pct(95), max_ms_per_frame: +sorted.at(-1).toFixed(2), target_p95_ms: 33, page_errors: problems.length };
  } finally {
    await context.close();
  }
}

/**
 * Steer mode's keys against the page's clock: ← held for about a second turns the target heading, ↑
 * held for about half a second raises the target speed. The rates use the key events' own times in the
 * page and the readout after the release (it refreshes every 100 ms).
 */
async function steerKeysBenchmark(ctx) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  const readout = () =>
    page.evaluate(
      () =>
        new Promise((resolve) => {
          const el = $ui('steer-readout');
          const observer = new MutationObserver(() => {
            observer.disconnect();
            resolve({ heading: Number(el.dataset.targetHeading), speed: Number(el.dataset.targetSpeed) });
          });
          observer.observe(el, { attributes: true });
        }),
    );
  /** Holds `key` for about `ms`; returns the seconds between its keydown and keyup in the page. */
  const hold = async (key, ms) => {
    await page.evaluate(() => {
      window.keyTimes = {};
      document.addEventListener('keydown', (e) => (window.keyTimes.down ??= e.timeStamp), { once: true });
      document.addEventListener('keyup', (e) => (window.keyTimes.up = e.timeStamp), { once: true });
    });
    await page.keyboard.down(key);
    await page.waitForTimeout(ms);
    await page.keyboard.up(key);
    const { down, up } = await page.evaluate(() => window.keyTimes);
    return (up - down) / 1000;
  };
  try {
    await page.click('#mode-steer');
    await page.waitForFunction(() => Number($ui('steer-status').dataset.frame) > 15, null, { timeout: 120_000 });
    const a = await readout();
    const turnSeconds = await hold('ArrowLeft', 1000);
    const b = await readout();
    const speedSeconds = await hold('ArrowUp', 500);
    const c = await readout();
    const turn = Math.atan2(Math.sin(b.heading - a.heading), Math.cos(b.heading - a.heading));
    return {
      turn_deg_per_s: +((turn * 180) / Math.PI / turnSeconds).toFixed(1),
      target_turn_deg_per_s: 90,
      speed_change_m_per_s2: +((c.speed - b.speed) / speedSeconds).toFixed(2),
      target_speed_change_m_per_s2: 1,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

export const BENCHMARKS = [
  {
    name: 'path-follow',
    description: 'followPath on the five benchmark paths (walk, seed 0) — target: optimisation ≥ 2× faster than the motion lasts',
    run: pathFollowBenchmark,
    summary: (r) => `least ${r.least_realtime_factor}× real time (target ≥ 2×): ${JSON.stringify(r.realtime_factor)}`,
  },
  {
    name: 'live-control',
    description: 'simulateControl, 6 s with speed and heading changes: compute per model frame — target p95 < 33 ms',
    run: liveControlBenchmark,
    summary: (r) => `${r.p95_ms_per_frame} ms per frame p95 (target < 33), p50 ${r.p50_ms_per_frame}, max ${r.max_ms_per_frame}`,
  },
  {
    name: 'latent-erd-paths',
    description: 'followPath on the five benchmark paths (walk, seed 0) with model "latent-erd", and with the generator (default model) in the same run — latent ERD targets: mean error ≤ 0.15 m, progress ≥ 95%, ≥ 20× real time',
    run: (ctx) => pathModelsBenchmark(ctx),
    summary: (r) => {
      const [a, g] = PATH_MODELS.map((m) => r.summary[m]);
      return (
        `latent ERD mean error ${a.mean_error_m} m (worst ${a.worst_mean_error_m}, target ≤ 0.15), least progress ${(a.least_progress * 100).toFixed(1)}% (target ≥ 95%),` +
        ` least ${a.least_realtime_factor}× real time (target ≥ 20×), skating ${a.mean_skating_m_per_s} m/s, sliding ${a.mean_sliding_m_per_s} m/s; generator ${g.mean_error_m} m, ${(g.least_progress * 100).toFixed(1)}%, ${g.least_realtime_factor}×, ${g.mean_skating_m_per_s} / ${g.mean_sliding_m_per_s} m/s` +
        `\n${latentPathsTable(r)}`
      );
    },
  },
  {
    name: 'vae-lstm-paths',
    description: 'followPath on the five benchmark paths (walk, seed 0) with model "vae-lstm", beside the latent ERD and the generator in the same run — VAE-LSTM targets: ≥ 100× real time, mean error ≤ 0.10 m',
    run: (ctx) => pathModelsBenchmark(ctx, VAE_PATH_MODELS),
    summary: (r) => {
      const v = r.summary['vae-lstm'];
      return (
        `VAE-LSTM mean error ${v.mean_error_m} m (worst path ${v.worst_mean_error_m}, target ≤ 0.10), least progress ${(v.least_progress * 100).toFixed(1)}%,` +
        ` least ${v.least_realtime_factor}× real time (target ≥ 100×), sliding ${v.mean_sliding_m_per_s} m/s` +
        VAE_PATH_MODELS.slice(1).map((m) => `; ${m} ${r.summary[m].mean_error_m} m, least ${r.summary[m].least_realtime_factor}×`).join('') +
        `\n${latentPathsTable(r, VAE_PATH_MODELS)}`
      );
    },
  },
  {
    name: 'steer-mode',
    description: 'Steer mode: live control streaming (no input: straight ahead at 1.2 m/s), default quality — target 60 fps',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-steer', 'steer-status'),
    summary: liveModeSummary,
  },
  {
    name: 'steer-mode-latent-erd',
    description: 'Steer mode with the latent ERD: one latent step (4 frames) per pull from its worker (no input: straight ahead at 1.2 m/s), default quality — target 60 fps',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-steer', 'steer-status', 'latent-erd'),
    summary: liveModeSummary,
  },
  {
    name: 'steer-keys',
    description: 'Steer mode: ← held ~1 s and ↑ held ~0.5 s — targets: the heading turns 90°/s, the speed changes 1 m/s per second',
    run: steerKeysBenchmark,
    summary: (r) => `turn ${r.turn_deg_per_s}°/s (target 90), speed ${r.speed_change_m_per_s2} m/s per second (target 1)`,
  },
];
