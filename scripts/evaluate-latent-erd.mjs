// The latent ERD's path following and live control, measured in headless Chromium through the public API
// (the code the Path and Steer modes run), exactly as scripts/evaluate-control.mjs measures the generator
// with the MAP optimiser for docs/models/control.md: the five benchmark paths (walk and run, SEEDS seeds
// each) and the live-control scenarios (a change at 3 s of a 6 s run). Writes docs/models/latent-erd-browser.json
// for the report (docs/models/latent-erd.md); the generator's numbers are docs/models/control.json.
//
//   npm run evaluate:latent-erd            # 3 seeds per case
//   SEEDS=5 npm run evaluate:latent-erd
//
// Path fit, arc progress and compute time come from followPath's stats; foot skating (planted toe speed:
// web/motion/footSkating.ts, as training/metrics.py foot_skating) is measured in the page on the returned
// (foot-locked) motions, and against unconstrained generation from the same seed: the latent ERD on its
// random control (generate without `control`), the same length. Control responses are read from the
// returned speed and heading. Also 10,000 frames of random control from 5 seeds: the per-second pose
// change (web/motion/poseChange.ts), to see whether the motion collapses to a mean pose.
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { launchBrowser, openPlayground, ROOT, startServer } from '../tests/support/browser.mjs';
import { controlRow, mean, percentile, rootSpeed, SCENARIOS, SIM_SECONDS } from './controlScenarios.mjs';

const SEEDS = Number(process.env.SEEDS ?? 3);
const OUT = path.join(ROOT, 'docs/models/latent-erd-browser.json');
const PATHS = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/benchmark_paths.json'), 'utf8')).paths;
/** The targets for the latent ERD; the live-control limits are docs/models/control.md's. */
const TARGETS = { meanError: 0.15, arcProgress: 0.95, realtime: 20, heading90: 1.0, heading180: 1.5, speedError: 0.2, p95ms: 33 };

const RANDOM_FRAMES = 10_000;
const RANDOM_SEEDS = 5;


async function followOne(page, name, gait, seed) {
  return page.evaluate(
    async ({ points, gait, seed }) => {
      const m = await window.playground.followPath({ model: 'latent-erd', points, gait, seed });
      const { footSkating } = await import('/motion/footSkating.ts');
      return { skating: footSkating(m), fps: m.fps, frames: m.frames, joints: m.joints, positions: Array.from(m.positions), stats: m.stats };
    },
    { points: PATHS[name].points, gait, seed },
  );
}

/** The latent ERD on its random control from `seed`: skating, and the per-second pose change. */
async function freeOne(page, seed, frames, poseChange = false) {
  return page.evaluate(
    async ({ seed, frames, poseChange }) => {
      const started = performance.now();
      const m = await window.playground.generate({ model: 'latent-erd', frames, seed });
      const ms = performance.now() - started;
      const { footSkating } = await import('/motion/footSkating.ts');
      const out = { skating: footSkating(m), ms };
      if (poseChange) {
        const { poseChangePerSecond } = await import('/motion/poseChange.ts');
        out.poseChange = poseChangePerSecond(m.positions, m.joints.length, m.fps);
      }
      return out;
    },
    { seed, frames, poseChange },
  );
}

async function simulateOne(page, scenario, seed) {
  return page.evaluate(
    async ({ schedule, seed, seconds, gait }) => {
      const m = await window.playground.simulateControl({ model: 'latent-erd', seconds, schedule, seed, ...(gait ? { gait } : {}) });
      const { footSkating } = await import('/motion/footSkating.ts');
      return { skating: footSkating(m), fps: m.fps, frames: m.frames, speed: Array.from(m.speed), heading: Array.from(m.heading), computeMs: Array.from(m.computeMs) };
    },
    { schedule: scenario.schedule, seed, seconds: scenario.seconds ?? SIM_SECONDS, gait: scenario.gait },
  );
}

/** JSON has no Infinity: a response never reached is written as null, with `reached: false`. */
const finite = (v) => (Number.isFinite(v) ? v : null);

