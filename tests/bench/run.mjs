// Benchmarks of the page in headless Chromium (software GL here). Not a pass/fail test: each benchmark
// prints one JSON line (machine-readable) and the run ends with a human summary.
//
//   npm run bench                    # all benchmarks
//   npm run bench -- playback-auto   # only the named ones
//   BENCH_SECONDS=10 npm run bench   # longer measuring windows
//
// The benchmarks live in one file per family (FAMILIES below), each exporting BENCHMARKS: a list of
// { name, description, run(ctx), summary(result) }. run() returns an object of metrics (ctx gives the
// browser and the served URL); summary() returns the benchmark's line(s) of the human summary. Add a
// benchmark to its family's list; shared helpers are in common.mjs.
import { launchBrowser, startServer } from '../support/browser.mjs';
import * as aclstm from './aclstm.mjs';
import * as character from './character.mjs';
import * as userCharacter from './userCharacter.mjs';
import * as cleanup from './cleanup.mjs';
import * as control from './control.mjs';
import * as firstFrame from './firstFrame.mjs';
import * as generator from './generator.mjs';
import * as largeImport from './largeImport.mjs';
import * as memory from './memory.mjs';
import * as peers from './peers.mjs';
import * as playback from './playback.mjs';

/** In the order `npm run bench` runs them. */
const FAMILIES = [playback, generator, character, userCharacter, aclstm, control, peers, firstFrame, largeImport, cleanup, memory];
const BENCHMARKS = FAMILIES.flatMap((family) => family.BENCHMARKS);

async function main() {
  const wanted = process.argv.slice(2);
  const unknown = wanted.filter((w) => !BENCHMARKS.some((b) => b.name === w));
  if (unknown.length) {
    console.error(`unknown benchmark(s): ${unknown.join(', ')}; known: ${BENCHMARKS.map((b) => b.name).join(', ')}`);
    process.exit(2);
  }
  const chosen = wanted.length ? BENCHMARKS.filter((b) => wanted.includes(b.name)) : BENCHMARKS;
  const { server, url } = await startServer();
  const browser = await launchBrowser();
  const results = [];
  try {
    for (const b of chosen) {
      const started = Date.now();
      let result;
      try {
        result = { bench: b.name, ok: true, ...(await b.run({ browser, url })) };
      } catch (e) {
        result = { bench: b.name, ok: false, error: String(e?.message ?? e) };
      }
      result.seconds = +((Date.now() - started) / 1000).toFixed(1);
      console.log(JSON.stringify(result));
      results.push({ b, result });
    }
  } finally {
    await browser.close();
    await server.close();
  }
  console.log('\nSummary');
  for (const { b, result: r } of results) {
    console.log(r.ok ? `  ${b.name}: ${b.summary(r)}\n    ${b.description}` : `  ${b.name}: FAILED — ${r.error}`);
  }
  const renderer = results.find((x) => x.result.renderer)?.result.renderer;
  if (renderer) console.log(`  WebGL: ${renderer}`);
}

await main();
