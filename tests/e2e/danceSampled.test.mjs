// A sampled dance model (issue 42: `head: "mdn"` in its JSON) in the page: generate reproduces a dance from its seed
// and another seed with the same seed motion dances differently; temperature is refused with the reason; Dance mode
// keeps a link's seed past the seed motions (every seed is its own dance) and dances. The model is the first aclstm
// entry of public/models/index.json whose JSON has head "mdn"; until one is listed the suite is skipped.
// ACLSTM_MDN_DIR=<dir> serves a development export (<id>.json and <id>.onnx in dir) as one more manifest entry instead.
import assert from 'node:assert/strict';
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { installUiLookups, launchBrowser, ROOT, startServer, waitUntil } from './harness.mjs';

/** { id, info, dir, extra }: the sampled model, where its files are, and whether it must be added to the manifest. */
function findModel() {
  const dev = process.env.ACLSTM_MDN_DIR;
  if (dev) {
    const file = readdirSync(dev).find((f) => f.endsWith('.json') && JSON.parse(readFileSync(path.join(dev, f), 'utf8')).head === 'mdn');
    if (!file) throw new Error(`ACLSTM_MDN_DIR=${dev} holds no JSON with head "mdn"`);
    return { id: file.replace(/\.json$/, ''), info: JSON.parse(readFileSync(path.join(dev, file), 'utf8')), dir: dev, extra: true };
  }
  const models = path.join(ROOT, 'public', 'models');
  for (const entry of JSON.parse(readFileSync(path.join(models, 'index.json'), 'utf8')).models) {
    const json = path.join(models, `${entry.id}.json`);
    if (entry.kind !== 'aclstm' || !existsSync(json)) continue;
    const info = JSON.parse(readFileSync(json, 'utf8'));
    if (info.head === 'mdn') return { id: entry.id, info, dir: models, extra: false };
  }
  return undefined;
}

const MODEL = findModel();

describe('a sampled dance model in the page', { skip: !MODEL && 'no sampled (head "mdn") dance model is listed yet', timeout: 300_000 }, () => {
  const s = {};
  before(async () => {
    Object.assign(s, await startServer());
    s.browser = await launchBrowser();
  });
  after(async () => {
    await s.browser?.close();
    await s.server?.close();
  });

  /** A fresh page at `query` (with a development export, served as one more manifest entry); its errors collected. */
  async function open(query) {
    const context = await s.browser.newContext({ viewport: { width: 1280, height: 800 } });
    if (MODEL.extra) {
      const { id, info, dir } = MODEL;
      await context.route('**/models/index.json', async (route) => {
        const res = await route.fetch();
        const body = await res.json();
        body.models.push({ id, kind: 'aclstm', skeleton: 'aclstm-standard', fps: info.fps, styles: info.styles, bytes: info.bytes, file: info.file });
        await route.fulfill({ response: res, json: body });
      });
      await context.route(`**/models/${id}.*`, (route) => {
        const name = decodeURIComponent(new URL(route.request().url()).pathname.split('/').pop());
        return route.fulfill({ body: readFileSync(path.join(dir, name)), contentType: name.endsWith('.json') ? 'application/json' : 'application/octet-stream' });
      });
    }
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
    page.on('console', (m) => m.type() === 'error' && problems.push(`console.error: ${m.text()}`));
    await page.addInitScript(installUiLookups);
    await page.goto(`${s.url}?${query}`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.playground !== undefined, null, { timeout: 30_000 });
    await page.evaluate(() => window.playground.ready);
    return { page, problems, context };
  }

  test('generate: a seed reproduces its dance, another seed with the same seed motion dances differently, temperature is refused', async () => {
    const { page, problems, context } = await open('mode=clip');
    const count = MODEL.info.seeds.filter((x) => x.style === 'indian').length;
    const r = await page.evaluate(
      async ({ model, count }) => {
        const digest = async (seed) => {
          const m = await window.playground.generate({ model, style: 'indian', frames: 90, seed });
          let h = 0;
          for (let i = 0; i < m.positions.length; i++) h = (Math.imul(h, 31) + Math.round(m.positions[i] * 1e5)) | 0;
          return { h, finite: m.positions.every(Number.isFinite), frames: m.frames };
        };
        let refused = '';
        try {
          await window.playground.generate({ model, style: 'indian', frames: 5, seed: 0, temperature: 0.3 });
        } catch (e) {
          refused = e.message;
        }
        return { a: await digest(1), again: await digest(1), sameMotion: await digest(1 + count), refused };
      },
      { model: MODEL.id, count },
    );
    assert.deepEqual(r.again, r.a, 'the same style and seed give the same dance');
    assert.notEqual(r.sameMotion.h, r.a.h, `seed ${1 + count} starts from seed 1's seed motion but draws other numbers`);
    assert.equal(r.a.frames, 90);
    assert.ok(r.a.finite);
    assert.match(r.refused, /^generate: temperature is not meaningful for acLSTM models: .*a sampled one draws with its own per-style settings/);
    assert.deepEqual(problems, []);
    await context.close();
  });

  test('Dance mode keeps a link’s seed past the seed motions, and dances', async () => {
    const { page, problems, context } = await open(`mode=dance&model=${MODEL.id}&style=martial&seed=13`);
    await waitUntil(page, () => Number($ui('dance-status').dataset.frame ?? 0) > 60, undefined, { timeout: 60_000, message: 'the sampled model never danced 60 frames' });
    const ui = await page.evaluate(() => ({
      seed: $ui('dance-seed').value,
      label: $ui('dance-seed').selectedOptions[0]?.textContent,
      options: $ui('dance-seed').options.length,
      search: location.search,
    }));
    const count = MODEL.info.seeds.filter((x) => x.style === 'martial').length;
    const motion = MODEL.info.seeds.filter((x) => x.style === 'martial')[13 % count].name;
    assert.equal(ui.seed, '13');
    assert.equal(ui.label, `${motion} · seed 13`);
    assert.equal(ui.options, count + 1);
    assert.match(ui.search, /seed=13/);
    assert.deepEqual(problems, []);
    await context.close();
  });
});
