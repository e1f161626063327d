// End-to-end tests of the page: a Vite dev server in-process, headless Chromium, real CMU clips.
// Run with `npm run test:e2e` (node --test tests/e2e/). Needs /usr/bin/chromium (or CHROMIUM_PATH) and
// the shared corpus at ../shared/mocap (or MOCAP_DIR).
import assert from 'node:assert/strict';
import { gzipSync } from 'node:zlib';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { before, describe, test } from 'node:test';
import { corpusText, nextFrames, openPlayground, ROOT, startServer, usePlayground, waitUntil } from './harness.mjs';

const BVH_CLIP = 'cmu/bvh/07_04.bvh.gz';
const AMC_CLIP = 'cmu/amc/16_11.amc.gz';
const ASF_FILE = 'cmu/asf/16.asf';

/** In-page: a JSON-friendly summary of a motion (typed arrays do not cross page.evaluate as such). */
const SUMMARY = `(m) => m && ({
  fps: m.fps, frames: m.frames, joints: m.joints, parents: m.parents,
  n: m.positions.length, first: Array.from(m.positions.slice(0, 6)),
  contacts: m.contacts ? Array.from(m.contacts) : null,
})`;

function maxAbsDiff(a, b) {
  assert.equal(a.length, b.length, 'position arrays differ in length');
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]));
  return worst;
}

