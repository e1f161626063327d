// Generator family: the generator's raw step (one stream and batch 64, 1 and 2 threads), the refiner's extra cost
// per frame, and Random walk mode (the generator streaming beside the display).
import { openPlayground } from '../support/browser.mjs';
import { liveModeBenchmark, liveModeSummary, modelBenchmark, VIEWPORT } from './common.mjs';

const GENERATOR_CLIENT = { module: '/runtime/generator/generatorClient.ts', name: 'GeneratorClient', options: {} };

async function generatorBenchmark(ctx, threads, batch, steps) {
  const r = await modelBenchmark(ctx, { client: GENERATOR_CLIENT, threads, batch, steps });
  return { ...r, ...(batch === 1 ? { target_steps_per_s: 1000 } : { target_particle_steps_per_s: 20000 }) };
}

/**
 * The refiner's extra cost per frame: generate (batch 1, one thread) of the same frames without and with
 * refine, interleaved, best of `runs` each. With refine the worker also runs R's step per frame, the
 * end effectors, the decoding of the refined frames and the foot lock; the foot lock alone is timed on the
 * page's thread over the same refined frames, so the refiner's share without it can be reported too.
 */
async function refinerCostBenchmark(ctx, { frames = 3000, runs = 3 } = {}) {
  const { context, page, problems } = await openPlayground(ctx.browser, `${ctx.url}?mode=clip&threads=1`, VIEWPORT);
  try {
    const r = await page.evaluate(
      async ({ frames, runs }) => {
        const { GeneratorClient } = await import('/runtime/generator/generatorClient.ts');
        const { footLock } = await import('/motion/footLock.ts');
        const info = await (await fetch('models/generator.json')).json();
        const client = new GeneratorClient({ threads: 1 });
        try {
          const loaded = await client.init();
          const params = { seed: 0, temperature: 0.5 };
          await client.generate({ ...params, frames: 60 }); // warm-up: wasm, and loading the refiner
          await client.generate({ ...params, frames: 60, refine: true });
          const raw = [], refined = [], lock = [];
          let last;
          for (let i = 0; i < runs; i++) {
            let t = performance.now();
            await client.generate({ ...params, frames });
            raw.push(performance.now() - t);
            t = performance.now();
            last = await client.generate({ ...params, frames, refine: true });
            refined.push(performance.now() - t);
            // The foot lock alone, on the refined frames before the lock would be ideal; on the locked ones it
            // takes the same path (same contacts, planted feet), which is what the timing needs.
            t = performance.now();
            footLock(last.refined.positions, last.refined.contacts, info.skeleton.joints, info.skeleton.offsets);
            lock.push(performance.now() - t);
          }
          return { raw: Math.min(...raw), refined: Math.min(...refined), lock: Math.min(...lock), threads: loaded.threads, isolated: globalThis.crossOriginIsolated };
        } finally {
          client.dispose();
        }
      },
      { frames, runs },
    );
    const perFrame = (ms) => +((ms / frames) * 1000).toFixed(1); // µs per frame
    return {
      frames,
      threads: r.threads,
      isolated: r.isolated,
      generator_us_per_frame: perFrame(r.raw),
      refine_us_per_frame: perFrame(r.refined),
      foot_lock_us_per_frame: perFrame(r.lock),
      refiner_extra: +(r.refined / r.raw - 1).toFixed(3),
      refiner_extra_without_lock: +((r.refined - r.lock) / r.raw - 1).toFixed(3),
      target_refiner_extra: 0.3,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

/** The summary of a generatorBenchmark result: steps/s at batch 1, particle-steps/s at batch 64. */
function generatorSummary(r) {
  const target = r.batch === 1 ? `${r.steps_per_s} steps/s (target ≥ 1,000)` : `${r.particle_steps_per_s} particle-steps/s (target ≥ 20,000)`;
  return `${target}, ${r.ms_per_call} ms/call, ${r.threads} thread(s)${r.isolated ? '' : ' (not isolated)'}`;
}

export const BENCHMARKS = [
  ...[1, 2].flatMap((threads) => [
    {
      name: `generator-single-t${threads}`,
      description: `generator, one stream (batch 1, 2000 steps), ${threads} thread(s) requested — target ≥ 1,000 steps/s`,
      run: (ctx) => generatorBenchmark(ctx, threads, 1, 2000),
      summary: generatorSummary,
    },
    {
      name: `generator-batch64-t${threads}`,
      description: `generator, batch 64 (300 steps), ${threads} thread(s) requested — target ≥ 20,000 particle-steps/s`,
      run: (ctx) => generatorBenchmark(ctx, threads, 64, 300),
      summary: generatorSummary,
    },
  ]),
  {
    name: 'refiner-cost',
    description: 'generate 3000 frames (batch 1, 1 thread) without and with refine (refiner step + end effectors + decode + foot lock) — target: refine adds ≤ 30% per frame',
    run: (ctx) => refinerCostBenchmark(ctx),
    summary: (r) =>
      `refine adds ${(r.refiner_extra * 100).toFixed(1)}% per frame (target ≤ 30%), ${(r.refiner_extra_without_lock * 100).toFixed(1)}% without the foot lock;` +
      ` ${r.generator_us_per_frame} → ${r.refine_us_per_frame} µs per frame, foot lock ${r.foot_lock_us_per_frame} µs, ${r.threads} thread(s)`,
  },
  {
    name: 'random-walk',
    description: 'Random walk mode streaming from the generator (default threads), default quality — target 60 fps',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status'),
    summary: liveModeSummary,
  },
];
