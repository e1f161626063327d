// A user's model pack (python -m training.own … --out OUT; tests/fixtures/packs/my-walks is a 30-iteration run on
// three CMU clips, my-dance a 30-iteration --kind dance run on three acLSTM salsa files) loaded by the page: dropped as its files, as a folder (the drop's entries walked) and as its
// .zip, from the element's `models` attribute, from the page's `?models=` parameter and playground.loadModels. Its
// model is listed in the Random walk, Path and Steer pickers as the user's, streams a random walk and follows a path
// (a dance pack: in the Dance picker, dancing its style);
// broken packs (bad JSON, an ONNX of another shape, a missing file, too large) are refused with a short message
// and the shipped models keep working. Run with `node --test tests/e2e/packs.test.mjs`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { before, describe, test } from 'node:test';
import { installUiLookups, ROOT, sitePage, usePlayground, waitUntil } from './harness.mjs';

const PACK = path.join(ROOT, 'tests', 'fixtures', 'packs');
const CORP = { 'Cross-Origin-Resource-Policy': 'same-origin' };
const PACK_FILES = ['my-walks.json', 'my-walks.onnx', 'card.md', 'pose_change.png'];
const DANCE_FILES = ['my-dance.json', 'my-dance.onnx', 'card.md', 'pose_change.png'];
const CORNER = JSON.parse(readFileSync(path.join(ROOT, 'tests', 'fixtures', 'benchmark_paths.json'), 'utf8')).paths.corner.points;
const packJson = () => JSON.parse(readFileSync(path.join(PACK, 'my-walks', 'my-walks.json'), 'utf8'));

/** Files served under packs/: the fixture, and broken variants of it. */
function servedFiles() {
  const files = new Map(PACK_FILES.map((f) => [`my-walks/${f}`, readFileSync(path.join(PACK, 'my-walks', f))]));
  files.set('my-walks.zip', readFileSync(path.join(PACK, 'my-walks.zip')));
  for (const f of DANCE_FILES) files.set(`my-dance/${f}`, readFileSync(path.join(PACK, 'my-dance', f)));
  // An ONNX of another shape: the shipped generator's network under the pack's JSON (other hidden size).
  const wrong = { ...packJson(), id: 'wrong-shape' };
  files.set('wrong/wrong-shape.json', Buffer.from(JSON.stringify(wrong)));
  files.set('wrong/my-walks.onnx', readFileSync(path.join(ROOT, 'public', 'models', 'generator.onnx')));
  files.set('bad/my-walks.json', Buffer.from('{ "id": "my-walks", "kind": '));
  files.set('missing/my-walks.json', files.get('my-walks/my-walks.json'));
  return files;
}

