// A model pack of `python -m training.own` checked in the page as a user gets it (headless Chromium, the public API):
// loaded by a drop of its files and by `?models=`, then, for a dance pack, `generate` of 10,000 frames per seed in
// its style (finite, pose change per second against the held-out median on its card, seconds below 20% of it);
// for a locomotion pack
//   - Random walk's model streaming 10,000 frames per seed (generate, temperature 0.5 as Random walk): pose change per
//     second (web/motion/poseChange.ts) against the held-out clips' median on the pack's card, lowest second;
//   - foot sliding by both measures (web/motion/footSkating.ts) raw and after the page's foot lock
//     (web/motion/footLock.ts), against the held-out clips' sliding on the card (training/metrics.py, the same measures);
//   - Path: followPath on every benchmark path (tests/fixtures/benchmark_paths.json), walking and running, with the
//     control report's measures (mean and largest error, arc progress, coverage within 0.15 m, sliding after the lock).
//
//   node scripts/evaluate-pack.mjs PACK_DIR [--seeds 3] [--frames 10000] [--out FILE.json]
import { readdirSync, readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { launchBrowser, openPlayground, ROOT, startServer } from '../tests/support/browser.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : fallback;
};
const PACK_DIR = args.find((a, i) => !a.startsWith('--') && !(i > 0 && args[i - 1].startsWith('--')));
if (!PACK_DIR) {
  console.error('usage: node scripts/evaluate-pack.mjs PACK_DIR [--seeds 3] [--frames 10000] [--out FILE.json]');
  process.exit(2);
}
const SEEDS = Number(option('--seeds', 3));
const FRAMES = Number(option('--frames', 10_000));
const OUT = option('--out', null);
const PATHS = JSON.parse(readFileSync(path.join(ROOT, 'tests/fixtures/benchmark_paths.json'), 'utf8')).paths;
const FREEZE_FRACTION = 0.2;
const COVERAGE_TOLERANCE = 0.15;

const files = readdirSync(PACK_DIR).filter((f) => /\.(json|onnx|md|png)$/.test(f));
// The pack's JSON is the one with a "pack" field (as the page's readPack chooses).
const jsonName = files.filter((f) => f.endsWith('.json')).find((f) => 'pack' in JSON.parse(readFileSync(path.join(PACK_DIR, f), 'utf8')));
if (!jsonName) {
  console.error(`${PACK_DIR}: no JSON with a "pack" field: not a python -m training.own pack`);
  process.exit(2);
}
const info = JSON.parse(readFileSync(path.join(PACK_DIR, jsonName), 'utf8'));
const card = info.pack.measures;
if (info.kind !== 'aclstm' && !card?.real) {
  console.error(`${jsonName} has no pack.measures: not a finished python -m training.own pack`);
  process.exit(2);
}
const fmt = (v, d = 3) => (Number.isFinite(v) ? v.toFixed(d) : String(v));