async function main() {
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  const models = JSON.parse(readFileSync(path.join(ROOT, 'public/models/index.json'), 'utf8')).models;
  const erd = models.find((m) => m.id === 'latent-erd');
  const report = {
    date: new Date().toISOString().slice(0, 10),
    made_by: 'npm run evaluate:latent-erd (scripts/evaluate-latent-erd.mjs)',
    model: { id: 'latent-erd', bytes: erd?.bytes ?? null, manifold_bytes: models.find((m) => m.id === 'manifold')?.bytes ?? null },
    seeds: SEEDS,
    targets: TARGETS,
    simSeconds: SIM_SECONDS,
    paths: [],
    control: [],
    loadBefore: os.loadavg()[0],
    cores: os.cpus().length,
  };
  try {
    const { page, problems } = await openPlayground(browser, url);
    // Warm-up (model load, first wasm calls).
    report.crossOriginIsolated = await page.evaluate(async () => (await window.playground.generate({ model: 'latent-erd', frames: 8, seed: 0 }), globalThis.crossOriginIsolated));
    for (const gait of ['walk', 'run']) {
      for (const name of Object.keys(PATHS)) {
        for (let seed = 0; seed < SEEDS; seed++) {
          const m = await followOne(page, name, gait, seed);
          const free = await freeOne(page, seed, m.frames);
          const seconds = m.frames / m.fps;
          const row = {
            gait, path: name, seed, frames: m.frames, seconds,
            ...m.stats,
            realtime: (seconds * 1000) / m.stats.optimizeMs,
            speed: rootSpeed(m),
            skating: m.skating,
            skatingBeforeLock: m.stats.skatingBeforeLock,
            freeSkating: free.skating,
          };
          report.paths.push(row);
          console.log(JSON.stringify(row));
        }
      }
    }
    for (const [name, scenario] of Object.entries(SCENARIOS)) {
      for (let seed = 0; seed < SEEDS; seed++) {
        const sim = await simulateOne(page, scenario, seed);
        const row = controlRow(name, scenario, seed, sim, TARGETS);
        row.headingResponse = finite(row.headingResponse);
        report.control.push(row);
        console.log(JSON.stringify(row));
      }
    }
    const freeControl = [];
    for (let seed = 0; seed < SEEDS; seed++) freeControl.push((await freeOne(page, seed, SIM_SECONDS * 30)).skating);
    report.freeControlSkating = mean(freeControl);
    report.randomControl = [];
    for (let seed = 0; seed < RANDOM_SEEDS; seed++) {
      const r = await freeOne(page, seed, RANDOM_FRAMES, true);
      const row = {
        seed, frames: RANDOM_FRAMES, computeMs: r.ms, realtime: (RANDOM_FRAMES / 30) / (r.ms / 1000), skating: r.skating,
        poseChange: { seconds: r.poseChange.length, min: Math.min(...r.poseChange), p5: percentile(r.poseChange, 5), median: percentile(r.poseChange, 50), perSecond: r.poseChange.map((v) => +v.toFixed(4)) },
      };
      report.randomControl.push(row);
      console.log(JSON.stringify({ ...row, poseChange: { ...row.poseChange, perSecond: `${row.poseChange.perSecond.length} values` } }));
    }
    report.summary = summarise(report);
    report.problems = problems;
    report.loadAfter = os.loadavg()[0];
  } finally {
    await browser.close();
    await server.close();
  }
  mkdirSync(path.dirname(OUT), { recursive: true });
  writeFileSync(OUT, JSON.stringify(report, null, 1) + '\n');
  console.log(JSON.stringify(report.summary, null, 1));
  console.log(`wrote ${OUT}`);
}

/** Per path and gait, and per scenario, the numbers control.md's tables show, and whether the targets hold. */
function summarise(r) {
  const T = r.targets;
  const paths = {};
  for (const row of r.paths) {
    const key = `${row.gait} ${row.path}`;
    (paths[key] ??= []).push(row);
  }
  const pathRows = Object.entries(paths).map(([key, g]) => ({
    case: key,
    meanError: mean(g.map((p) => p.meanError)),
    worstMeanError: Math.max(...g.map((p) => p.meanError)),
    maxError: Math.max(...g.map((p) => p.maxError)),
    leastProgress: Math.min(...g.map((p) => p.arcProgress)),
    motionSeconds: mean(g.map((p) => p.seconds)),
    computeSeconds: mean(g.map((p) => p.optimizeMs)) / 1000,
    leastRealtime: Math.min(...g.map((p) => p.realtime)),
    speed: mean(g.map((p) => p.speed)),
    skatingBeforeLock: mean(g.map((p) => p.skatingBeforeLock)),
    skating: mean(g.map((p) => p.skating)),
    freeSkating: mean(g.map((p) => p.freeSkating)),
  }));
  // The five benchmark paths of the targets (arc progress does not measure the back-and-forth path, which doubles back).
  const walk = r.paths.filter((p) => p.gait === 'walk' && p.path !== 'back-and-forth');
  const scenarios = Object.keys(SCENARIOS).map((name) => {
    const g = r.control.filter((c) => c.scenario === name);
    return {
      scenario: name,
      headingResponse: g[0].kind === 'heading' ? g.map((c) => c.headingResponse) : null,
      speedAt1s: g.map((c) => c.speedAt1s),
      worstSpeedError: Math.max(...g.map((c) => c.speedError)),
      p95ms: Math.max(...g.map((c) => c.p95ms)),
      maxMs: Math.max(...g.map((c) => c.maxMs)),
      skating: mean(g.map((c) => c.skating)),
    };
  });
  const heads = r.control.filter((c) => c.kind === 'heading');
  return {
    paths: pathRows,
    walkWithinTargets: walk.every((p) => p.meanError <= T.meanError && p.arcProgress >= T.arcProgress && p.realtime >= T.realtime),
    scenarios,
    headingWithinLimits: heads.every((c) => c.reached && c.headingResponse <= c.limit),
    worstP95ms: Math.max(...r.control.map((c) => c.p95ms)),
    randomControlMinPoseChange: Math.min(...r.randomControl.map((x) => x.poseChange.min)),
  };
}

main().catch((err) => {
  console.error(err);
  process.exit(1);
});