describe('model packs', { timeout: 900_000 }, () => {
  const suite = usePlayground();
  const pages = new Map();

  before(async () => {
    const files = servedFiles();
    await suite.context.route(`${suite.url}packs/**`, (route) => {
      const file = new URL(route.request().url()).pathname.replace(/^\/packs\//, '');
      if (files.has(file)) return route.fulfill({ status: 200, contentType: 'application/octet-stream', headers: CORP, body: files.get(file) });
      return route.fulfill({ status: 404, headers: CORP, body: 'not here' });
    });
    await suite.context.route(`${suite.url}site/**`, (route) => {
      const file = new URL(route.request().url()).pathname.replace(/^\/site\//, '');
      if (pages.has(file)) return route.fulfill({ status: 200, contentType: 'text/html', body: pages.get(file) });
      return route.fulfill({ status: 404, body: 'not here' });
    });
  });

  /** A fresh playground page (a pack loaded once stays listed in its page). */
  async function freshPage(query = '?mode=clip') {
    const page = await suite.context.newPage();
    const problems = [];
    page.on('pageerror', (err) => problems.push(err.message));
    await page.addInitScript(installUiLookups);
    await page.goto(`${suite.url}${query}`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.playground !== undefined);
    await page.evaluate(() => window.playground.ready);
    return { page, problems };
  }

  /** Drops files fetched from packs/ (as they are named there, less their folder) on the page's frame. */
  const dropFetched = (page, names) =>
    page.evaluate(async (names) => {
      const data = new DataTransfer();
      for (const n of names) data.items.add(new File([await (await fetch(`packs/${n}`)).arrayBuffer()], n.split('/').pop()));
      $uiFrame().dispatchEvent(new DragEvent('drop', { dataTransfer: data, bubbles: true, cancelable: true }));
    }, names);

  /** The pickers' labels of the pack's model, and its card button. */
  const listed = (page, id) =>
    page.evaluate((id) => ['walk-model', 'path-model', 'steer-model'].map((s) => [...$ui(s).options].find((o) => o.value === id)?.textContent ?? null), id);

  test('a dropped pack is listed in Random walk, Path and Steer, walks, follows a path and is steered; its card opens', async (t) => {
    const { page, problems } = await freshPage();
    try {
      await dropFetched(page, PACK_FILES.map((f) => `my-walks/${f}`));
      await waitUntil(page, () => [...$ui('walk-model').options].some((o) => o.value === 'my-walks'), null, { timeout: 60_000, message: 'the dropped pack is listed' });
      assert.deepEqual(await listed(page, 'my-walks'), Array(3).fill('my-walks (your model)'));
      // The shipped models are still listed, the default first.
      assert.ok((await page.evaluate(() => $ui('walk-model').options.length)) >= 2);

      // Random walk with the pack's model: frames stream, finite (refine was on for the shipped generator).
      await page.evaluate(() => {
        $ui('walk-refine').checked = true;
        $ui('walk-refine').dispatchEvent(new Event('change'));
        $ui('walk-model').value = 'my-walks';
        $ui('walk-model').dispatchEvent(new Event('change'));
        $ui('mode-walk').click();
      });
      const walk = await waitUntil(page, () => {
        const m = window.playground.current();
        return m && m.frames >= 60 && $ui('walk-seed-state').options.length > 1 ? { frames: m.frames, finite: m.positions.every(Number.isFinite), seeds: [...$ui('walk-seed-state').options].map((o) => o.textContent) } : null;
      }, null, { timeout: 120_000, message: 'the pack walks in Random walk' });
      assert.ok(walk.finite, 'finite frames');
      const seedNames = packJson().seeds.map((s) => s.name);
      assert.deepEqual(walk.seeds.slice(1), seedNames, "the seed states are the pack's own");
      // The header names the pack's model, and the sliding readout compares with the pack's own held-out clips.
      const labels = await page.evaluate(() => ({ reference: $ui('walk-skating-reference').textContent, header: document.querySelector('motion-playground').shadowRoot.textContent }));
      assert.equal(labels.reference, `your held-out clips: ${packJson().pack.measures.real.sliding_low_foot.toFixed(2)} m/s`);
      assert.match(labels.header, /my-walks · 30 fps · live/);
      // Refine was on for the shipped generator before: off and disabled for the pack, back on with the generator.
      assert.deepEqual(await page.evaluate(() => [$ui('walk-refine').disabled, $ui('walk-refine').checked, $ui('walk-refine').title]), [true, false, 'Your model has no refiner']);
      assert.deepEqual(await page.evaluate(() => {
        $ui('walk-model').value = 'generator';
        $ui('walk-model').dispatchEvent(new Event('change'));
        return [$ui('walk-refine').disabled, $ui('walk-refine').checked];
      }), [false, true]);
      await page.evaluate(() => {
        $ui('walk-model').value = 'my-walks';
        $ui('walk-model').dispatchEvent(new Event('change'));
      });

      // Its card, from the Path picker.
      await page.evaluate(() => {
        $ui('mode-path').click();
        $ui('path-model').value = 'my-walks';
        $ui('path-model').dispatchEvent(new Event('change'));
      });
      const card = await page.evaluate(async () => {
        const button = $ui('path-model').nextElementSibling;
        if (!button || button.hidden) return null;
        button.click();
        const dialog = $uiOne('dialog.pack-card');
        const img = dialog?.querySelector('img');
        if (img && !img.complete) await new Promise((r) => img.addEventListener('load', r, { once: true }));
        return { open: dialog?.open, text: dialog?.querySelector('pre')?.textContent ?? '', plot: img?.naturalWidth ?? 0 };
      });
      assert.ok(card, 'a card button beside the Path picker');
      // The Steer picker follows the Path picker's choice, and its tooltip says where that model's data came from.
      assert.match(await page.evaluate(() => $ui('steer-model').title), /^Trained on your folder my-walks \(0\.2 minutes\)\. Licence: your data's own terms\.$/);
      assert.equal(card.open, true);
      assert.match(card.text, /^# my-walks/);
      assert.ok(card.plot > 100, 'the pose-change plot is shown');
      await page.evaluate(() => $uiOne('dialog.pack-card').close());

      // The benchmark 'corner' path followed by the MAP optimiser (Path mode's worker call) with the pack's model:
      // finite, non-empty. A 30-iteration model need not follow it well: only that it runs is asserted.
      const r = await page.evaluate(async (points) => {
        const m = await window.playground.followPath({ model: 'my-walks', points, gait: 'walk', seed: 1 });
        return { frames: m.frames, finite: m.positions.every(Number.isFinite), stats: m.stats };
      }, CORNER);
      t.diagnostic(`corner path with the pack: ${r.frames} frames, mean error ${r.stats.meanError.toFixed(2)} m, ${(r.stats.arcProgress * 100).toFixed(0)} % of the path`);
      assert.ok(r.frames > 30 && r.finite, `frames ${r.frames}`);
      assert.ok(Number.isFinite(r.stats.meanError) && r.stats.arcProgress > 0, JSON.stringify(r.stats));
      // Path mode itself walks the same path with the pack's model (the page's element given model, path and mode).
      await page.evaluate((points) => {
        const el = document.querySelector('motion-playground');
        el.setAttribute('model', 'my-walks');
        el.setAttribute('path', points.map((p) => p.join(',')).join(';'));
        el.setAttribute('mode', 'path');
      }, CORNER);
      const line = await waitUntil(page, () => $uiOne('.path-stats')?.textContent, null, { timeout: 90_000, message: 'Path mode walks the path with the pack' });
      t.diagnostic(`Path mode: ${line}`);
      assert.match(line, /^my-walks: error mean [\d.]+ cm/);
      const shown = await page.evaluate(() => ({ frames: window.playground.current()?.frames ?? 0, finite: window.playground.current()?.positions.every(Number.isFinite) }));
      assert.ok(shown.frames > 30 && shown.finite, JSON.stringify(shown));
      // Steer's live control (simulateControl runs the same controller) with the pack's model.
      const steer = await page.evaluate(async () => {
        const m = await window.playground.simulateControl({ model: 'my-walks', seconds: 2, schedule: [{ t: 0, speed: 1.2, heading: 0 }], seed: 1 });
        return { frames: m.frames, finite: m.positions.every(Number.isFinite) };
      });
      assert.ok(steer.frames >= 50 && steer.finite, JSON.stringify(steer));
      assert.deepEqual(problems, []);
    } finally {
      await page.close();
    }
  });

  test('a dropped dance pack is listed in Dance only, dances its style in Dance mode and in generate; its card opens', async () => {
    const { page, problems } = await freshPage();
    try {
      await dropFetched(page, DANCE_FILES.map((f) => `my-dance/${f}`));
      await waitUntil(page, () => [...$ui('dance-model').options].some((o) => o.value === 'my-dance'), null, { timeout: 60_000, message: 'the dropped dance pack is listed' });
      assert.deepEqual(await listed(page, 'my-dance'), [null, null, null], 'not in Random walk, Path or Steer');
      assert.match(await page.evaluate(() => [...$uiAll('.toast')].map((t) => t.textContent).join(' | ')), /Your model my-dance is loaded: choose it in Dance\./);
      await page.evaluate(() => {
        $ui('dance-model').value = 'my-dance';
        $ui('dance-model').dispatchEvent(new Event('change'));
        $ui('mode-dance').click();
      });
      const dance = await waitUntil(page, () => {
        const m = window.playground.current();
        return m && m.frames >= 60 && $ui('dance-style').value === 'salsa' ? { frames: m.frames, joints: m.joints.length, finite: m.positions.every(Number.isFinite), styles: [...$ui('dance-style').options].map((o) => o.value) } : null;
      }, null, { timeout: 120_000, message: 'the dance pack dances in Dance mode' });
      assert.deepEqual(dance.styles, ['salsa']);
      assert.ok(dance.finite && dance.joints === 25, JSON.stringify(dance));
      const card = await page.evaluate(() => {
        const button = $ui('dance-model').nextElementSibling;
        if (!button || button.hidden) return null;
        button.click();
        return $uiOne('dialog.pack-card')?.querySelector('pre')?.textContent ?? '';
      });
      assert.match(card ?? '', /^# my-dance/);
      await page.evaluate(() => $uiOne('dialog.pack-card').close());
      const m = await page.evaluate(async () => {
        const m = await window.playground.generate({ model: 'my-dance', style: 'salsa', frames: 90, seed: 1 });
        const models = window.playground.models();
        return { frames: m.frames, finite: m.positions.every(Number.isFinite), entry: models.find((x) => x.id === 'my-dance') };
      });
      assert.equal(m.frames, 90);
      assert.ok(m.finite);
      assert.deepEqual(m.entry?.styles, ['salsa']);
      assert.deepEqual(problems, []);
    } finally {
      await page.close();
    }
  });

  test('a dropped folder (its entries walked) and a dropped .zip load the pack', async () => {
    const { page } = await freshPage();
    try {
      // A folder drop: items whose entries are a directory holding the pack's files (what a browser gives).
      const id = await page.evaluate(async (names) => {
        const files = await Promise.all(names.map(async (n) => new File([await (await fetch(`packs/my-walks/${n}`)).arrayBuffer()], n)));
        const fileEntry = (f) => ({ isFile: true, isDirectory: false, file: (ok) => ok(f) });
        let read = false;
        const folder = { isFile: false, isDirectory: true, createReader: () => ({ readEntries: (ok) => ok(read ? [] : ((read = true), files.map(fileEntry))) }) };
        const { droppedFolderFiles } = await import('/ui/packInput.ts');
        const walked = await droppedFolderFiles([{ webkitGetAsEntry: () => folder }]);
        return window.playground.loadModels(walked);
      }, PACK_FILES);
      assert.equal(id, 'my-walks');
    } finally {
      await page.close();
    }
    const second = await freshPage();
    try {
      await dropFetched(second.page, ['my-walks.zip']);
      await waitUntil(second.page, () => [...$ui('steer-model').options].some((o) => o.value === 'my-walks'), null, { timeout: 60_000, message: 'the dropped zip is listed' });
      const m = await second.page.evaluate(async () => {
        const m = await window.playground.generate({ model: 'my-walks', frames: 60, seed: 2 });
        return { frames: m.frames, finite: m.positions.every(Number.isFinite) };
      });
      assert.deepEqual(m, { frames: 60, finite: true });
    } finally {
      await second.page.close();
    }
  });

  test('?models= and the models attribute load the pack by URL; another origin is refused', async () => {
    const { page } = await freshPage('?mode=clip&models=packs/my-walks/my-walks.json');
    try {
      await waitUntil(page, () => [...$ui('path-model').options].some((o) => o.value === 'my-walks'), null, { timeout: 60_000, message: '?models= loads the pack' });
    } finally {
      await page.close();
    }
    pages.set('attr.html', sitePage(`
      <motion-playground id="good" models="../packs/my-walks/my-walks.json" controls="minimal"></motion-playground>
      <motion-playground id="far" models="https://example.com/pack.json" controls="none"></motion-playground>`));
    const site = await suite.context.newPage();
    try {
      await site.goto(`${suite.url}site/attr.html`, { waitUntil: 'load' });
      await waitUntil(site, () => window.events.some((e) => e.id === 'far' && e.type === 'error'), null, { timeout: 90_000, message: 'the far pack is refused' });
      const reason = await site.evaluate(() => window.events.find((e) => e.id === 'far' && e.type === 'error').detail.reason);
      assert.match(reason, /^models: .*example\.com.*(origin|allowed)/);
      assert.ok(reason.length <= 300);
      await waitUntil(site, () => {
        const root = document.getElementById('good').shadowRoot;
        return [...root.getElementById('walk-model').options].some((o) => o.value === 'my-walks');
      }, null, { timeout: 90_000, message: 'the models attribute loads the pack' });
    } finally {
      await site.close();
    }
  });

  test('broken packs are refused with a short message; the shipped models still work', async () => {
    const { page } = await freshPage();
    try {
      const r = await page.evaluate(async () => {
        const fetched = async (n) => new File([await (await fetch(`packs/${n}`)).arrayBuffer()], n.split('/').pop());
        const refusal = async (source) => {
          try {
            await window.playground.loadModels(await source);
            return null;
          } catch (e) {
            return e.message;
          }
        };
        const out = {
          badJson: await refusal(Promise.all(['bad/my-walks.json', 'my-walks/my-walks.onnx'].map(fetched))),
          wrongShape: await refusal(Promise.all(['wrong/wrong-shape.json', 'wrong/my-walks.onnx'].map(fetched))),
          missing: await refusal(Promise.all(['missing/my-walks.json'].map(fetched))),
          missingUrl: await refusal('packs/missing/my-walks.json'),
          oversize: await refusal([new File([new Uint8Array(33 * 1024 * 1024)], 'my-walks.zip')]),
          notZip: await refusal([new File(['hello'], 'my-walks.zip')]),
        };
        out.listed = [...$ui('walk-model').options].map((o) => o.value);
        const m = await window.playground.generate({ model: 'generator', frames: 30, seed: 1 });
        out.shipped = m.frames === 30 && m.positions.every(Number.isFinite);
        return out;
      });
      assert.match(r.badJson, /my-walks\.json is not valid JSON/);
      assert.match(r.wrongShape, /the pack's model does not load: /);
      assert.match(r.missing, /the pack has no my-walks\.onnx/);
      assert.match(r.missingUrl, /404|not found/i);
      assert.match(r.oversize, /over the 32 MB limit/);
      assert.match(r.notZip, /not a zip file/);
      for (const [k, v] of Object.entries(r)) if (typeof v === 'string') assert.ok(v.length <= 300, `${k}: ${v.length} chars`);
      assert.ok(!r.listed.includes('my-walks') && !r.listed.includes('wrong-shape'), 'nothing refused is listed');
      assert.equal(r.shipped, true, 'the shipped generator still generates');
    } finally {
      await page.close();
    }
  });
});
