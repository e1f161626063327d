// The VAE-LSTM on the five benchmark paths beside the latent ERD and the generator with the MAP optimiser,
// all three measured in one run in headless Chromium through the public API (playground.followPath, the code
// Path mode runs): mean and max error, arc progress, × real time (the motion's seconds over the seconds it
// took), foot sliding before and after the lock (footSkating.ts lowFootSliding) and skating by the contacts,
// walk and run, SEEDS seeds each. Also what Vary shows: VAE-LSTM walks of one path from several seeds,
// their mean pairwise joint distance relative to the hips. Writes docs/models/vae-lstm-browser.json for
// docs/models/vae-lstm.md (python -m training.vae_lstm.evaluate).
//
//   npm run evaluate:vae-lstm            # 3 seeds per case
//   SEEDS=1 npm run evaluate:vae-lstm
import { readFileSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { launchBrowser, openPlayground, ROOT, startServer } from '../tests/e2e/harness.mjs';

const SEEDS = Number(process.env.SEEDS ?? 3);
const OUT = path.join(ROOT, 'docs/models/vae-lstm-browser.json');
const PATHS = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/benchmark_paths.json'), 'utf8')).paths;
const MODELS = ['vae-lstm', 'latent-erd', 'generator'];
const VARY_SEEDS = 6;

async function followOne(page, model, points, gait, seed) {
  return page.evaluate(
    async ({ model, points, gait, seed }) => {
      const m = await window.playground.followPath({ model, points, gait, seed });
      return { frames: m.frames, fps: m.fps, stats: m.stats };
    },
    { model, points, gait, seed },
  );
}

/** Mean pairwise joint distance (cm) relative to the hips over the frames all the walks share. */
async function varyOne(page, points) {
  return page.evaluate(
    async ({ points, seeds }) => {
      const walks = [];
      for (let seed = 0; seed < seeds; seed++) walks.push(await window.playground.followPath({ model: 'vae-lstm', points, seed }));
      const frames = Math.min(...walks.map((w) => w.frames));
      const J = walks[0].joints.length;
      let sum = 0, pairs = 0;
      for (let a = 0; a < walks.length; a++) {
        for (let b = a + 1; b < walks.length; b++) {
          let d = 0;
          for (let f = 0; f < frames; f++) {
            for (let j = 0; j < J; j++) {
              const o = (f * J + j) * 3, r = f * J * 3;
              const dx = walks[a].positions[o] - walks[a].positions[r] - (walks[b].positions[o] - walks[b].positions[r]);
              const dy = walks[a].positions[o + 1] - walks[a].positions[r + 1] - (walks[b].positions[o + 1] - walks[b].positions[r + 1]);
              const dz = walks[a].positions[o + 2] - walks[a].positions[r + 2] - (walks[b].positions[o + 2] - walks[b].positions[r + 2]);
              d += Math.hypot(dx, dy, dz);
            }
          }
          sum += d / (frames * J);
          pairs++;
        }
      }
      return { seeds, frames, meanPairwiseCm: (sum / pairs) * 100 };
    },
    { points, seeds: VARY_SEEDS },
  );
}

const mean = (xs) => xs.reduce((a, b) => a + b, 0) / xs.length;

async function main() {
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  const report = { date: new Date().toISOString().slice(0, 10), made_by: 'npm run evaluate:vae-lstm (scripts/evaluate-vae-lstm.mjs)', seeds: SEEDS,
    load_before: +os.loadavg()[0].toFixed(2), cores: os.cpus().length, runs: [], paths: [] };
  try {
    const { page, problems } = await openPlayground(browser, url);
    report.isolated = await page.evaluate(() => globalThis.crossOriginIsolated);
    for (const model of MODELS) await followOne(page, model, [[0, 0], [0, 1]], 'walk', 0); // warm-up: load, first wasm calls
    for (const gait of ['walk', 'run']) {
      for (const [name, { points }] of Object.entries(PATHS)) {
        for (const model of MODELS) {
          const runs = [];
          for (let seed = 0; seed < SEEDS; seed++) {
            const m = await followOne(page, model, points, gait, seed);
            const seconds = m.frames / m.fps;
            const run = { gait, path: name, model, seed, seconds, ...m.stats, realtime: (seconds * 1000) / m.stats.optimizeMs };
            report.runs.push(run);
            runs.push(run);
          }
          const row = {
            path: name, gait, model,
            meanError: mean(runs.map((r) => r.meanError)), worstMeanError: Math.max(...runs.map((r) => r.meanError)),
            maxError: Math.max(...runs.map((r) => r.maxError)), leastProgress: Math.min(...runs.map((r) => r.arcProgress)),
            leastRealTime: Math.min(...runs.map((r) => r.realtime)), meanRealTime: mean(runs.map((r) => r.realtime)),
            sliding: mean(runs.map((r) => r.sliding)), slidingBeforeLock: mean(runs.map((r) => r.slidingBeforeLock)),
            skating: mean(runs.map((r) => r.skating)), skatingBeforeLock: mean(runs.map((r) => r.skatingBeforeLock)),
          };
          report.paths.push(row);
          console.log(JSON.stringify(row));
        }
      }
    }
    report.vary = {};
    for (const [name, { points }] of Object.entries(PATHS)) report.vary[name] = await varyOne(page, points);
    console.log(JSON.stringify(report.vary));
    report.page_errors = problems.length;
    report.load_after = +os.loadavg()[0].toFixed(2);
  } finally {
    await browser.close();
    server.close();
  }
  writeFileSync(OUT, JSON.stringify(report, null, 1) + '\n');
  console.log(`wrote ${OUT}`);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
