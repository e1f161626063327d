// Running that lasts (issue 39): does followPath({ gait: 'run' }) keep a running gait over a 60 m path? Toe swing per
// second (web/motion/toeSwing.ts) of every path-following model, in headless Chromium through the public API, against
// real runs measured the same way (the same TypeScript function, in Node, on the Bandai Namco runs of every style and
// on the set's walks for contrast; each clip on its own, never joined).
//
//   node scripts/evaluate-running.mjs [--seeds 3] [--models generator,latent-erd,vae-lstm,style-generator:normal]
//                                     [--steer generator,style-generator:normal] [--out FILE.json]
//
// A model with styles is named with its style (`id:style`). --steer also runs simulateControl (Steer's live loop)
// for 45 s at 3.5 m/s (about 60 m of running), turning gently (heading ±0.5 rad every 15 s).
// A second "runs" when its toe swing is at least half the real runs' median; the report gives, per run, the share of
// running seconds and where the first stretch of 3 s without a running second starts ("stops after"), and issue 39's
// criterion: the lowest second's toe swing as a share of the real runs' median (done when >= 80% in every second).
import { readdirSync, readFileSync, writeFileSync } from 'node:fs';
import { gunzipSync } from 'node:zlib';
import path from 'node:path';
import { createServer } from 'vite';
import { launchBrowser, openPlayground, MOCAP, ROOT, startServer } from '../tests/support/browser.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const SEEDS = Number(option('--seeds', 3));
const OUT = option('--out', null);
const RUN_FRACTION = 0.5;
const STOPPED_S = 3; // the gait has stopped running once it goes this many seconds without a running one
// Two paths: straight, 60 m, and a gentle S (a sine of 6 m amplitude over 58 m: about 63 m long, tightest radius about 14 m).
const STRAIGHT = Array.from({ length: 61 }, (_, i) => [0, i]);
const S_CURVE = Array.from({ length: 61 }, (_, i) => {
  const a = (i / 60) * Math.PI * 2;
  return [Number((6 * Math.sin(a)).toFixed(3)), i * 0.96];
});
const PATHS = { 'straight 60 m': STRAIGHT, 's-curve 60 m': S_CURVE };

const median = (v) => {
  const s = [...v].sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
};
const fmt = (v, d = 2) => (Number.isFinite(v) ? v.toFixed(d) : String(v));

/** The TypeScript measures, loaded through Vite in Node (the same code the page runs). */
async function nodeModules() {
  const vite = await createServer({ configFile: path.join(ROOT, 'vite.config.ts'), logLevel: 'error', server: { middlewareMode: true, hmr: false, watch: null } });
  const { toeSwingPerSecond } = await vite.ssrLoadModule('/motion/toeSwing.ts');
  const { parseBVH } = await vite.ssrLoadModule('/motion/bvh.ts');
  return { vite, toeSwingPerSecond, parseBVH };
}

function realSwing({ toeSwingPerSecond, parseBVH }, content) {
  const dir = path.join(MOCAP, 'bandai', 'bvh');
  const files = readdirSync(dir).filter((f) => f.startsWith(`dataset-2_${content}_`)).sort();
  const picked = files.filter((_, i) => i % 10 === 0); // a spread over every style
  const seconds = picked.flatMap((f) => toeSwingPerSecond(parseBVH(gunzipSync(readFileSync(path.join(dir, f))).toString())));
  return { clips: picked.length, seconds: seconds.length, median: median(seconds), p10: [...seconds].sort((a, b) => a - b)[Math.floor(seconds.length / 10)] };
}

/** The share of running seconds, and where the first stretch of STOPPED_S or more non-running seconds starts (null: none). */
function judge(seconds, line) {
  const running = seconds.map((s) => s >= line);
  let stopsAfter = null;
  for (let k = 0, stretch = 0; k < running.length && stopsAfter === null; k++) {
    stretch = running[k] ? 0 : stretch + 1;
    if (stretch === STOPPED_S) stopsAfter = k + 1 - STOPPED_S;
  }
  return { share: running.filter(Boolean).length / seconds.length, stopsAfter, seconds: seconds.length };
}

