// Memory family (issue 43): <motion-playground> elements added to a page and removed again, round after
// round, as a single-page site does when it navigates. Measured: live Workers (created minus terminated, an
// init script wraps window.Worker), live WebGL contexts, the page's JS heap after a forced collection (CDP
// Performance.getMetrics JSHeapUsedSize) and the resident memory of the browser's renderer and GPU processes
// (ps; software GL keeps its buffers in the GPU process). Target: after the rounds the workers are back where
// they started, heap and renderer memory within 10 % of the start.
import { addAndRemove, installCounters, sample, serveSite, sitePage } from '../support/lifecycle.mjs';
import { VIEWPORT } from './common.mjs';

const ROUNDS = Number(process.env.BENCH_ROUNDS ?? 10);
const PER_ROUND = 7;

async function churnBenchmark(ctx) {
  const context = await ctx.browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  try {
    await serveSite(context, ctx.url, { 'empty.html': sitePage('') });
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (e) => problems.push(e.message));
    await page.addInitScript(installCounters);
    await page.goto(`${ctx.url}site/empty.html`, { waitUntil: 'load' });
    await page.waitForFunction(() => customElements.get('motion-playground') !== undefined);
    const cdp = await page.context().newCDPSession(page);
    await cdp.send('Performance.enable');
    // A first round loads the modules, onnxruntime and the shared downloads: the start is measured after it.
    await addAndRemove(page, PER_ROUND);
    await page.waitForTimeout(1500);
    const start = await sample(page, cdp);
    const rounds = [];
    let shown = 0;
    for (let r = 0; r < ROUNDS; r++) {
      shown += await addAndRemove(page, PER_ROUND);
      await page.waitForTimeout(1000);
      rounds.push(await sample(page, cdp));
    }
    const end = rounds[rounds.length - 1];
    const peakWorkers = Math.max(...rounds.map((x) => x.workers));
    return {
      rounds: ROUNDS,
      per_round: PER_ROUND,
      shown_motion: `${shown}/${ROUNDS * PER_ROUND}`,
      workers_start: start.workers,
      workers_end: end.workers,
      workers_peak_after_removal: peakWorkers,
      contexts_end: end.contexts,
      heap_start_mb: start.heapMB,
      heap_end_mb: end.heapMB,
      heap_change_pct: +((100 * (end.heapMB - start.heapMB)) / start.heapMB).toFixed(1),
      renderer_start_mb: start.rendererMB,
      renderer_end_mb: end.rendererMB,
      renderer_change_pct: start.rendererMB ? +((100 * (end.rendererMB - start.rendererMB)) / start.rendererMB).toFixed(1) : null,
      per_round_samples: rounds.map((x) => `${x.workers}w ${x.contexts}gl ${x.heapMB}MB ${x.rendererMB}MB`).join(' | '),
      page_errors: problems.length,
    };
  } finally {
    await context.close();
  }
}

export const BENCHMARKS = [
  {
    name: 'element-churn',
    description: `${PER_ROUND} elements added and removed, ${ROUNDS} rounds after a warm-up round: workers, WebGL contexts, JS heap (after GC) and renderer+GPU process RSS — target: workers back to the start, heap and renderer within 10 %`,
    run: churnBenchmark,
    summary: (r) =>
      `workers ${r.workers_start} → ${r.workers_end} (peak after removal ${r.workers_peak_after_removal}), WebGL contexts left ${r.contexts_end};` +
      ` JS heap ${r.heap_start_mb} → ${r.heap_end_mb} MB (${r.heap_change_pct} %), renderer+GPU RSS ${r.renderer_start_mb} → ${r.renderer_end_mb} MB` +
      ` (${r.renderer_change_pct} %); ${r.shown_motion} elements showed motion before removal`,
  },
];