describe('motion playground page', { timeout: 150_000 }, () => {
  // The shared page; every test checks the console and page errors of its own steps (usePlayground).
  const suite = usePlayground();
  let url, browser, page;
  const text = {};

  before(() => {
    ({ url, browser, page } = suite);
    text.bvh = corpusText(BVH_CLIP);
    text.amc = corpusText(AMC_CLIP);
    text.asf = corpusText(ASF_FILE);
  });

  /** Imports through the API in the page and shows the result; returns its summary. */
  async function importAndShow(t, format, asf, name) {
    return page.evaluate(
      async ({ t, format, asf, name, SUMMARY }) => {
        const m = await window.playground.importMotion(t, format, asf);
        window.playground.show(m, name);
        return eval(SUMMARY)(m);
      },
      { t, format, asf, name, SUMMARY },
    );
  }

  const currentSummary = () => page.evaluate((S) => eval(S)(window.playground.current()), SUMMARY);

  /** Shows CMU 16_11 (imported once per page, kept in the page), paused at frame 0 unless `playing`; returns its summary. */
  async function showClip({ playing = false } = {}) {
    return page.evaluate(
      async ({ amc, asf, playing, SUMMARY }) => {
        const p = window.playground;
        window.clip16_11 ??= await p.importMotion(amc, 'amc', asf);
        p.show(window.clip16_11, '16_11.amc');
        if (!playing) p.pause();
        return eval(SUMMARY)(p.current());
      },
      { amc: text.amc, asf: text.asf, playing, SUMMARY },
    );
  }

  test('ready resolves; the page is cross-origin isolated; version and models', async () => {
    // The state of a page that nothing has been done to yet: a page of its own.
    const fresh = await openPlayground(browser, url);
    const info = await fresh.page.evaluate(async () => {
      await window.playground.ready;
      return {
        isolated: globalThis.crossOriginIsolated,
        version: window.playground.version,
        models: window.playground.models(),
        current: window.playground.current(),
        lastError: window.playground.lastError(),
        state: window.playground.state(),
      };
    });
    assert.equal(info.isolated, true, 'COOP/COEP headers should make the page cross-origin isolated');
    assert.match(info.version, /^\d+\.\d+\.\d+/);
    // models() lists the manifest's entries without their internal `file` (and `files`, of a model with several).
    const manifest = JSON.parse(readFileSync(path.join(ROOT, 'public', 'models', 'index.json'), 'utf8'));
    assert.deepEqual(info.models, manifest.models.map(({ file, files, ...rest }) => rest));
    assert.equal(info.current, null);
    assert.equal(info.lastError, null);
    assert.equal(info.state.frames, 0);
    assert.equal(await fresh.page.locator('#empty-state').isVisible(), true, 'empty state invites a drop');
    await fresh.context.close();
    assert.deepEqual(fresh.problems, []);
  });

  test('imports a CMU BVH clip through the API into a sensible Motion', async () => {
    const m = await importAndShow(text.bvh, 'bvh', undefined, '07_04.bvh');
    assert.equal(m.fps, 120);
    assert.equal(m.frames, 450);
    assert.ok(m.joints.length >= 20, `expected a full skeleton, got ${m.joints.length} joints`);
    assert.equal(m.parents[0], -1);
    assert.equal(m.n, m.frames * m.joints.length * 3);
    const stats = await page.evaluate(() => {
      const m = window.playground.current();
      const J = m.joints.length;
      let minY = Infinity, maxY = -Infinity;
      for (let j = 0; j < J; j++) { minY = Math.min(minY, m.positions[j * 3 + 1]); maxY = Math.max(maxY, m.positions[j * 3 + 1]); }
      const r0 = [m.positions[0], m.positions[2]], r1 = [m.positions[(m.frames - 1) * J * 3], m.positions[(m.frames - 1) * J * 3 + 2]];
      return { height: maxY - minY, hipY: m.positions[1], travel: Math.hypot(r1[0] - r0[0], r1[1] - r0[1]) };
    });
    assert.ok(stats.height > 1.2 && stats.height < 2.1, `figure height ${stats.height} m`);
    assert.ok(stats.hipY > 0.6 && stats.hipY < 1.3, `hip height ${stats.hipY} m`);
    assert.ok(stats.travel > 1, `a walk should travel, got ${stats.travel} m`);
    assert.ok(m.contacts && m.contacts.length === m.frames * 2, 'contacts attached');
    assert.ok(m.contacts.some((c) => c === 1) && m.contacts.some((c) => c === 0), 'feet plant and lift');
  });

  test('imports an ASF/AMC clip, shows it, plays it and loops', async () => {
    const m = await importAndShow(text.amc, 'amc', text.asf, '16_11.amc');
    assert.equal(m.fps, 120);
    assert.equal(m.frames, 534);
    assert.equal(m.joints.length, 31);
    assert.equal(m.joints[0], 'root');
    const cur = await currentSummary();
    assert.equal(cur.frames, 534);
    assert.deepEqual(cur.joints, m.joints);

    const s0 = await page.evaluate(() => window.playground.state());
    assert.equal(s0.playing, true);
    assert.equal(s0.frames, 534);
    assert.equal(s0.fps, 120);
    // It plays: half a second of the clip goes by (how fast against the wall clock is `npm run bench`'s
    // playback_rate).
    await waitUntil(page, (f) => window.playground.state().frame >= f + 60, s0.frame, { message: `playback advances 60 frames from frame ${s0.frame}` });
    // And loops: from near the end it comes round to the start, still playing.
    await page.evaluate(() => window.playground.seek(500));
    await waitUntil(page, () => window.playground.state().frame < 100, null, { message: 'playback loops from frame 500 back to the start' });
    assert.equal((await page.evaluate(() => window.playground.state())).playing, true);
    assert.match(await page.locator('#clip-meta').textContent(), /31 joints · 534 frames · 120 fps/);
    assert.match(await page.locator('#clip-meta').textContent(), /\d+ steps/, 'footprints placed');
    assert.equal(await page.locator('#empty-state').isVisible(), false);
  });

  test('playback controls: pause, seek, speed, timeline, keyboard', async () => {
    await showClip({ playing: true });
    const r = await page.evaluate(() => {
      const p = window.playground;
      p.pause();
      p.seek(100);
      const a = p.state();
      const speeds = [p.setSpeed(0.5), p.setSpeed(10), p.setSpeed(0.01)];
      p.setSpeed(1);
      p.seek(1e9);
      const end = p.state().frame;
      p.seek(-5);
      const start = p.state().frame;
      let seekError = null;
      try { p.seek(NaN); } catch (e) { seekError = e.message; }
      return { a, speeds, end, start, seekError };
    });
    assert.equal(r.a.playing, false);
    assert.equal(r.a.frame, 100);
    assert.ok(Math.abs(r.a.time - 100 / 120) < 1e-9);
    assert.deepEqual(r.speeds, [0.5, 2, 0.25]);
    assert.equal(r.end, 533);
    assert.equal(r.start, 0);
    assert.match(r.seekError, /finite number/);

    // Paused: the frame stays put while the display loop (which advances playback) runs 10 frames.
    await page.evaluate(() => window.playground.seek(200));
    await nextFrames(page, 10);
    assert.equal((await page.evaluate(() => window.playground.state())).frame, 200);

    // Timeline scrubbing.
    await page.locator('#timeline').fill('300');
    assert.equal((await page.evaluate(() => window.playground.state())).frame, 300);

    // Keyboard: arrows step (shift: 10), space toggles.
    await page.locator('body').click({ position: { x: 640, y: 300 } });
    await page.keyboard.press('ArrowRight');
    assert.equal((await page.evaluate(() => window.playground.state())).frame, 301);
    await page.keyboard.press('Shift+ArrowLeft');
    assert.equal((await page.evaluate(() => window.playground.state())).frame, 291);
    await page.keyboard.press('Space');
    assert.equal((await page.evaluate(() => window.playground.state())).playing, true);
    await page.keyboard.press('Space');
    assert.equal((await page.evaluate(() => window.playground.state())).playing, false);

    // The play button.
    await page.locator('#play-btn').click();
    assert.equal((await page.evaluate(() => window.playground.state())).playing, true);
  });

  test('BVH export → re-import reproduces the positions within 1 mm', async () => {
    for (const [t, format, asf] of [[text.amc, 'amc', text.asf], [text.bvh, 'bvh', undefined]]) {
      const r = await page.evaluate(
        async ({ t, format, asf }) => {
          const p = window.playground;
          const m = await p.importMotion(t, format, asf);
          const bvh = p.exportBVH(m);
          const back = await p.importMotion(bvh, 'bvh');
          return {
            head: bvh.slice(0, 200),
            frameTime: /Frame Time:\s*([0-9.eE+-]+)/.exec(bvh)?.[1],
            framesLine: /Frames:\s*(\d+)/.exec(bvh)?.[1],
            zyx: /CHANNELS 3 Zrotation Yrotation Xrotation/.test(bvh),
            a: { joints: m.joints, fps: m.fps, frames: m.frames, pos: Array.from(m.positions) },
            b: { joints: back.joints, fps: back.fps, frames: back.frames, pos: Array.from(back.positions) },
          };
        },
        { t, format, asf },
      );
      assert.match(r.head, /^HIERARCHY\s+ROOT /);
      assert.ok(r.zyx, 'ZYX Euler rotation channels');
      assert.equal(Number(r.framesLine), r.a.frames);
      assert.ok(Math.abs(Number(r.frameTime) - 1 / r.a.fps) < 1e-6, `Frame Time ${r.frameTime}`);
      assert.equal(r.b.frames, r.a.frames);
      assert.ok(Math.abs(r.b.fps - r.a.fps) < 1e-3);
      // Compare joint by joint (by name): every original joint must come back.
      const J = r.a.joints.length, JB = r.b.joints.length;
      let worst = 0;
      r.a.joints.forEach((name, j) => {
        const k = r.b.joints.indexOf(name);
        assert.ok(k >= 0, `joint ${name} missing after the round trip`);
        for (let f = 0; f < r.a.frames; f++) {
          for (let c = 0; c < 3; c++) {
            worst = Math.max(worst, Math.abs(r.a.pos[(f * J + j) * 3 + c] - r.b.pos[(f * JB + k) * 3 + c]));
          }
        }
      });
      assert.ok(worst < 0.001, `${format} round trip: worst position error ${(worst * 1000).toFixed(3)} mm`);
    }
  });

  test('the Export BVH button downloads the shown motion', async () => {
    await showClip();
    const [download] = await Promise.all([page.waitForEvent('download'), page.locator('#export-menu-btn').click().then(() => page.locator('#export-btn').click())]);
    assert.equal(download.suggestedFilename(), '16_11.bvh');
    const file = await download.path();
    const bvh = readFileSync(file, 'utf8');
    assert.match(bvh, /^HIERARCHY/);
    assert.match(bvh, /Frames:\s*534/);
    const same = await page.evaluate((t) => window.playground.exportBVH(window.playground.current(), { restPose: 'tpose' }) === t, bvh);
    assert.ok(same, 'download equals exportBVH(current(), { restPose: "tpose" }), the menu default');
  });

  test('importMotion parses in the import worker: the motion comes back whole, a parser error keeps its name, format and line', async () => {
    const r = await page.evaluate(async ({ bvh, SUMMARY }) => {
      const posted = [];
      const native = Worker.prototype.postMessage;
      Worker.prototype.postMessage = function (message, transfer) {
        posted.push(message?.type);
        return native.call(this, message, transfer);
      };
      try {
        const m = await window.playground.importMotion(bvh, 'bvh');
        const error = await window.playground.importMotion(bvh.replace(/Frame Time:.*/, 'Frame Time: fast'), 'bvh').catch((e) => e);
        return {
          posted,
          motion: eval(SUMMARY)(m),
          typed: m.positions instanceof Float32Array && m.contacts instanceof Uint8Array,
          error: { name: error.name, message: error.message, cause: { name: error.cause?.name, format: error.cause?.format, line: error.cause?.line } },
        };
      } finally {
        Worker.prototype.postMessage = native;
      }
    }, { bvh: text.bvh, SUMMARY });
    assert.deepEqual(r.posted, ['text', 'text']);
    assert.deepEqual([r.motion.frames, r.motion.joints[0], r.motion.n, r.typed], [450, 'Hips', 450 * r.motion.joints.length * 3, true]);
    assert.deepEqual([r.error.name, r.error.cause], ['MotionFormatError', { name: 'MotionFormatError', format: 'bvh', line: 187 }]);
    assert.match(r.error.message, /^importMotion: BVH line 187: .*"fast"/);
  });

  describe('bad input is refused with a clear message and the scene stays', () => {
    const lines = () => text.bvh.split('\n');
    const cases = [
      { name: 'empty string', input: () => ['', 'bvh'], reason: /empty/i },
      {
        name: 'binary junk',
        input: () => {
          let seed = 7;
          const rnd = () => (seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648;
          return [Array.from({ length: 4096 }, () => String.fromCharCode(Math.floor(rnd() * 256))).join(''), 'bvh'];
        },
        reason: /binary|NUL|non-printable/i,
      },
      { name: 'truncated BVH (in the motion data)', input: () => [text.bvh.slice(0, Math.floor(text.bvh.length * 0.6)), 'bvh'], reason: /line \d+|frame|truncat/i },
      { name: 'truncated BVH (in the hierarchy)', input: () => [text.bvh.slice(0, 1500), 'bvh'], reason: /line \d+/i },
      {
        name: 'NaN values',
        input: () => {
          const l = lines();
          const i = l.findIndex((x) => x.startsWith('Frame Time')) + 10;
          const tok = l[i].trim().split(/\s+/);
          tok[5] = 'NaN';
          l[i] = tok.join(' ');
          return [l.join('\n'), 'bvh'];
        },
        reason: /NaN|number/,
      },
      { name: 'AMC naming an unknown bone', input: () => [text.amc.replace('\n1\nroot', '\n1\ntail 1 2 3\nroot'), 'amc', text.asf], reason: /unknown bone "tail"/ },
      { name: 'absurd frame count', input: () => [text.bvh.replace(/Frames:\s*\d+/, 'Frames: 2000000000'), 'bvh'], reason: /frames/i },
      { name: 'frame count larger than the data', input: () => [text.bvh.replace(/Frames:\s*\d+/, 'Frames: 900000'), 'bvh'], reason: /frame/i },
      { name: 'AMC without its ASF', input: () => [text.amc, 'amc'], reason: /ASF|skeleton/ },
      { name: 'junk ASF', input: () => [text.amc, 'amc', '\u0000\u0001junk'], reason: /ASF/ },
      { name: 'unknown format', input: () => [text.bvh, 'fbx'], reason: /format/ },
      { name: 'an AMC passed as BVH', input: () => [text.amc, 'bvh'], reason: /HIERARCHY/ },
    ];

    for (const c of cases) {
      test(c.name, async () => {
        const shown = await showClip();
        assert.equal(shown.frames, 534);
        const [t, format, asf] = c.input();
        const r = await page.evaluate(
          async ({ t, format, asf }) => {
            try {
              await window.playground.importMotion(t, format, asf);
              return { ok: true };
            } catch (e) {
              return { ok: false, message: String(e?.message ?? e), lastError: window.playground.lastError() };
            }
          },
          { t, format, asf },
        );
        assert.equal(r.ok, false, 'the promise must reject');
        assert.match(r.message, c.reason);
        assert.match(r.message, /^importMotion: /);
        assert.equal(r.lastError, r.message, 'lastError() is the message shown');
        const toast = page.locator('.toast.error').last();
        assert.equal(await toast.isVisible(), true, 'an error message is shown on the page');
        assert.equal((await toast.locator('.toast-text').textContent()).trim(), r.message);
        assert.deepEqual(await currentSummary(), shown, 'the shown motion is unchanged');
      });
    }

    test('show() refuses bad motions and keeps the scene', async () => {
      const shown = await showClip();
      const bad = [
        [null, /object/],
        [{ fps: 30, frames: 2, joints: ['a'], parents: [-1], positions: [0, 0, 0] }, /positions/],
        [{ fps: 30, frames: 1, joints: ['a', 'b'], parents: [-1, 5], positions: new Array(6).fill(0) }, /parent/],
        [{ fps: 30, frames: 1, joints: ['a'], parents: [-1], positions: [0, NaN, 0] }, /non-finite/],
        [{ fps: -1, frames: 1, joints: ['a'], parents: [-1], positions: [0, 0, 0] }, /fps/],
      ];
      for (const [m, reason] of bad) {
        const r = await page.evaluate((m) => {
          try {
            window.playground.show(m);
            return { ok: true };
          } catch (e) {
            return { ok: false, message: e.message };
          }
        }, m);
        assert.equal(r.ok, false);
        assert.match(r.message, /^show: /);
        assert.match(r.message, reason);
        assert.deepEqual(await currentSummary(), shown);
      }
      const exportErr = await page.evaluate(() => {
        try { window.playground.exportBVH({}); } catch (e) { return e.message; }
        return null;
      });
      assert.match(exportErr, /^exportBVH: /);
    });

    test('messages can be dismissed', async () => {
      await page.evaluate(() => window.playground.importMotion('', 'bvh').catch(() => {}));
      const toast = await page.locator('.toast.error').last().elementHandle();
      assert.match(await toast.textContent(), /importMotion: .*empty/i);
      await (await toast.$('.toast-close')).click();
      await waitUntil(page, (el) => !el.isConnected, toast, { message: 'the closed message goes' });
    });
  });

  describe('drag and drop', () => {
    /** Dispatches dragenter/dragover/drop on the page with files built in the page (remembering what was shown before). */
    async function drop(files) {
      await page.evaluate(async (files) => {
        window.shownBeforeDrop = window.playground.current();
        const dt = new DataTransfer();
        for (const f of files) {
          const data = f.base64 ? Uint8Array.from(atob(f.base64), (c) => c.charCodeAt(0)) : f.text;
          dt.items.add(new File([data], f.name));
        }
        const target = $uiOne('.viewer-canvas');
        for (const type of ['dragenter', 'dragover', 'drop']) {
          target.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true }));
        }
      }, files);
    }
    /** Waits until the drop has replaced the shown motion with one of `n` frames. */
    const waitFrames = (n) =>
      waitUntil(page, (n) => window.playground.current() !== window.shownBeforeDrop && window.playground.current()?.frames === n, n, {
        timeout: 15_000,
        message: `the dropped ${n}-frame clip is shown`,
      });

    test('a .bvh file', async () => {
      await drop([{ name: '07_04.bvh', text: text.bvh }]);
      await waitFrames(450);
      const cur = await currentSummary();
      assert.equal(cur.joints[0], 'Hips');
      assert.equal((await page.locator('#clip-name').textContent()), '07_04.bvh');
      assert.equal((await page.evaluate(() => window.playground.state())).playing, true);
    });

    test('an .asf + gzipped .amc pair dropped together', async () => {
      await drop([
        { name: '16.asf', text: text.asf },
        { name: '16_11.amc.gz', base64: gzipSync(Buffer.from(text.amc)).toString('base64') },
      ]);
      await waitFrames(534);
      assert.equal((await currentSummary()).joints[0], 'root');
      assert.equal((await page.locator('#clip-name').textContent()), '16_11.amc');
    });

    test('the .asf first, then the .amc alone (the last ASF is remembered)', async () => {
      await drop([{ name: '07_04.bvh', text: text.bvh }]);
      await waitFrames(450);
      await drop([{ name: '16.asf', text: text.asf }]);
      await page.waitForFunction(() => [...$uiAll('.toast.info')].some((t) => /Skeleton 16\.asf/.test(t.textContent)));
      assert.equal((await currentSummary()).frames, 450, 'an ASF alone does not change the scene');
      const amc12 = corpusText('cmu/amc/16_12.amc.gz');
      await drop([{ name: '16_12.amc', text: amc12 }]);
      await waitFrames(441);
      assert.equal((await page.locator('#clip-name').textContent()), '16_12.amc');
    });

    test('a large drop is read and parsed in a worker and shows its progress; a broken one gives the parser\'s message', async () => {
      // 07_04 with its MOTION section repeated to about 3 MB (over the 1 MB that shows progress), plain and gzipped.
      const lines = text.bvh.split('\n');
      const motion = lines.findIndex((l) => l.trim() === 'MOTION');
      const frameLines = lines.slice(motion + 3).filter((l) => l.trim());
      const copies = 10, frames = frameLines.length * copies;
      const big = [...lines.slice(0, motion), 'MOTION', `Frames: ${frames}`, lines[motion + 2], ''].join('\n') + (frameLines.join('\n') + '\n').repeat(copies);
      assert.ok(big.length > 3e6, `${big.length} bytes`);
      await page.evaluate(() => {
        // What the page posts to workers, and the import indicator's stages and visibility as they change.
        window.posted = [];
        window.nativePostMessage = Worker.prototype.postMessage;
        Worker.prototype.postMessage = function (message, transfer) {
          window.posted.push({ type: message?.type, files: Array.isArray(message?.files) ? message.files.map((f) => f.name) : undefined });
          return window.nativePostMessage.call(this, message, transfer);
        };
        const status = $ui('import-status');
        window.importSeen = [];
        window.importWatch = new MutationObserver(() => window.importSeen.push(status.hidden ? 'hidden' : status.dataset.stage));
        window.importWatch.observe(status, { attributes: true, attributeFilter: ['hidden', 'data-stage'] });
      });
      const seen = async () => (await page.evaluate(() => window.importSeen.splice(0))).filter((s, i, all) => s !== all[i - 1]);
      try {
        await drop([{ name: 'long.bvh', text: big }]);
        await waitFrames(frames);
        assert.deepEqual(await page.evaluate(() => window.posted.filter((p) => p.type === 'files')), [{ type: 'files', files: ['long.bvh'] }]);
        assert.deepEqual(await seen(), ['read', 'parse', 'hidden']);
        assert.equal(await page.locator('#clip-name').textContent(), 'long.bvh');

        await drop([{ name: 'long.bvh.gz', base64: gzipSync(Buffer.from(big)).toString('base64') }]);
        await waitFrames(frames);
        assert.deepEqual(await seen(), ['read', 'decompress', 'parse', 'hidden']);

        const shown = await currentSummary();
        await drop([{ name: 'cut.bvh', text: big.slice(0, 2_000_000) + 'junk\n' }]);
        await waitUntil(page, () => /^Could not import cut\.bvh: BVH line \d+: /.test(window.playground.lastError() ?? ''), null, { message: 'the broken large drop is reported' });
        assert.deepEqual(await seen(), ['read', 'parse', 'hidden']);
        assert.deepEqual(await currentSummary(), shown, 'the scene stays');
        assert.equal(await page.locator('#import-status').isHidden(), true);
      } finally {
        await page.evaluate(() => {
          Worker.prototype.postMessage = window.nativePostMessage;
          window.importWatch.disconnect();
        });
      }
    });

    test('a broken drop shows a message and keeps the scene', async () => {
      const before = await showClip();
      await drop([{ name: 'broken.bvh', text: text.bvh.slice(0, 2000) }]);
      await waitUntil(page, () => /broken\.bvh/.test(window.playground.lastError() ?? ''), null, { message: 'the broken drop is reported' });
      assert.match(await page.evaluate(() => window.playground.lastError()), /broken\.bvh.*BVH line \d+/);
      assert.match(await page.locator('.toast.error').last().textContent(), /broken\.bvh/);
      await drop([{ name: 'notes.txt', text: 'hello' }]);
      await waitUntil(page, () => /Unsupported file "notes\.txt"/.test(window.playground.lastError() ?? ''), null, { message: 'the .txt drop is reported' });
      await drop([{ name: 'bad.amc.gz', base64: Buffer.from('not gzip at all').toString('base64') }]);
      await waitUntil(page, () => /gzip/.test(window.playground.lastError() ?? ''), null, { message: 'the bad gzip drop is reported' });
      assert.deepEqual(await currentSummary(), before);
    });
  });

  test('screenshot for the docs: mid-walk with footprints and trail', async () => {
    // A sharper still: same page, high quality (MSAA) at a pinned full resolution.
    const shot = await browser.newPage({ viewport: { width: 1280, height: 720 }, deviceScaleFactor: 1 });
    const shotProblems = [];
    shot.on('console', (m) => m.type() === 'error' && shotProblems.push(m.text()));
    shot.on('pageerror', (e) => shotProblems.push(e.message));
    await shot.goto(`${url}?quality=high&resolution=full`);
    await shot.waitForFunction(() => window.playground !== undefined);
    await shot.evaluate(() => window.playground.ready);
    await shot.evaluate(
      async ({ amc, asf }) => {
        const p = window.playground;
        const m = await p.importMotion(amc, 'amc', asf);
        p.show(m, '16_11.amc');
        p.pause();
        p.seek(Math.round(m.frames * 0.55));
        p.setView({ framing: 'character' });
      },
      { amc: text.amc, asf: text.asf },
    );
    await nextFrames(shot, 12);
    const png = await shot.screenshot({ type: 'png' });
    // A test run leaves the tracked docs alone: the still goes to test-results/ unless asked for the docs.
    const out = process.env.UPDATE_DOCS_SCREENSHOT ? path.join(ROOT, 'docs', 'screenshot.png') : path.join(ROOT, 'test-results', 'screenshot.png');
    mkdirSync(path.dirname(out), { recursive: true });
    writeFileSync(out, png);
    // Decode the PNG in the page and measure it: many colours, real contrast, and the figure's and
    // footprints' blue and orange present.
    const stats = await shot.evaluate(async (b64) => {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      const bmp = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
      const c = new OffscreenCanvas(bmp.width, bmp.height);
      const g = c.getContext('2d');
      g.drawImage(bmp, 0, 0);
      const d = g.getImageData(0, 0, bmp.width, bmp.height).data;
      const colours = new Set();
      let sum = 0, sum2 = 0, blue = 0, orange = 0;
      for (let i = 0; i < d.length; i += 4) {
        const [r, gr, b] = [d[i], d[i + 1], d[i + 2]];
        colours.add((r >> 2) << 12 | (gr >> 2) << 6 | (b >> 2));
        const l = 0.2126 * r + 0.7152 * gr + 0.0722 * b;
        sum += l; sum2 += l * l;
        if (b > 180 && r < 120 && b - r > 90) blue++;
        if (r > 200 && gr > 90 && gr < 170 && b < 110) orange++;
      }
      const n = d.length / 4;
      return { w: bmp.width, h: bmp.height, colours: colours.size, sd: Math.sqrt(sum2 / n - (sum / n) ** 2), blue, orange };
    }, png.toString('base64'));
    await shot.close();
    assert.equal(stats.w, 1280);
    assert.ok(stats.colours > 1000, `screenshot has only ${stats.colours} colours`);
    assert.ok(stats.sd > 8, `screenshot is nearly flat (luminance sd ${stats.sd.toFixed(1)})`);
    assert.ok(stats.blue > 300 && stats.orange > 300, `left/right colours visible (blue ${stats.blue}, orange ${stats.orange})`);
    assert.deepEqual(shotProblems, []);
  });

  test('works without cross-origin isolation too', async () => {
    // A second server whose responses carry no COOP/COEP.
    const plainServer = await startServer({
      headers: { 'Cross-Origin-Opener-Policy': 'unsafe-none', 'Cross-Origin-Embedder-Policy': 'unsafe-none' },
    });
    try {
      const { context, page: plain, problems: errs } = await openPlayground(browser, plainServer.url);
      const r = await plain.evaluate(async (bvh) => {
        const m = await window.playground.importMotion(bvh, 'bvh');
        window.playground.show(m);
        return { isolated: globalThis.crossOriginIsolated, frames: window.playground.current().frames };
      }, text.bvh);
      await context.close();
      assert.equal(r.isolated, false);
      assert.equal(r.frames, 450);
      assert.deepEqual(errs, []);
    } finally {
      await plainServer.server.close();
    }
  });
});