async function main() {
  const node = await nodeModules();
  const real = { run: realSwing(node, 'run'), walk: realSwing(node, 'walk') };
  await node.vite.close();
  const line = RUN_FRACTION * real.run.median;
  console.log(`real Bandai runs: toe swing median ${fmt(real.run.median)} m/s (p10 ${fmt(real.run.p10)}) over ${real.run.seconds} s of ${real.run.clips} clips; walks ${fmt(real.walk.median)} (p10 ${fmt(real.walk.p10)}); a running second: >= ${fmt(line)} m/s`);
  const report = { date: new Date().toISOString().slice(0, 10), real, line, runs: [] };
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  try {
    const { page } = await openPlayground(browser, url);
    const listed = await page.evaluate(() => window.playground.models().map((m) => m.id));
    const asked = option('--models', 'generator,latent-erd,vae-lstm').split(',');
    const unknown = [...asked, ...option('--steer', '').split(',').filter(Boolean)].filter((m) => !listed.includes(m.split(':')[0]));
    if (unknown.length) throw new Error(`not listed in models/index.json: ${unknown.join(', ')} (listed: ${listed.join(', ')})`);
    const lowest = (swing) => Math.min(...swing) / real.run.median;
    for (const entry of asked) {
      const [model, style] = entry.split(':');
      for (const [name, points] of Object.entries(PATHS)) {
        for (let seed = 0; seed < SEEDS; seed++) {
          const r = await page.evaluate(async ({ model, style, points, seed }) => {
            const m = await window.playground.followPath({ model, points, gait: 'run', seed, ...(style ? { style } : {}) });
            const { toeSwingPerSecond } = await import('/motion/toeSwing.ts');
            return { frames: m.frames, fps: m.fps, swing: toeSwingPerSecond(m), stats: m.stats };
          }, { model, style, points, seed });
          const verdict = judge(r.swing, line);
          report.runs.push({ model: entry, path: name, seed, ...verdict, lowestShare: lowest(r.swing), medianSwing: median(r.swing), swing: r.swing, meanError: r.stats.meanError, arcProgress: r.stats.arcProgress });
          console.log(`${entry} ${name} seed ${seed}: ${verdict.seconds} s, toe swing median ${fmt(median(r.swing))} m/s, lowest second ${fmt(lowest(r.swing) * 100, 0)}% of real runs', running ${fmt(verdict.share * 100, 0)}% of seconds, ${verdict.stopsAfter === null ? 'never stops for 3 s' : `stops after ${verdict.stopsAfter} s`}; path error ${fmt(r.stats.meanError)} m, progress ${fmt(r.stats.arcProgress * 100, 0)}%`);
        }
      }
    }
    const steered = option('--steer', '').split(',').filter(Boolean);
    for (const entry of steered) {
      const [model, style] = entry.split(':');
      for (let seed = 0; seed < SEEDS; seed++) {
        const r = await page.evaluate(async ({ model, style, seed }) => {
          const schedule = [{ t: 0, speed: 3.5, heading: 0 }, { t: 15, speed: 3.5, heading: 0.5 }, { t: 30, speed: 3.5, heading: -0.5 }];
          const m = await window.playground.simulateControl({ model, seconds: 45, schedule, gait: 'run', seed, ...(style ? { style } : {}) });
          const { toeSwingPerSecond } = await import('/motion/toeSwing.ts');
          const speeds = Array.from(m.speed ?? []);
          return { frames: m.frames, swing: toeSwingPerSecond(m), meanSpeed: speeds.reduce((a, b) => a + b, 0) / Math.max(1, speeds.length) };
        }, { model, style, seed });
        const verdict = judge(r.swing, line);
        report.runs.push({ model: entry, path: 'steer 45 s at 3.5 m/s', seed, ...verdict, lowestShare: lowest(r.swing), medianSwing: median(r.swing), swing: r.swing, meanSpeed: r.meanSpeed });
        console.log(`${entry} steer 45 s at 3.5 m/s seed ${seed}: toe swing median ${fmt(median(r.swing))} m/s, lowest second ${fmt(lowest(r.swing) * 100, 0)}% of real runs', running ${fmt(verdict.share * 100, 0)}% of seconds, ${verdict.stopsAfter === null ? 'never stops for 3 s' : `stops after ${verdict.stopsAfter} s`}; mean speed ${fmt(r.meanSpeed)} m/s`);
      }
    }
  } finally {
    await browser.close();
    await server.close();
    if (OUT) writeFileSync(OUT, JSON.stringify(report, null, 1) + '\n');
  }
}

main().catch((err) => {
  console.error(err);
  process.exit(1);
});