async function main() {
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  const report = { pack: info.id, date: new Date().toISOString().slice(0, 10), seeds: SEEDS, frames: FRAMES, real: card?.real };
  try {
    const { context, page, problems } = await openPlayground(browser, url);
    await context.route(`${url}mypack/**`, (route) => {
      const name = new URL(route.request().url()).pathname.split('/').pop();
      if (!files.includes(name)) return route.fulfill({ status: 404, body: 'not here' });
      return route.fulfill({ status: 200, contentType: 'application/octet-stream', body: readFileSync(path.join(PACK_DIR, name)) });
    });

    // Loaded by a drop of its files.
    let t0 = Date.now();
    await page.evaluate(async (names) => {
      const data = new DataTransfer();
      for (const n of names) data.items.add(new File([await (await fetch(`mypack/${n}`)).arrayBuffer()], n));
      $uiFrame().dispatchEvent(new DragEvent('drop', { dataTransfer: data, bubbles: true, cancelable: true }));
    }, files);
    const pickers = info.kind === 'aclstm' ? ['dance-model'] : ['walk-model', 'path-model', 'steer-model'];
    await page.waitForFunction(({ id, picker }) => [...$ui(picker).options].some((o) => o.value === id), { id: info.id, picker: pickers[0] }, { timeout: 120_000 });
    report.dropLoad = { seconds: (Date.now() - t0) / 1000, listed: await page.evaluate(({ id, pickers }) => pickers.map((s) => [...$ui(s).options].find((o) => o.value === id)?.textContent), { id: info.id, pickers }) };
    console.log(`drop: listed in ${report.dropLoad.seconds.toFixed(1)} s as ${report.dropLoad.listed.join(' / ')}`);

    // Loaded by ?models= in a fresh page.
    const byUrl = await context.newPage();
    await byUrl.addInitScript(() => {
      window.$ui = (id) => document.querySelector('motion-playground')?.shadowRoot?.getElementById(id) ?? null;
    });
    t0 = Date.now();
    await byUrl.goto(`${url}?mode=clip&models=mypack/${jsonName}`, { waitUntil: 'load' });
    await byUrl.waitForFunction(({ id, picker }) => [...($ui(picker)?.options ?? [])].some((o) => o.value === id), { id: info.id, picker: pickers[0] }, { timeout: 120_000 });
    report.urlLoad = { seconds: (Date.now() - t0) / 1000 };
    console.log(`?models=: listed in ${report.urlLoad.seconds.toFixed(1)} s`);
    await byUrl.close();

    if (info.kind === 'aclstm') {
      report.dance = [];
      for (const style of info.styles) {
      const median = info.real_pose_change[style];
      for (let seed = 0; seed < SEEDS; seed++) {
        const r = await page.evaluate(
          async ({ id, style, frames, seed }) => {
            const t = performance.now();
            const m = await window.playground.generate({ model: id, style, frames, seed });
            const ms = performance.now() - t;
            const { poseChangePerSecond } = await import('/motion/poseChange.ts');
            const root = [];
            for (let f = 0; f < m.frames; f++) root.push(m.positions[f * m.joints.length * 3 + 1]);
            return { ms, frames: m.frames, finite: m.positions.every(Number.isFinite), seconds: poseChangePerSecond(m.positions, m.joints.length, m.fps), rootHeight: [Math.min(...root), Math.max(...root)] };
          },
          { id: info.id, style, frames: FRAMES, seed },
        );
        const sorted = [...r.seconds].sort((a, b) => a - b);
        const row = {
          style, seed, frames: r.frames, finite: r.finite, generateSeconds: r.ms / 1000, rootHeight: r.rootHeight,
          medianRatio: sorted[Math.floor(sorted.length / 2)] / median, lowestRatio: sorted[0] / median,
          secondsBelowFreeze: r.seconds.filter((v) => v < FREEZE_FRACTION * median).length, seconds: r.seconds.length,
        };
        report.dance.push(row);
        console.log(`dance ${style} seed ${seed}: ${row.frames} frames in ${fmt(row.generateSeconds, 1)} s, finite ${row.finite}, root height ${fmt(row.rootHeight[0], 2)}-${fmt(row.rootHeight[1], 2)} m; median pose change ${fmt(row.medianRatio, 2)}x the held-out median, ${row.secondsBelowFreeze}/${row.seconds} s below 20%`);
      }
      }
      report.problems = problems;
      return;
    }

    // Random walk's model, 10,000 frames per seed.
    report.stream = [];
    for (let seed = 0; seed < SEEDS; seed++) {
      const r = await page.evaluate(
        async ({ id, frames, seed, offsets }) => {
          const t = performance.now();
          const m = await window.playground.generate({ model: id, frames, seed, temperature: 0.5 });
          const ms = performance.now() - t;
          const { poseChangePerSecond } = await import('/motion/poseChange.ts');
          const { footSkating, lowFootSliding } = await import('/motion/footSkating.ts');
          const { footLock } = await import('/motion/footLock.ts');
          const seconds = poseChangePerSecond(m.positions, m.joints.length, m.fps);
          const locked = { ...m, positions: footLock(m.positions, m.contacts, m.joints, offsets) };
          return {
            ms, frames: m.frames, finite: m.positions.every(Number.isFinite), seconds,
            skating: footSkating(m), sliding: lowFootSliding(m), skatingLocked: footSkating(locked), slidingLocked: lowFootSliding(locked),
          };
        },
        { id: info.id, frames: FRAMES, seed, offsets: info.skeleton.offsets },
      );
      const median = card.real.median_pose_change;
      const sorted = [...r.seconds].sort((a, b) => a - b);
      const row = {
        seed, frames: r.frames, finite: r.finite, generateSeconds: r.ms / 1000,
        lowestSecond: sorted[0], lowestRatio: sorted[0] / median, medianRatio: sorted[Math.floor(sorted.length / 2)] / median,
        secondsBelowFreeze: r.seconds.filter((s) => s < FREEZE_FRACTION * median).length, seconds: r.seconds.length,
        skating: r.skating, sliding: r.sliding, skatingLocked: r.skatingLocked, slidingLocked: r.slidingLocked,
      };
      report.stream.push(row);
      console.log(`stream seed ${seed}: ${row.frames} frames in ${fmt(row.generateSeconds, 1)} s, finite ${row.finite}; lowest second ${fmt(row.lowestRatio, 2)}x the held-out median, median ${fmt(row.medianRatio, 2)}x, ${row.secondsBelowFreeze}/${row.seconds} s below 20%; sliding raw ${fmt(row.sliding)} locked ${fmt(row.slidingLocked)} m/s (held-out ${fmt(card.real.sliding_low_foot)}), contact bits raw ${fmt(row.skating)} locked ${fmt(row.skatingLocked)} (held-out ${fmt(card.real.sliding_contact_bits)})`);
    }

    // Path mode's follower on every benchmark path.
    report.paths = [];
    for (const gait of ['walk', 'run']) {
      for (const [name, p] of Object.entries(PATHS)) {
        for (let seed = 0; seed < SEEDS; seed++) {
          const r = await page.evaluate(
            async ({ id, points, gait, seed, tolerance }) => {
              const m = await window.playground.followPath({ model: id, points, gait, seed });
              const { pathCoverage, rootGroundTrack } = await import('/motion/pathCoverage.ts');
              const coverage = pathCoverage(points, rootGroundTrack(m.positions, m.joints.length, m.frames), tolerance);
              return { frames: m.frames, finite: m.positions.every(Number.isFinite), coverage, stats: m.stats };
            },
            { id: info.id, points: p.points, gait, seed, tolerance: COVERAGE_TOLERANCE },
          );
          const row = { path: name, gait, seed, frames: r.frames, finite: r.finite, coverage: r.coverage, ...r.stats };
          report.paths.push(row);
          console.log(`${gait} ${name} seed ${seed}: error mean ${fmt(row.meanError)} max ${fmt(row.maxError)} m, progress ${fmt(row.arcProgress * 100, 1)}%, coverage ${fmt(row.coverage * 100, 1)}%, sliding ${fmt(row.sliding)} (before lock ${fmt(row.slidingBeforeLock)}) m/s, ${fmt(row.optimizeMs / 1000, 1)} s`);
        }
      }
    }
    report.problems = problems;
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
