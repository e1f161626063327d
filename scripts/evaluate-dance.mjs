// A dance model judged through the page (issue 42): `generate` of --frames frames per style and seed in headless
// Chromium through the public API, each run judged by the fair freeze rule of training/aclstm/freeze_rule.py against
// the real held-out clips' reference stored in docs/models/aclstm.json (real_reference: median, share of low seconds),
// with jitter against the real clips' (real_jitter_cm there), all on what the page gives: the drawn frames (for a
// sampled model, through its output filter), fitted to the skeleton, feet planted.
//
//   node scripts/evaluate-dance.mjs [--model aclstm-mdn] [--frames 20000] [--seeds 5] [--out FILE.json]
//
// Rule, as freeze_rule.py states it: a second is low below 20% of the style's real median pose change; a run passes
// when (a) its share of low seconds is at most twice the real share, (b) no low stretch lasts 5 s, and (c) its median
// is at least half the real median. Jitter: mean |second difference| of the joints relative to the root (cm). The
// raised-foot share (training/aclstm/raised_foot.py): frames with the higher ankle over 0.3 m above the lowest point,
// against real_raised_foot there. All three are web/motion/freezeRule.ts, run in the page (its parity with Python:
// tests/unit/measuresParity.test.ts).
// Seeds 0..N-1 (not chosen by result); a link with the same model, style and seed shows the same dance.
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { launchBrowser, openPlayground, ROOT, startServer } from '../tests/support/browser.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const MODEL = option('--model', 'aclstm-mdn');
const FRAMES = Number(option('--frames', 20000));
const SEEDS = Number(option('--seeds', 5));
const OUT = option('--out', null);

const stored = JSON.parse(readFileSync(path.join(ROOT, 'docs/models/aclstm.json'), 'utf8'));
const fmt = (v, d = 2) => (Number.isFinite(v) ? v.toFixed(d) : String(v));

async function main() {
  const report = { date: new Date().toISOString().slice(0, 10), model: MODEL, frames: FRAMES, seeds: SEEDS, runs: [] };
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  try {
    const { page } = await openPlayground(browser, url);
    const info = await page.evaluate((id) => window.playground.models().find((m) => m.id === id), MODEL);
    if (!info) throw new Error(`${MODEL} is not listed in public/models/index.json`);
    for (const style of info.styles) {
      const ref = stored.real_reference[style];
      const realJitter = stored.real_jitter_cm[style];
      const realRaised = stored.real_raised_foot?.[style];
      for (let seed = 0; seed < SEEDS; seed++) {
        const r = await page.evaluate(async ({ model, style, frames, seed, ref }) => {
          const t = performance.now();
          const m = await window.playground.generate({ model, style, frames, seed });
          const ms = performance.now() - t;
          const { poseChangePerSecond } = await import('/motion/poseChange.ts');
          const { jitterCm, judgeFreeze, raisedFootShare } = await import('/motion/freezeRule.ts');
          const J = m.joints.length, p = m.positions;
          let rootMin = Infinity, rootMax = -Infinity;
          for (let f = 0; f < m.frames; f++) {
            rootMin = Math.min(rootMin, p[f * J * 3 + 1]);
            rootMax = Math.max(rootMax, p[f * J * 3 + 1]);
          }
          const verdict = judgeFreeze(poseChangePerSecond(p, J, m.fps), ref);
          return { ms, frames: m.frames, finite: p.every(Number.isFinite), verdict, jitterCm: jitterCm(p, J), raisedFoot: raisedFootShare(p, m.joints), rootHeight: [rootMin, rootMax] };
        }, { model: MODEL, style, frames: FRAMES, seed, ref });
        const verdict = r.verdict;
        const row = { style, seed, frames: r.frames, finite: r.finite, generateSeconds: r.ms / 1000, rootHeight: r.rootHeight, jitterVsReal: r.jitterCm / realJitter, raisedFoot: r.raisedFoot, ...verdict };
        report.runs.push(row);
        console.log(`${MODEL} ${style} seed ${seed}: ${r.frames} frames in ${fmt(row.generateSeconds, 0)} s, finite ${r.finite}, root ${fmt(r.rootHeight[0])}-${fmt(r.rootHeight[1])} m; low seconds ${fmt(100 * verdict.lowShare, 1)}% (real ${fmt(100 * ref.low_share, 1)}%), longest low ${verdict.longestLowS} s, median ${fmt(verdict.medianRatio)}x real; jitter ${fmt(row.jitterVsReal)}x real; a foot raised in ${fmt(100 * r.raisedFoot, 0)}% of frames${realRaised === undefined ? '' : ` (real ${fmt(100 * realRaised, 1)}%)`}; ${verdict.passes ? 'passes' : `FAILS (${['a', 'b', 'c'].filter((k) => !verdict[k]).join(', ')})`}`);
      }
    }
    const passed = report.runs.filter((r) => r.passes && r.finite).length;
    const range = (key, scale = 1, d = 2) => `${fmt(scale * Math.min(...report.runs.map((r) => r[key])), d)}-${fmt(scale * Math.max(...report.runs.map((r) => r[key])), d)}`;
    console.log(`${MODEL}: ${passed}/${report.runs.length} runs pass the fair rule through the page; jitter ${range('jitterVsReal')}x real; a foot raised in ${range('raisedFoot', 100, 0)}% of frames`);
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
