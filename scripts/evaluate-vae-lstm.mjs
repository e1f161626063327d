// The VAE-LSTM on the five benchmark paths beside the latent ERD and the generator with the MAP optimiser,
// all three measured in one run in headless Chromium through the public API (playground.followPath, the code
// Path mode runs): mean and max error, arc progress, the share of the path followed within 0.15 m (pathCoverage.ts), × real
// time (the motion's seconds over the seconds it took), foot sliding before and after the lock (footSkating.ts lowFootSliding) and skating by the contacts,
// walk and run, SEEDS seeds each. Also what Vary shows: VAE-LSTM walks of one path from several seeds,
// their mean pairwise joint distance relative to the hips. Then generate's random control, 3,000 frames for 40 seeds: the
// lowest and median second of pose change against the real median (docs/models/vae-lstm.json). And, when cache/vae-lstm-map-windows.json is there
// (python -m training.vae_lstm.evaluate --map-windows), the report's prediction row of the generator with the
// MAP follower given each held-out window's true root path: its joint position error at the same horizons,
// in the world and relative to the hips. Writes docs/models/vae-lstm-browser.json for docs/models/vae-lstm.md
// (python -m training.vae_lstm.evaluate).
//
//   npm run evaluate:vae-lstm            # 3 seeds per case
//   SEEDS=1 npm run evaluate:vae-lstm
//   ONLY=map OUT=/tmp/x.json npm run evaluate:vae-lstm   # only the MAP prediction row (a check of the script)
//   MODELS=vae-lstm,latent-erd npm run evaluate:vae-lstm  # those models only; the generator's rows kept from the last run
import { existsSync, readFileSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { launchBrowser, openPlayground, ROOT, startServer } from '../tests/support/browser.mjs';

const SEEDS = Number(process.env.SEEDS ?? 3);
const OUT = process.env.OUT ?? path.join(ROOT, 'docs/models/vae-lstm-browser.json');
const PATHS = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/benchmark_paths.json'), 'utf8')).paths;
const ALL_MODELS = ['vae-lstm', 'latent-erd', 'generator'];
// MODELS=vae-lstm,latent-erd measures only those; the other models' rows (and the MAP prediction row, the generator's)
// are kept from the previous OUT, with the date they were measured (`kept`).
const MODELS = process.env.MODELS ? process.env.MODELS.split(',') : ALL_MODELS;
const VARY_SEEDS = 6;
const MAP_WINDOWS = path.join(ROOT, 'cache/vae-lstm-map-windows.json');
const RANDOM_SEEDS = 40;
const RANDOM_FRAMES = 3000;
const REAL_MEDIAN = JSON.parse(readFileSync(path.join(ROOT, 'docs/models/vae-lstm.json'), 'utf8')).long_runs.real_median_pose_change;

/** The MAP follower on each window's true root path: errors (cm) at the horizons, in the world and relative to the hips. */
async function mapPrediction(page, spec) {
  const out = { windows: spec.windows.length, followed: 0, refused: [], with_root_cm: {}, relative_cm: {} };
  const sums = Object.fromEntries(spec.horizons.map((k) => [k, { world: 0, rel: 0, n: 0 }]));
  for (const w of spec.windows) {
    const r = await page.evaluate(async ({ points, horizons }) => {
      try {
        const m = await window.playground.followPath({ points, gait: 'walk', seed: 0 });
        const J = m.joints.length;
        return { frames: m.frames, poses: horizons.map((k) => Array.from(m.positions.subarray(Math.min(k, m.frames - 1) * J * 3, (Math.min(k, m.frames - 1) + 1) * J * 3))) };
      } catch (e) {
        return { error: e.message };
      }
    }, { points: w.points, horizons: spec.horizons });
    if (r.error) {
      out.refused.push(`${w.clip} @${w.start}: ${r.error}`);
      continue;
    }
    out.followed++;
    spec.horizons.forEach((k, i) => {
      const made = r.poses[i], real = w.real[String(k)].flat();
      const J = real.length / 3;
      let world = 0, rel = 0;
      for (let j = 0; j < J; j++) {
        const d = [0, 1, 2].map((c) => made[j * 3 + c] - real[j * 3 + c]);
        const dr = [0, 1, 2].map((c) => made[j * 3 + c] - made[c] - (real[j * 3 + c] - real[c]));
        world += Math.hypot(...d);
        rel += Math.hypot(...dr);
      }
      sums[k].world += world / J;
      sums[k].rel += rel / J;
      sums[k].n++;
    });
  }
  for (const k of spec.horizons) {
    out.with_root_cm[k] = +((sums[k].world / sums[k].n) * 100).toFixed(1);
    out.relative_cm[k] = +((sums[k].rel / sums[k].n) * 100).toFixed(1);
  }
  return out;
}

async function followOne(page, model, points, gait, seed) {
  return page.evaluate(
    async ({ model, points, gait, seed }) => {
      const { pathCoverage, rootGroundTrack } = await import('/motion/pathCoverage.ts');
      const m = await window.playground.followPath({ model, points, gait, seed });
      // The share of the path's length the root (hips) passed within 0.15 m, in order (issue 43's measure).
      return { frames: m.frames, fps: m.fps, stats: m.stats, coverage: pathCoverage(points, rootGroundTrack(m.positions, m.joints.length)) };
    },
    { model, points, gait, seed },
  );
}

/**
 * generate's random control for RANDOM_FRAMES frames, seeds 0..RANDOM_SEEDS-1, as the page returns it (fitted, feet
 * locked): each run's lowest and median second of pose change (web/motion/poseChange.ts) against the real median.
 */
async function randomControlRuns(page, realMedian) {
  const runs = await page.evaluate(async ({ seeds, frames }) => {
    const { poseChangePerSecond } = await import('/motion/poseChange.ts');
    const out = [];
    for (let seed = 0; seed < seeds; seed++) {
      const m = await window.playground.generate({ model: 'vae-lstm', frames, seed });
      const s = poseChangePerSecond(m.positions, m.joints.length, m.fps);
      const sorted = [...s].sort((a, b) => a - b);
      out.push({ seed, lowest: sorted[0], lowestAt: s.indexOf(sorted[0]), median: sorted[sorted.length >> 1] });
    }
    return out;
  }, { seeds: RANDOM_SEEDS, frames: RANDOM_FRAMES });
  return {
    frames: RANDOM_FRAMES, real_median: realMedian,
    runs: runs.map((r) => ({ seed: r.seed, lowest_second: +(r.lowest / realMedian).toFixed(3), lowest_at_s: r.lowestAt, median_second: +(r.median / realMedian).toFixed(3) })),
  };
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
    for (const gait of process.env.ONLY === 'map' ? [] : ['walk', 'run']) {
      for (const [name, { points }] of Object.entries(PATHS)) {
        for (const model of MODELS) {
          const runs = [];
          for (let seed = 0; seed < SEEDS; seed++) {
            const m = await followOne(page, model, points, gait, seed);
            const seconds = m.frames / m.fps;
            const run = { gait, path: name, model, seed, seconds, ...m.stats, coverage: m.coverage, realtime: (seconds * 1000) / m.stats.optimizeMs };
            report.runs.push(run);
            runs.push(run);
          }
          const row = {
            path: name, gait, model,
            meanError: mean(runs.map((r) => r.meanError)), worstMeanError: Math.max(...runs.map((r) => r.meanError)),
            maxError: Math.max(...runs.map((r) => r.maxError)), leastProgress: Math.min(...runs.map((r) => r.arcProgress)),
            leastCoverage: Math.min(...runs.map((r) => r.coverage)),
            leastRealTime: Math.min(...runs.map((r) => r.realtime)), meanRealTime: mean(runs.map((r) => r.realtime)),
            sliding: mean(runs.map((r) => r.sliding)), slidingBeforeLock: mean(runs.map((r) => r.slidingBeforeLock)),
            skating: mean(runs.map((r) => r.skating)), skatingBeforeLock: mean(runs.map((r) => r.skatingBeforeLock)),
          };
          report.paths.push(row);
          console.log(JSON.stringify(row));
        }
      }
    }
    const previous = MODELS.length < ALL_MODELS.length && existsSync(OUT) ? JSON.parse(readFileSync(OUT, 'utf8')) : undefined;
    if (previous) {
      const kept = (r) => !MODELS.includes(r.model);
      report.paths.push(...previous.paths.filter(kept));
      report.runs.push(...previous.runs.filter(kept));
      // Each kept model with the date its rows were measured.
      report.kept = Object.fromEntries(ALL_MODELS.filter((m) => !MODELS.includes(m)).map((m) => [m, previous.kept?.[m] ?? previous.date]));
      if (!MODELS.includes('generator') && previous.map_prediction) report.map_prediction = previous.map_prediction;
      const names = Object.keys(PATHS);
      const order = (r) => [['walk', 'run'].indexOf(r.gait), names.indexOf(r.path), ALL_MODELS.indexOf(r.model)];
      report.paths.sort((a, b) => order(a).reduce((d, v, i) => d || v - order(b)[i], 0));
    }
    if (report.map_prediction) console.log('the MAP prediction row kept from the previous run');
    else if (existsSync(MAP_WINDOWS)) {
      report.map_prediction = await mapPrediction(page, JSON.parse(readFileSync(MAP_WINDOWS, 'utf8')));
      console.log(JSON.stringify(report.map_prediction));
    } else console.log(`no ${MAP_WINDOWS}: the MAP prediction row is left out (python -m training.vae_lstm.evaluate --map-windows writes it)`);
    if (process.env.ONLY !== 'map') {
      report.random_control = await randomControlRuns(page, REAL_MEDIAN);
      console.log(JSON.stringify(report.random_control.runs.map((r) => r.lowest_second)));
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
