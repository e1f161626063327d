// Benchmarks of the page in headless Chromium (software GL here). Not a pass/fail test: each benchmark
// prints one JSON line (machine-readable) and the run ends with a human summary.
//
//   npm run bench                    # all benchmarks
//   npm run bench -- playback-auto   # only the named ones
//   BENCH_SECONDS=10 npm run bench   # longer measuring windows
//
// Add a benchmark by appending { name, description, run(ctx) } to BENCHMARKS; run() returns an object
// of metrics. ctx gives the browser, the served URL and corpus access.
import { execFileSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import path from 'node:path';
import { build as viteBuild, preview as vitePreview } from 'vite';
import { corpusText, freePort, installUiLookups, launchBrowser, openPlayground, ROOT, startServer } from '../e2e/harness.mjs';

const SECONDS = Number(process.env.BENCH_SECONDS ?? 5);
const WARMUP_SECONDS = Number(process.env.BENCH_WARMUP ?? 4);
const VIEWPORT = { width: 1280, height: 720 };

/**
 * Display frame timing in the page: rAF intervals over `seconds`. With `clock`, also the playback
 * clock's rate against the page's clock: playback seconds advanced per second (unwrapped at the loop
 * point, times the speed's inverse; 1 = real time), sampled at every display frame.
 */
async function measureFrames(page, seconds, { clock = false } = {}) {
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

/**
 * Raw step throughput of a model client (`client`: its module, export and options) via its `benchmark`,
 * in a page opened with `?threads=N` in Clip mode with nothing loaded (so no Random walk streams beside it). With
 * `generate`, also the end-to-end rate of `generate` (steps, decoding and, for the dance models, the skeleton fit)
 * after a short warm-up call.
 */
async function modelBenchmark(ctx, { client, threads, batch, steps, generate }) {
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

const GENERATOR_CLIENT = { module: '/runtime/generatorClient.ts', name: 'GeneratorClient', options: {} };
const DANCE_CLIENT = { module: '/runtime/danceClient.ts', name: 'DanceClient', options: { model: 'aclstm' } };

async function generatorBenchmark(ctx, threads, batch, steps) {
  const r = await modelBenchmark(ctx, { client: GENERATOR_CLIENT, threads, batch, steps });
  return { ...r, ...(batch === 1 ? { target_steps_per_s: 1000 } : { target_particle_steps_per_s: 20000 }) };
}

/**
 * Display frame rate while a live mode streams (default threads), plus how far its stream got per second.
 * `model`: Steer mode's model choice (#steer-model) to set first.
 */
async function liveModeBenchmark(ctx, button, statusId, model) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
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
      ...displayFields(stats, problems),
    };
  } finally {
    await context.close();
  }
}

/** What every display benchmark reports about the renderer and page health. */
function displayFields(stats, problems) {
  return {
    pixel_ratio: +stats.pixelRatio.toFixed(3),
    quality: stats.quality,
    renderer: stats.renderer,
    page_errors: problems.length,
  };
}

const ACLSTM_BENCHMARKS = [1, 2].map((threads) => ({
  name: `aclstm-single-t${threads}`,
  description: `acLSTM, one dance (batch 1): 2000 raw steps, and generate 3000 frames (steps + decode + skeleton fit), ${threads} thread(s) requested — target ≥ 600 frames/s`,
  kind: 'aclstm',
  run: (ctx) =>
    modelBenchmark(ctx, { client: DANCE_CLIENT, threads, batch: 1, steps: 2000, generate: { style: 'salsa', seed: 0, frames: 3000 } }).then((r) => ({
      ...r,
      target_frames_per_s: 600,
    })),
}));

const GENERATOR_BENCHMARKS = [1, 2].flatMap((threads) => [
  {
    name: `generator-single-t${threads}`,
    description: `generator, one stream (batch 1, 2000 steps), ${threads} thread(s) requested — target ≥ 1,000 steps/s`,
    kind: 'generator',
    run: (ctx) => generatorBenchmark(ctx, threads, 1, 2000),
  },
  {
    name: `generator-batch64-t${threads}`,
    description: `generator, batch 64 (300 steps), ${threads} thread(s) requested — target ≥ 20,000 particle-steps/s`,
    kind: 'generator',
    run: (ctx) => generatorBenchmark(ctx, threads, 64, 300),
  },
]);

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
        const { GeneratorClient } = await import('/runtime/generatorClient.ts');
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
/**
 * The page against its peers, in one run: end-to-end `generate` throughput (the network, decoding, skeleton fit,
 * contact labels and foot lock, and the worker's messages; best of 3, one stream, the page's default threads)
 * for the acLSTM and the generator, and a PyTorch eager loop of the same network and native onnxruntime on its
 * ONNX step, one thread each (python -m training.bench.peers). The two alternate for PEER_ROUNDS rounds and each
 * side's best counts: this machine has slow spells of several seconds (a PyTorch loop timed once right after the
 * browser started ran at 2,200-2,300 frames/s, alone 3,700-3,800), so a ratio of one timing each is a coin toss.
 *
 * Also the batch-64 wasm ceiling (batch64Ceiling): the particle search's raw generator call at batch 64 against
 * a graph with only the step's matrix products, which the Python command writes to a git-ignored tmp/ folder
 * for the run (training/bench/ceiling.py) and times natively beside the shipped step.
 */
