// Your own character (issue 40): loadCharacter of a ~3 MB GLB (goal ≤ 1 s), and Random walk drawn with a 30k-vertex
// character of the user's (goal 60 fps), with what retargeting each live chunk costs the page (its
// "character-retarget" performance entries: only a chunk's new frames are retargeted, web/viewer/userCharacter.ts).
// The GLBs are made in the page (tests/support/characterRigs.mjs: a generated skinned humanoid of that size).
import { ROOT, openPlayground } from '../support/browser.mjs';
import { displayFields, liveModeSummary, measureFrames, SECONDS, VIEWPORT, WARMUP_SECONDS } from './common.mjs';

const RIGS = `/@fs${ROOT}tests/support/characterRigs.mjs`;

/** loadCharacter of a generated ~3 MB rig, `runs` times: median and worst milliseconds. */
async function loadBenchmark(ctx, runs = 7) {
  const { context, page, problems } = await openPlayground(ctx.browser, `${ctx.url}?mode=clip`, VIEWPORT);
  try {
    const r = await page.evaluate(
      async ({ rigsUrl, runs }) => {
        const rigs = await import(rigsUrl);
        const bytes = await rigs.makeRig({ naming: 'mixamo', scale: 0.01, pose: 'A', vertices: 62_000 });
        const times = [];
        let info;
        for (let i = 0; i < runs; i++) {
          const started = performance.now();
          info = await window.playground.loadCharacter(bytes.slice());
          times.push(performance.now() - started);
        }
        return { bytes: bytes.length, vertices: info.vertices, bones: info.bones.length, times };
      },
      { rigsUrl: RIGS, runs },
    );
    const sorted = [...r.times].sort((a, b) => a - b);
    return {
      file_mb: +(r.bytes / 1e6).toFixed(2),
      vertices: r.vertices,
      bones: r.bones,
      runs,
      first_ms: Math.round(r.times[0]),
      median_ms: Math.round(sorted[Math.floor(sorted.length / 2)]),
      max_ms: Math.round(sorted[sorted.length - 1]),
      target_ms: 1000,
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

/** Random walk with the user's character of about `vertices` vertices: display rate, stream rate, retargeting cost. */
async function walkBenchmark(ctx, vertices, query = '') {
  const { context, page, problems } = await openPlayground(ctx.browser, `${ctx.url}?mode=clip${query}`, VIEWPORT);
  const streamFrame = () => page.evaluate(() => Number($ui('walk-status').dataset.frame));
  try {
    const loaded = await page.evaluate(
      async ({ rigsUrl, vertices }) => {
        const rigs = await import(rigsUrl);
        return window.playground.loadCharacter(await rigs.makeRig({ naming: 'mixamo', scale: 0.01, pose: 'A', vertices }));
      },
      { rigsUrl: RIGS, vertices },
    );
    await page.click('#mode-walk');
    await page.waitForFunction(() => Number($ui('walk-status').dataset.frame) > 0, null, { timeout: 60_000 });
    await page.waitForTimeout(WARMUP_SECONDS * 1000);
    await page.evaluate(() => performance.clearMeasures('character-retarget'));
    const f0 = await streamFrame();
    const frames = await measureFrames(page, SECONDS);
    const f1 = await streamFrame();
    const stats = await page.evaluate(() => window.playground.stats());
    const retargets = await page.evaluate(() => performance.getEntriesByName('character-retarget').map((e) => ({ ms: e.duration, frames: e.detail.frames })));
    const ms = retargets.map((r) => r.ms);
    return {
      viewport: `${VIEWPORT.width}x${VIEWPORT.height}`,
      ...frames,
      target_fps: 60,
      stream_frames_per_s: +((f1 - f0) / SECONDS).toFixed(1),
      target_stream_frames_per_s: 30,
      character_vertices: stats.characterVertices,
      loaded_vertices: loaded.vertices,
      retargets: retargets.length,
      retarget_frames: retargets.reduce((s, r) => s + r.frames, 0),
      retarget_mean_ms: ms.length ? +(ms.reduce((a, b) => a + b, 0) / ms.length).toFixed(1) : null,
      retarget_max_ms: ms.length ? +Math.max(...ms).toFixed(1) : null,
      ...displayFields(stats, problems),
    };
  } finally {
    await context.close();
  }
}

const walkSummary = (r) =>
  `${liveModeSummary(r)}, ${r.character_vertices} character vertices; retargeting ${r.retargets} chunks (${r.retarget_frames} frames): mean ${r.retarget_mean_ms} ms, max ${r.retarget_max_ms} ms`;

export const BENCHMARKS = [
  {
    name: 'load-character-3mb',
    description: 'playground.loadCharacter of a ~3 MB GLB (a generated skinned humanoid, 62k vertices, Mixamo names, 0.01 scale) — target ≤ 1000 ms',
    run: (ctx) => loadBenchmark(ctx),
    summary: (r) => `${r.file_mb} MB, ${r.vertices} vertices, ${r.bones} bones: median ${r.median_ms} ms, worst ${r.max_ms} ms, first ${r.first_ms} ms of ${r.runs} (target ≤ ${r.target_ms} ms)`,
  },
  {
    name: 'random-walk-own-character-30k',
    description: 'Random walk drawn with a 30k-vertex character of the user\'s (loadCharacter), default quality — target 60 fps',
    run: (ctx) => walkBenchmark(ctx, 30_000),
    summary: walkSummary,
  },
  {
    name: 'random-walk-own-character-30k-high',
    description: 'The same at ?quality=high (MSAA, shadow map) — target 60 fps with a GPU',
    run: (ctx) => walkBenchmark(ctx, 30_000, '&quality=high'),
    summary: walkSummary,
  },
];
