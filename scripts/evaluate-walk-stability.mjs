// Long walks seen from outside (issue 39): `generate` of --frames frames per seed (and style, for a model with styles)
// in headless Chromium through the public API, each stream's per-second pose change (web/motion/poseChange.ts) against
// the real held-out walks' median: stable when no second falls below 20% of it (the freeze line of the reports), every
// value is finite and the hips stay in 0.4-1.3 m. The real medians are the reports': docs/models/generator.json (CMU
// walks) and, per style, docs/models/style-generator-shipped.json.
//
//   node scripts/evaluate-walk-stability.mjs [--model generator] [--seeds 11,12,13] [--frames 10000] [--styles a,b]
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { launchBrowser, openPlayground, ROOT, startServer } from '../tests/support/browser.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const MODEL = option('--model', 'generator');
const SEEDS = option('--seeds', '11,12,13').split(',').map(Number);
const FRAMES = Number(option('--frames', 10000));
const FREEZE_FRACTION = 0.2;
const HIPS = [0.4, 1.3];
const readJson = (file) => JSON.parse(readFileSync(path.join(ROOT, file), 'utf8'));

/** The real held-out walks' median pose change (m/s) for `style` (undefined: the CMU walks). */
function realMedian(style) {
  if (style === undefined) return readJson('docs/models/generator.json').real.median_pose_change;
  const real = readJson('docs/models/style-generator-shipped.json').long_runs.styles[style]?.real;
  if (!real) throw new Error(`no real reference for style ${style} in docs/models/style-generator-shipped.json`);
  return real.pose_change_median;
}

async function main() {
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  let unstable = 0;
  try {
    const { page } = await openPlayground(browser, url);
    const info = await page.evaluate(async (id) => {
      await window.playground.ready;
      return window.playground.models().find((m) => m.id === id);
    }, MODEL);
    if (!info) throw new Error(`${MODEL} is not listed in public/models/index.json`);
    const styles = info.styles?.length ? (option('--styles', null)?.split(',') ?? info.styles) : [undefined];
    for (const style of styles) {
      const median = realMedian(style);
      for (const seed of SEEDS) {
        const r = await page.evaluate(async ({ model, frames, seed, style }) => {
          const m = await window.playground.generate({ model, frames, seed, ...(style ? { style } : {}) });
          const { poseChangePerSecond } = await import('/motion/poseChange.ts');
          const seconds = poseChangePerSecond(m.positions, m.joints.length, m.fps);
          const J = m.joints.length;
          let hipsMin = Infinity, hipsMax = -Infinity;
          for (let f = 0; f < m.frames; f++) {
            hipsMin = Math.min(hipsMin, m.positions[f * J * 3 + 1]);
            hipsMax = Math.max(hipsMax, m.positions[f * J * 3 + 1]);
          }
          let lowest = 0;
          seconds.forEach((v, k) => { if (v < seconds[lowest]) lowest = k; });
          return { frames: m.frames, finite: m.positions.every(Number.isFinite), seconds, lowest, hips: [hipsMin, hipsMax] };
        }, { model: MODEL, frames: FRAMES, seed, style });
        const below = r.seconds.filter((v) => v < FREEZE_FRACTION * median).length;
        const stable = r.finite && below === 0 && r.hips[0] >= HIPS[0] && r.hips[1] <= HIPS[1];
        if (!stable) unstable++;
        console.log(`${MODEL}${style ? ` ${style}` : ''} seed ${seed}: ${r.frames} frames; lowest second ${(r.seconds[r.lowest] / median).toFixed(2)}x the real median (second ${r.lowest} of ${r.seconds.length}); ` +
          `${below} seconds below the freeze line; hips ${r.hips[0].toFixed(2)}-${r.hips[1].toFixed(2)} m; ${stable ? 'stable' : 'NOT STABLE'}`);
      }
    }
    console.log(`${MODEL}: ${unstable ? `${unstable} unstable streams` : 'every stream stable'}`);
  } finally {
    await browser.close();
    await server.close();
  }
}

main().catch((err) => {
  console.error(err);
  process.exit(1);
});