async function peersBenchmark(ctx) {
  const FRAMES = 2000;
  const PEER_ROUNDS = 3;
  mkdirSync(path.join(ROOT, 'tmp'), { recursive: true });
  const dir = mkdtempSync(path.join(ROOT, 'tmp', 'bench-ceiling-')); // tmp/ is git-ignored; removed below
  const ceilingFile = path.join(dir, 'generator-ceiling.onnx');
  try {
    const python = path.join(ROOT, '.venv', 'bin', 'python');
    const timePeers = (first) => {
      const args = ['-m', 'training.bench.peers', '--frames', String(FRAMES), ...(first ? ['--ceiling', ceilingFile] : [])];
      return JSON.parse(execFileSync(python, args, { cwd: ROOT, encoding: 'utf8' }).trim().split('\n').pop());
    };
    // Clip mode with nothing loaded: the page runs nothing but the measured calls, as the peers run alone (the plain
    // URL opens Random walk, whose stream and 60 fps drawing would share this 2-core machine with them).
    const { context, page, problems } = await openPlayground(ctx.browser, `${ctx.url}?mode=clip`, VIEWPORT);
    const peerRuns = [], pageRuns = [];
    let batch64;
    try {
      for (let round = 0; round < PEER_ROUNDS; round++) {
        peerRuns.push(timePeers(round === 0));
        pageRuns.push(
          await page.evaluate(async (frames) => {
            const rate = async (options) => {
              await window.playground.generate({ ...options, frames: 60 }); // load and warm up
              let best = 0;
              for (let k = 0; k < 3; k++) {
                const t0 = performance.now();
                await window.playground.generate({ ...options, frames });
                best = Math.max(best, frames / ((performance.now() - t0) / 1000));
              }
              return best;
            };
            return { aclstm: await rate({ model: 'aclstm', style: 'salsa', seed: 0 }), generator: await rate({ model: 'generator', seed: 0 }) };
          }, FRAMES),
        );
      }
      // The dev server serves files under the repository at /@fs/<absolute path> (vite.config.ts: fs.allow).
      batch64 = await batch64Ceiling(page, `/@fs${ceilingFile.split(path.sep).join('/')}`);
    } finally {
      await context.close();
    }
    // Each side's best over the rounds (a slow spell only slows a timing down).
    const bestOf = (runs, pick) => Math.max(...runs.map(pick));
    const peers = peerRuns[0];
    const row = (name) => {
      const pageRate = bestOf(pageRuns, (r) => r[name]);
      const torch = bestOf(peerRuns, (r) => r[name].torch_frames_per_s);
      const ort = bestOf(peerRuns, (r) => r[name].ort_frames_per_s);
      return {
        page_frames_per_s: Math.round(pageRate),
        torch_frames_per_s: Math.round(torch),
        ort_frames_per_s: Math.round(ort),
        page_over_torch: +(pageRate / torch).toFixed(2),
        page_over_ort: +(pageRate / ort).toFixed(2),
        // Every round: page ÷ PyTorch loop of that round.
        page_over_torch_rounds: pageRuns.map((r, k) => +(r[name] / peerRuns[k][name].torch_frames_per_s).toFixed(2)),
        page_runs: pageRuns.map((r) => Math.round(r[name])),
        torch_runs: peerRuns.map((r) => Math.round(r[name].torch_frames_per_s)),
        ...(peers[name].ort_single_step_frames_per_s ? { ort_single_step_frames_per_s: Math.round(bestOf(peerRuns, (r) => r[name].ort_single_step_frames_per_s)), ort: peers[name].ort } : {}),
        torch_loop: peers[name].torch,
      };
    };
    const native = peers.batch64_native;
    return {
      frames: FRAMES,
      rounds: PEER_ROUNDS,
      aclstm: row('aclstm'),
      generator: row('generator'),
      batch64: {
        ...batch64,
        ceiling_graph: { ops: peers.ceiling.ops, gemms: peers.ceiling.gemms, multiply_adds_per_particle_step: peers.ceiling.multiply_adds_per_particle_step },
        native_t1: {
          generator_particle_steps_per_s: Math.round(native.generator.particle_steps_per_s),
          ceiling_particle_steps_per_s: Math.round(native.ceiling.particle_steps_per_s),
          page_over_ceiling: +native.generator_over_ceiling.toFixed(3),
        },
      },
      targets: { aclstm_over_torch: 1.5, generator_over_torch: 3, batch64_page_over_ceiling: 0.9 },
      page_errors: problems.length,
    };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

/**
 * The generator's raw step at batch 64 (GeneratorClient.benchmark: the call the particle search makes, h and c
 * fed back) against the products-only graph at `ceilingUrl` run the same way (its own GeneratorClient, so the
 * same worker code, thread count and feeding), at the page's default thread count and at 1 thread (once when
 * that is the default). Per thread count the two alternate for `rounds` rounds of `steps` calls after a
 * warm-up; the ratio is best against best (a busy machine only slows runs down).
 */
async function batch64Ceiling(page, ceilingUrl, { batch = 64, steps = 100, rounds = 15 } = {}) {
  const r = await page.evaluate(
    async ({ ceilingUrl, batch, steps, rounds }) => {
      const { GeneratorClient } = await import('/runtime/generatorClient.ts');
      const { pageThreads } = await import('/ui/modelHost.ts');
      const defaultThreads = pageThreads();
      const rows = [];
      for (const threads of [...new Set([defaultThreads, 1])]) {
        const clients = { generator: new GeneratorClient({ threads }), ceiling: new GeneratorClient({ threads, modelUrl: ceilingUrl }) };
        try {
          const runs = { generator: [], ceiling: [] };
          let used;
          for (const c of Object.values(clients)) {
            used = (await c.init()).threads;
            await c.benchmark(batch, 100); // warm-up
          }
          for (let k = 0; k < rounds; k++) {
            // Alternating order (ABBA…), so a slow spell of the machine weighs on both graphs alike.
            const order = k % 2 ? ['ceiling', 'generator'] : ['generator', 'ceiling'];
            for (const name of order) runs[name].push(await clients[name].benchmark(batch, steps));
          }
          rows.push({ threads, used, runs });
        } finally {
          for (const c of Object.values(clients)) c.dispose();
        }
      }
      return { defaultThreads, rows, isolated: globalThis.crossOriginIsolated };
    },
    { ceilingUrl, batch, steps, rounds },
  );
  const best = (runs) => Math.max(...runs.map((b) => b.particleStepsPerSecond));
  const median = (xs) => [...xs].sort((a, b) => a - b)[(xs.length - 1) >> 1];
  const rows = r.rows.map(({ threads, used, runs }) => {
    const g = best(runs.generator), c = best(runs.ceiling);
    return {
      threads_requested: threads,
      threads: used,
      page_default: threads === r.defaultThreads,
      generator_particle_steps_per_s: Math.round(g),
      ceiling_particle_steps_per_s: Math.round(c),
      page_over_ceiling: +(g / c).toFixed(3),
      // The same, round by round (the two runs of a round are next to each other in time): the median.
      page_over_ceiling_paired_median: +median(runs.generator.map((b, k) => b.particleStepsPerSecond / runs.ceiling[k].particleStepsPerSecond)).toFixed(3),
      generator_ms_per_call: +Math.min(...runs.generator.map((b) => b.msPerCall)).toFixed(3),
      ceiling_ms_per_call: +Math.min(...runs.ceiling.map((b) => b.msPerCall)).toFixed(3),
      generator_runs: runs.generator.map((b) => Math.round(b.particleStepsPerSecond)),
      ceiling_runs: runs.ceiling.map((b) => Math.round(b.particleStepsPerSecond)),
    };
  });
  return { batch, steps, rounds, default_threads: r.defaultThreads, isolated: r.isolated, rows };
}

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

/**
 * A ~50 MB BVH dropped on the page (CMU 07_04 with its MOTION section repeated, built in the page), as a
 * person would. The page thread's long tasks (PerformanceObserver 'longtask') and display frame gaps (rAF)
 * during the import: from the drop until the clip is shown (the title changes to its name, which happens
 * in the same task as the show); and, apart, during the first 30 frames drawing it. Target: no task over
 * 100 ms during the import.
 */
async function largeImportBenchmark(ctx, megabytes) {
  const { context, page, problems } = await openPlayground(ctx.browser, ctx.url, VIEWPORT);
  try {
    const r = await page.evaluate(
      async ({ bvh, bytes }) => {
        const lines = bvh.split('\n');
        const motion = lines.findIndex((l) => l.trim() === 'MOTION');
        const frameLines = lines.slice(motion + 3).filter((l) => l.trim());
        const copies = Math.ceil(bytes / (frameLines.join('\n').length + 1));
        const frames = frameLines.length * copies;
        const text = [...lines.slice(0, motion), 'MOTION', `Frames: ${frames}`, lines[motion + 2], ''].join('\n') + (frameLines.join('\n') + '\n').repeat(copies);
        const name = '07_04-long.bvh';
        const file = new File([text], name);
        // performance.now() in the callback, not rAF's timestamp: after a long task that can be the frame's earlier start.
        const nextFrame = () => new Promise((resolve) => requestAnimationFrame(() => resolve(performance.now())));
        for (let i = 0; i < 10; i++) await nextFrame(); // the file's construction settles
        const tasks = [];
        const observer = new PerformanceObserver((list) => tasks.push(...list.getEntries().map((e) => ({ start: e.startTime, ms: e.duration }))));
        observer.observe({ type: 'longtask' });
        let shownAt = null;
        const title = $ui('clip-name');
        const titleObserver = new MutationObserver(() => {
          if (title.textContent === name) shownAt ??= performance.now();
        });
        titleObserver.observe(title, { childList: true, characterData: true, subtree: true });
        const errorBefore = window.playground.lastError();
        const dt = new DataTransfer();
        dt.items.add(file);
        const started = performance.now();
        const gaps = [];
        let last = started, after = 0;
        const target = $uiOne('.viewer-canvas');
        for (const type of ['dragenter', 'dragover', 'drop']) target.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true }));
        for (;;) {
          const now = await nextFrame();
          gaps.push({ start: last, ms: now - last });
          last = now;
          if (shownAt !== null && ++after >= 30) break;
          const error = window.playground.lastError();
          if (error !== errorBefore) throw new Error(`the import failed: ${error}`);
          if (now - started > 120_000) throw new Error('the clip was not shown within 120 s');
        }
        tasks.push(...observer.takeRecords().map((e) => ({ start: e.startTime, ms: e.duration })));
        observer.disconnect();
        titleObserver.disconnect();
        if (window.playground.current()?.frames !== frames) throw new Error(`the shown clip has ${window.playground.current()?.frames} frames, not ${frames}`);
        const longest = (list) => Math.max(0, ...list.map((t) => t.ms));
        const during = tasks.filter((t) => t.start < shownAt), drawing = tasks.filter((t) => t.start >= shownAt);
        return {
          bytes: text.length,
          frames,
          importMs: shownAt - started,
          longTasks: during.length,
          over100: during.filter((t) => t.ms > 100).length,
          longestTask: longest(during),
          maxGap: longest(gaps.filter((g) => g.start < shownAt)),
          longestDrawingTask: longest(drawing),
          maxDrawingGap: longest(gaps.filter((g) => g.start >= shownAt)),
        };
      },
      { bvh: corpusText('cmu/bvh/07_04.bvh.gz'), bytes: megabytes * 1e6 },
    );
    return {
      file: `cmu/bvh/07_04 with its MOTION section repeated: ${(r.bytes / 1e6).toFixed(1)} MB, ${r.frames} frames`,
      import_ms: Math.round(r.importMs),
      long_tasks: r.longTasks,
      tasks_over_100ms: r.over100,
      longest_task_ms: Math.round(r.longestTask),
      target_longest_task_ms: 100,
      max_frame_gap_ms: Math.round(r.maxGap),
      first_frames_longest_task_ms: Math.round(r.longestDrawingTask),
      first_frames_max_gap_ms: Math.round(r.maxDrawingGap),
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

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

/**
 * Runs in the page before its scripts (first-frame). Hooks window.playground as main.ts sets it, so `ready` is
 * seen as it resolves; then, unless the page has already chosen Random walk for itself (a first visit opens on
 * it: FIRST_VIEW in web/ui/viewState.ts, applied when `ready` resolves), presses the Random walk button. Watches
 * every display frame until the viewer holds the walk's first frames (playground.state().frames > 0) and takes
 * the time at the display frame after that one, by which the frame drawing them is on screen. Times are
 * performance.now(): ms since navigation start. The result lands in window.__firstFrame.
 */
function watchFirstFrame() {
  if (window.top !== window) return;
  performance.setResourceTimingBufferSize(100_000); // the dev server serves every module as a file of its own
  const out = { modeChosenByPage: null };
  let pg;
  Object.defineProperty(window, 'playground', {
    configurable: true,
    get: () => pg,
    set(value) {
      pg = value;
      value.ready.then(() => {
        out.readyMs = performance.now();
        const walk = window.$ui('mode-walk');
        out.modeChosenByPage = walk?.getAttribute('aria-pressed') === 'true';
        if (!out.modeChosenByPage) walk?.click();
      });
    },
  });
  // bytes: the file's size; transferred: its body as sent (smaller where the server compressed it).
  const file = (e) => ({
    file: new URL(e.name).pathname.split('/').pop(),
    bytes: e.decodedBodySize,
    transferred: e.encodedBodySize,
    startMs: Math.round(e.startTime),
    endMs: Math.round(e.responseEnd),
  });
  const tick = () => {
    if (out.readyMs === undefined || !(pg.state().frames > 0)) {
      requestAnimationFrame(tick);
      return;
    }
    out.shownMs = performance.now();
    requestAnimationFrame(() => {
      out.firstFrameMs = performance.now();
      out.walkPressed = window.$ui('mode-walk')?.getAttribute('aria-pressed') === 'true';
      out.title = window.$ui('clip-name')?.textContent ?? null;
      const done = performance.getEntriesByType('resource').filter((e) => e.responseEnd > 0 && e.responseEnd <= out.firstFrameMs);
      out.requests = done.length;
      out.models = done.filter((e) => new URL(e.name).pathname.includes('/models/')).map(file);
      out.wasm = done.filter((e) => new URL(e.name).pathname.endsWith('.wasm')).map(file);
      const nav = performance.getEntriesByType('navigation')[0];
      out.domContentLoadedMs = nav?.domContentLoadedEventEnd;
      out.loadMs = nav?.loadEventEnd;
      window.__firstFrame = out;
    });
  };
  requestAnimationFrame(tick);
}

/**
 * One fresh visit (a new browser context: empty cache) of `ctx.url + query`, watched by watchFirstFrame:
 * navigation start → `ready` → the first generated frame on screen, and the files fetched by then.
 */
async function firstFrameRun(ctx, query) {
  const context = await ctx.browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  try {
    const page = await context.newPage();
    const problems = [];
    page.on('console', (msg) => msg.type() === 'error' && problems.push(msg.text()));
    page.on('pageerror', (err) => problems.push(err.message));
    await page.addInitScript(installUiLookups);
    await page.addInitScript(watchFirstFrame);
    await page.goto(ctx.url + query, { waitUntil: 'commit' });
    await page.waitForFunction(() => window.__firstFrame, null, { timeout: 60_000, polling: 100 });
    const r = await page.evaluate(() => window.__firstFrame);
    if (!r.walkPressed) throw new Error(`the page is not in Random walk mode at its first frame (title ${JSON.stringify(r.title)})`);
    const sum = (files, key = 'bytes') => files.reduce((a, f) => a + f[key], 0);
    return {
      first_frame_ms: Math.round(r.firstFrameMs),
      ready_ms: Math.round(r.readyMs),
      shown_ms: Math.round(r.shownMs),
      dom_content_loaded_ms: Math.round(r.domContentLoadedMs),
      load_ms: Math.round(r.loadMs),
      walk_chosen_by: r.modeChosenByPage ? 'page' : 'click',
      // When each model file and the wasm were asked for and arrived: [start, end] ms after navigation start.
      fetched_ms: Object.fromEntries([...r.models, ...r.wasm].map((f) => [f.file, [f.startMs, f.endMs]])),
      model_bytes: sum(r.models),
      model_bytes_transferred: sum(r.models, 'transferred'),
      model_files: r.models,
      wasm_bytes: sum(r.wasm),
      requests: r.requests,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

/**
 * The page as `npm run build` makes it (without the type check), built into a git-ignored tmp/ folder and served
 * by `vite preview` (the same cross-origin isolation headers); `close()` stops the server and removes the folder.
 */
async function startBuiltPage() {
  mkdirSync(path.join(ROOT, 'tmp'), { recursive: true });
  const outDir = mkdtempSync(path.join(ROOT, 'tmp', 'bench-build-'));
  try {
    const configFile = path.join(ROOT, 'vite.config.ts');
    await viteBuild({ configFile, logLevel: 'error', build: { outDir, emptyOutDir: true, sourcemap: false } });
    const port = await freePort();
    const server = await vitePreview({ configFile, logLevel: 'warn', build: { outDir }, preview: { host: '127.0.0.1', port, strictPort: true, open: false } });
    return {
      url: `http://127.0.0.1:${port}/`,
      close: async () => {
        await server.close();
        rmSync(outDir, { recursive: true, force: true });
      },
    };
  } catch (e) {
    rmSync(outDir, { recursive: true, force: true });
    throw e;
  }
}

/**
 * First frame of a first visit: the plain URL in a fresh browser context opens on the refined Random walk (the
 * page chooses it when `ready` resolves; otherwise the watcher presses the button then), timed from navigation
 * start to the first generated frame on screen. Measured on the production build served from localhost (what a
 * visitor gets): one untimed visit, then `runs` visits of the plain URL and `runs` of `?refine=false` (the
 * generator alone), alternating. Also `runs` visits on the bench's dev server (which serves every module as a
 * file of its own, so its page alone loads far slower); its first visit also warms its module transforms.
 */
async function firstFrameBenchmark(ctx, { runs = 3 } = {}) {
  const median = (xs) => [...xs].sort((a, b) => a - b)[(xs.length - 1) >> 1];
  const summary = (rows) => ({
    first_frame_ms: median(rows.map((r) => r.first_frame_ms)),
    first_frame_ms_runs: rows.map((r) => r.first_frame_ms),
    ready_ms: median(rows.map((r) => r.ready_ms)),
    load_ms: median(rows.map((r) => r.load_ms)),
    model_bytes: rows[0].model_bytes,
    model_bytes_transferred: rows[0].model_bytes_transferred,
    model_files: Object.fromEntries(rows[0].model_files.map((f) => [f.file, f.bytes])),
    wasm_bytes: rows[0].wasm_bytes,
    walk_chosen_by: rows[0].walk_chosen_by,
  });
  const built = await startBuiltPage();
  const refined = [], raw = [], dev = [];
  let devCold;
  try {
    const at = { ...ctx, url: built.url };
    await firstFrameRun(at, ''); // untimed: the server's and the OS's file caches
    for (let i = 0; i < runs; i++) {
      refined.push(await firstFrameRun(at, ''));
      raw.push(await firstFrameRun(at, '?refine=false'));
    }
  } finally {
    await built.close();
  }
  devCold = await firstFrameRun(ctx, '');
  for (let i = 0; i < runs; i++) dev.push(await firstFrameRun(ctx, ''));
  return {
    served: 'the production build (vite build, vite preview) on localhost; the plain page URL (a first visit) in a fresh browser context per visit',
    ...summary(refined),
    target_first_frame_ms: 1500,
    runs: refined.map(({ model_files, ...r }) => r),
    generator_only: summary(raw),
    dev_server: { ...summary(dev), cold_first_frame_ms: devCold.first_frame_ms },
    page_errors: [devCold, ...refined, ...raw, ...dev].reduce((a, r) => a + r.page_errors, 0),
  };
}

const OPTIMIZER_BENCHMARKS = [
  {
    name: 'path-follow',
    description: 'followPath on the five benchmark paths (walk, seed 0) — target: optimisation ≥ 2× faster than the motion lasts',
    kind: 'path',
    run: pathFollowBenchmark,
  },
  {
    name: 'live-control',
    description: 'simulateControl, 6 s with speed and heading changes: compute per model frame — target p95 < 33 ms',
    kind: 'control',
    run: liveControlBenchmark,
  },
  {
    name: 'latent-erd-paths',
    description: 'followPath on the five benchmark paths (walk, seed 0) with model "latent-erd", and with the generator (default model) in the same run — latent ERD targets: mean error ≤ 0.15 m, progress ≥ 95%, ≥ 20× real time',
    kind: 'latent-paths',
    run: (ctx) => pathModelsBenchmark(ctx),
  },
  {
    name: 'vae-lstm-paths',
    description: 'followPath on the five benchmark paths (walk, seed 0) with model "vae-lstm", beside the latent ERD and the generator in the same run — VAE-LSTM targets: ≥ 100× real time, mean error ≤ 0.10 m',
    kind: 'vae-paths',
    run: (ctx) => pathModelsBenchmark(ctx, VAE_PATH_MODELS),
  },
];

export const BENCHMARKS = [
  {
    name: 'playback-auto',
    description: 'one character playing, default quality (software GL → no MSAA, dynamic resolution)',
    run: (ctx) => playbackBenchmark(ctx, ''),
  },
  {
    name: 'playback-high',
    description: 'one character playing, ?quality=high (MSAA, full resolution unless too slow)',
    run: (ctx) => playbackBenchmark(ctx, '?quality=high'),
  },
  ...[10_000, 100_000].map((frames) => ({
    name: `long-clip-${frames / 1000}k`,
    description: `a ${frames.toLocaleString('en')}-frame clip playing (16_11 repeated, 30 fps), default quality, trail and footprints on — target ≥ 55 fps mean`,
    run: (ctx) => longClipBenchmark(ctx, frames),
  })),
  ...GENERATOR_BENCHMARKS,
  {
    name: 'refiner-cost',
    description: 'generate 3000 frames (batch 1, 1 thread) without and with refine (refiner step + end effectors + decode + foot lock) — target: refine adds ≤ 30% per frame',
    kind: 'refiner',
    run: (ctx) => refinerCostBenchmark(ctx),
  },
  {
    name: 'random-walk',
    description: 'Random walk mode streaming from the generator (default threads), default quality — target 60 fps',
    kind: 'live',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-walk', 'walk-status'),
  },
  ...ACLSTM_BENCHMARKS,
  {
    name: 'dance-mode',
    description: 'Dance mode streaming acLSTM (30 fps model) (default threads), skeleton fit and pose-change plot, default quality — target 60 fps',
    kind: 'live',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-dance', 'dance-status'),
  },
  ...OPTIMIZER_BENCHMARKS,
  {
    name: 'steer-mode',
    description: 'Steer mode: live control streaming (no input: straight ahead at 1.2 m/s), default quality — target 60 fps',
    kind: 'live',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-steer', 'steer-status'),
  },
  {
    name: 'steer-mode-latent-erd',
    description: 'Steer mode with the latent ERD: one latent step (4 frames) per pull from its worker (no input: straight ahead at 1.2 m/s), default quality — target 60 fps',
    kind: 'live',
    run: (ctx) => liveModeBenchmark(ctx, '#mode-steer', 'steer-status', 'latent-erd'),
  },
  {
    name: 'steer-keys',
    description: 'Steer mode: ← held ~1 s and ↑ held ~0.5 s — targets: the heading turns 90°/s, the speed changes 1 m/s per second',
    kind: 'keys',
    run: steerKeysBenchmark,
  },
  {
    name: 'peers',
    description: 'generate end to end in the page (acLSTM, generator; one stream) against a PyTorch eager loop of the same network and native onnxruntime, and the generator\'s raw batch-64 call against a graph of only its matrix products (the wasm ceiling), one run — targets: acLSTM ≥ 1.5× and generator ≥ 3× the PyTorch loop, batch 64 ≥ 90% of the ceiling',
    kind: 'peers',
    run: peersBenchmark,
  },
  {
    name: 'first-frame',
    description: 'a first visit (fresh browser context) of the production build on localhost, opening on Random walk: navigation start to the first generated frame on screen, and the model bytes fetched by then (also ?refine=false, and the dev server) — target ≤ 1,500 ms',
    kind: 'first-frame',
    run: (ctx) => firstFrameBenchmark(ctx),
  },
  {
    name: 'import-50mb',
    description: 'a 50 MB BVH dropped on the page: the page thread\'s long tasks until it is shown — target: none over 100 ms',
    kind: 'import',
    run: (ctx) => largeImportBenchmark(ctx, 50),
  },
  {
    name: 'cleanup',
    description: 'playground.denoise (map, manifold, lowpass) on a 10 s held-out CMU walk with 3 cm jitter + 1% outliers: one warm-up call, then 3 timed — target ≥ 2× real time (issue 16)',
    kind: 'cleanup',
    run: (ctx) => cleanupBenchmark(ctx),
  },
];

async function main() {
  const wanted = process.argv.slice(2);
  const unknown = wanted.filter((w) => !BENCHMARKS.some((b) => b.name === w));
  if (unknown.length) {
    console.error(`unknown benchmark(s): ${unknown.join(', ')}; known: ${BENCHMARKS.map((b) => b.name).join(', ')}`);
    process.exit(2);
  }
  const chosen = wanted.length ? BENCHMARKS.filter((b) => wanted.includes(b.name)) : BENCHMARKS;
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  const results = [];
  try {
    for (const b of chosen) {
      const started = Date.now();
      let result;
      try {
        result = { bench: b.name, ok: true, ...(await b.run({ browser, url })) };
      } catch (e) {
        result = { bench: b.name, ok: false, error: String(e?.message ?? e) };
      }
      result.seconds = +((Date.now() - started) / 1000).toFixed(1);
      console.log(JSON.stringify(result));
      results.push({ b, result });
    }
  } finally {
    await browser.close();
    await server.close();
  }
  console.log('\nSummary');
  for (const { b, result: r } of results) {
    if (!r.ok) {
      console.log(`  ${b.name}: FAILED — ${r.error}`);
      continue;
    }
    if (b.kind === 'aclstm') {
      console.log(
        `  ${b.name}: ${r.generate_frames_per_s} frames/s end to end (target ≥ 600), raw steps ${r.steps_per_s}/s, ${r.ms_per_call} ms/call,` +
          ` ${r.threads} thread(s)${r.isolated ? '' : ' (not isolated)'}\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'generator') {
      const target = r.batch === 1 ? `${r.steps_per_s} steps/s (target ≥ 1,000)` : `${r.particle_steps_per_s} particle-steps/s (target ≥ 20,000)`;
      console.log(`  ${b.name}: ${target}, ${r.ms_per_call} ms/call, ${r.threads} thread(s)${r.isolated ? '' : ' (not isolated)'}\n    ${b.description}`);
      continue;
    }
    if (b.kind === 'refiner') {
      console.log(
        `  ${b.name}: refine adds ${(r.refiner_extra * 100).toFixed(1)}% per frame (target ≤ 30%), ${(r.refiner_extra_without_lock * 100).toFixed(1)}% without the foot lock;` +
          ` ${r.generator_us_per_frame} → ${r.refine_us_per_frame} µs per frame, foot lock ${r.foot_lock_us_per_frame} µs, ${r.threads} thread(s)\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'path') {
      console.log(`  ${b.name}: least ${r.least_realtime_factor}× real time (target ≥ 2×): ${JSON.stringify(r.realtime_factor)}\n    ${b.description}`);
      continue;
    }
    if (b.kind === 'latent-paths') {
      const [a, g] = PATH_MODELS.map((m) => r.summary[m]);
      console.log(
        `  ${b.name}: latent ERD mean error ${a.mean_error_m} m (worst ${a.worst_mean_error_m}, target ≤ 0.15), least progress ${(a.least_progress * 100).toFixed(1)}% (target ≥ 95%),` +
          ` least ${a.least_realtime_factor}× real time (target ≥ 20×), skating ${a.mean_skating_m_per_s} m/s, sliding ${a.mean_sliding_m_per_s} m/s; generator ${g.mean_error_m} m, ${(g.least_progress * 100).toFixed(1)}%, ${g.least_realtime_factor}×, ${g.mean_skating_m_per_s} / ${g.mean_sliding_m_per_s} m/s` +
          `\n${latentPathsTable(r)}\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'vae-paths') {
      const v = r.summary['vae-lstm'];
      console.log(
        `  ${b.name}: VAE-LSTM mean error ${v.mean_error_m} m (worst path ${v.worst_mean_error_m}, target ≤ 0.10), least progress ${(v.least_progress * 100).toFixed(1)}%,` +
          ` least ${v.least_realtime_factor}× real time (target ≥ 100×), sliding ${v.mean_sliding_m_per_s} m/s` +
          VAE_PATH_MODELS.slice(1).map((m) => `; ${m} ${r.summary[m].mean_error_m} m, least ${r.summary[m].least_realtime_factor}×`).join('') +
          `\n${latentPathsTable(r, VAE_PATH_MODELS)}\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'peers') {
      const line = (name, m, target) =>
        `${name} ${m.page_frames_per_s} frames/s in the page = ${m.page_over_torch}× the PyTorch loop (${m.torch_frames_per_s}/s; target ≥ ${target}×; best of ${r.rounds} alternating rounds each, round by round ${m.page_over_torch_rounds.join(' / ')}), ${m.page_over_ort}× native onnxruntime (${m.ort_frames_per_s}/s)`;
      const ceiling = r.batch64.rows
        .map(
          (x) =>
            `${x.threads} thread(s)${x.page_default ? ' (page default)' : ''}: generator ${x.generator_particle_steps_per_s} particle-steps/s = ${(x.page_over_ceiling * 100).toFixed(1)}%` +
            ` of the products-only ceiling ${x.ceiling_particle_steps_per_s}/s (best of ${r.batch64.rounds} each; round by round, median ${(x.page_over_ceiling_paired_median * 100).toFixed(1)}%)`,
        )
        .join('; ');
      const n = r.batch64.native_t1;
      console.log(
        `  ${b.name}: ${line('acLSTM', r.aclstm, r.targets.aclstm_over_torch)}; ${line('generator', r.generator, r.targets.generator_over_torch)}` +
          `\n    batch 64 in the page, ${ceiling} (target ≥ ${r.targets.batch64_page_over_ceiling * 100}%); native onnxruntime, 1 thread: ${n.generator_particle_steps_per_s} = ${(n.page_over_ceiling * 100).toFixed(1)}% of ${n.ceiling_particle_steps_per_s}` +
          `\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'control') {
      console.log(`  ${b.name}: ${r.p95_ms_per_frame} ms per frame p95 (target < 33), p50 ${r.p50_ms_per_frame}, max ${r.max_ms_per_frame}\n    ${b.description}`);
      continue;
    }
    if (b.kind === 'live') {
      console.log(
        `  ${b.name}: ${r.mean_fps} fps mean (target 60), p95 frame ${r.p95_frame_ms} ms, ${r.long_frames}/${r.frames} frames > 25 ms,` +
          ` stream ${r.stream_frames_per_s} frames/s (target ${r.target_stream_frames_per_s}) — ${r.quality} quality at pixel ratio ${r.pixel_ratio}\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'import') {
      console.log(
        `  ${b.name}: longest page-thread task ${r.longest_task_ms} ms (target ≤ 100), ${r.tasks_over_100ms} over 100 ms, ${r.long_tasks} over 50 ms;` +
          ` shown after ${r.import_ms} ms, largest frame gap ${r.max_frame_gap_ms} ms; drawing its first 30 frames: longest task` +
          ` ${r.first_frames_longest_task_ms} ms, largest gap ${r.first_frames_max_gap_ms} ms — ${r.file}\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'cleanup') {
      console.log(
        `  ${b.name}: ${r.rows.map((x) => `${x.method} ${x.realtime_min}× real time (slowest of ${r.runs}) ${x.pass ? 'PASS' : 'FAIL'}`).join(', ')} (target ≥ ${r.target_realtime}×)` +
          `\n    clip: ${r.clip}; noise ${JSON.stringify(r.noise)}\n${cleanupTable(r)}\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'first-frame') {
      const mb = (n) => `${(n / 1e6).toFixed(2)} MB`;
      const g = r.generator_only, d = r.dev_server;
      console.log(
        `  ${b.name}: first frame ${r.first_frame_ms} ms after navigation start (target ≤ ${r.target_first_frame_ms}; median of ${JSON.stringify(r.first_frame_ms_runs)}), production build;` +
          ` ready at ${r.ready_ms} ms; ${mb(r.model_bytes)} of models fetched by then (${Object.entries(r.model_files).map(([f, n]) => `${f} ${mb(n)}`).join(', ')}; ${mb(r.model_bytes_transferred)} as sent) + ${mb(r.wasm_bytes)} wasm;` +
          ` Random walk chosen by the ${r.walk_chosen_by}\n    with ?refine=false ${g.first_frame_ms} ms (${JSON.stringify(g.first_frame_ms_runs)}, ${mb(g.model_bytes)} of models);` +
          ` on the dev server ${d.first_frame_ms} ms (${JSON.stringify(d.first_frame_ms_runs)}, ready at ${d.ready_ms} ms; its first visit ${d.cold_first_frame_ms} ms)\n    ${b.description}`,
      );
      continue;
    }
    if (b.kind === 'keys') {
      console.log(
        `  ${b.name}: turn ${r.turn_deg_per_s}°/s (target 90), speed ${r.speed_change_m_per_s2} m/s per second (target 1)\n    ${b.description}`,
      );
      continue;
    }
    console.log(
      `  ${b.name}: ${r.mean_fps} fps mean, p95 frame ${r.p95_frame_ms} ms, ${r.long_frames}/${r.frames} frames > 25 ms,` +
        ` playback ${r.playback_rate}× real time (target 1) — ${r.quality} quality at pixel ratio ${r.pixel_ratio}, ${r.viewport}\n    ${b.description}`,
    );
  }
  const renderer = results.find((x) => x.result.renderer)?.result.renderer;
  if (renderer) console.log(`  WebGL: ${renderer}`);
}

await main();
