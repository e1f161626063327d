// Peers family: the page's end-to-end generate against a PyTorch loop and native onnxruntime of the same networks
// (.venv's Python: python -m training.bench.peers), and the generator's batch-64 call against its wasm ceiling.
import { execFileSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import path from 'node:path';
import { openPlayground, ROOT } from '../support/browser.mjs';
import { VIEWPORT } from './common.mjs';

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
      const { GeneratorClient } = await import('/runtime/generator/generatorClient.ts');
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

/** The summary of a peersBenchmark result: each model against its peers, and batch 64 against the ceiling. */
function peersSummary(r) {
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
  return (
    `${line('acLSTM', r.aclstm, r.targets.aclstm_over_torch)}; ${line('generator', r.generator, r.targets.generator_over_torch)}` +
    `\n    batch 64 in the page, ${ceiling} (target ≥ ${r.targets.batch64_page_over_ceiling * 100}%); native onnxruntime, 1 thread: ${n.generator_particle_steps_per_s} = ${(n.page_over_ceiling * 100).toFixed(1)}% of ${n.ceiling_particle_steps_per_s}`
  );
}

export const BENCHMARKS = [
  {
    name: 'peers',
    description: 'generate end to end in the page (acLSTM, generator; one stream) against a PyTorch eager loop of the same network and native onnxruntime, and the generator\'s raw batch-64 call against a graph of only its matrix products (the wasm ceiling), one run — targets: acLSTM ≥ 1.5× and generator ≥ 3× the PyTorch loop, batch 64 ≥ 90% of the ceiling',
    run: peersBenchmark,
    summary: peersSummary,
  },
];
