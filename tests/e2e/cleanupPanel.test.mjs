// End-to-end tests of Clip mode's Clean up panel (issue 16; web/ui/cleanupPanel.ts): the noise tool replaces the
// shown clip with a noisy copy and Restore brings the original back; Clean up with each method runs in the worker
// with a progress bar and Cancel and ends with the input and the cleaned motion side by side, the numbers filled in
// and the joint-angle plot's two curves; Cancel keeps the input; Export BVH downloads the cleaned motion; a skeleton
// that cannot be mapped gets the page's message and the scene stays. A screenshot of the panel after a clean-up goes
// to test-results/cleanup.png (docs/cleanup.png with UPDATE_DOCS_SCREENSHOT=1). Run with
// `node --test tests/e2e/cleanupPanel.test.mjs`.
import assert from 'node:assert/strict';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { describe, test } from 'node:test';
import { corpusText, nextFrames, ROOT, usePlayground, waitUntil } from './harness.mjs';

// 35_13 is held out of the generator's training (generator.json training.valid_files).
const AMC = corpusText('cmu/amc/35_13.amc.gz');
const ASF = corpusText('cmu/asf/35.asf');
const CLEAN_TIMEOUT = 240_000;

describe('Clip mode: the Clean up panel', () => {
  const suite = usePlayground();

  /** Imports 35_13, shows it in Clip mode (knees renamed with `rename`), opens the panel; window.cleanClip is the clip shown. */
  /** Shows 35_13, without the joints from `cut` down when given (a skeleton that is not a humanoid). */
  async function loadClip(cut) {
    const { page } = suite;
    await page.evaluate(
      async ({ amc, asf, cut }) => {
        const pg = window.playground;
        let clip = await pg.importMotion(amc, 'amc', asf);
        if (cut) {
          const gone = new Set();
          clip.parents.forEach((p, j) => (clip.joints[j] === cut || gone.has(p)) && gone.add(j));
          const kept = clip.joints.flatMap((_, j) => (gone.has(j) ? [] : [j]));
          const J = clip.joints.length;
          const positions = new Float32Array(clip.frames * kept.length * 3);
          for (let f = 0; f < clip.frames; f++) kept.forEach((j, k) => positions.set(clip.positions.subarray((f * J + j) * 3, (f * J + j) * 3 + 3), (f * kept.length + k) * 3));
          clip = { fps: clip.fps, frames: clip.frames, joints: kept.map((j) => clip.joints[j]), parents: kept.map((j) => kept.indexOf(clip.parents[j])), positions };
        }
        pg.show(clip, '35_13.amc');
        window.cleanClip = pg.current();
      },
      { amc: AMC, asf: ASF, cut },
    );
    if ((await page.locator('#cleanup-toggle').getAttribute('aria-expanded')) !== 'true') await page.locator('#cleanup-toggle').click();
    await waitUntil(page, () => $ui('cleanup-status').dataset.state === 'clip', null, { message: 'the panel shows the new clip' });
  }

  /** Records every state #cleanup-status goes through, with whether Cancel and the progress bar were shown then. */
  function recordStates() {
    return suite.page.evaluate(() => {
      const status = $ui('cleanup-status');
      window.cleanupStates = [];
      window.cleanupObserver?.disconnect();
      const seen = () => window.cleanupStates.push({ state: status.dataset.state, cancel: !$ui('cleanup-cancel').hidden, progress: !$ui('cleanup-progress').hidden });
      window.cleanupObserver = new MutationObserver(seen);
      window.cleanupObserver.observe(status, { attributes: true, attributeFilter: ['data-state'] });
    });
  }

  const panel = () =>
    suite.page.evaluate(() => {
      const num = (id) => {
        const t = $ui(id).textContent;
        return t === '—' ? null : Number(t);
      };
      const row = (r) => ({ jerk: num(`cleanup-${r}-jerk`), sliding: num(`cleanup-${r}-sliding`), bones: num(`cleanup-${r}-bones`), error: num(`cleanup-${r}-error`) });
      const s = $ui('cleanup-status');
      const plot = $ui('cleanup-plot').dataset;
      const labels = [...$uiAll('.figure-label')].filter((l) => !l.hidden).map((l) => l.textContent);
      return {
        state: s.dataset.state, method: s.dataset.method ?? null, runs: Number(s.dataset.runs), text: s.textContent,
        ready: $ui('cleanup-readout').dataset.ready,
        input: row('input'), cleaned: row('cleaned'),
        plot: { joint: plot.joint, input: Number(plot.inputPoints), cleaned: Number(plot.cleanedPoints), original: Number(plot.originalPoints) },
        joint: $ui('cleanup-joint').selectedOptions[0]?.textContent ?? null,
        labels,
        exportDisabled: $ui('cleanup-export').disabled,
        restoreDisabled: $ui('cleanup-restore').disabled,
      };
    });

  /** Add noise with the tool (default settings: 3 cm jitter, 1 % outlier frames); resolves once the noisy clip is shown. */
  async function addNoise() {
    await suite.page.locator('#cleanup-add-noise').click();
    await waitUntil(suite.page, () => $ui('cleanup-status').dataset.state === 'noisy', null, { message: 'Add noise shows the noisy clip' });
  }

  /** Clean up with `method`, waiting until the cleaned motion is shown. */
  async function cleanUp(method) {
    const { page } = suite;
    await page.selectOption('#cleanup-method', method);
    const runs = (await panel()).runs;
    await recordStates();
    await page.locator('#cleanup-go').click();
    await waitUntil(page, (n) => {
      const d = $ui('cleanup-status').dataset;
      return (d.state === 'cleaned' && Number(d.runs) > n) || window.playground.lastError();
    }, runs, { timeout: CLEAN_TIMEOUT, message: `Clean up with ${method} finishes` });
    assert.equal(await page.evaluate(() => window.playground.lastError()), null, 'no error');
    return page.evaluate(() => window.cleanupStates);
  }

  test('Add noise replaces the shown clip with a noisy copy, and Restore brings the original back', async () => {
    const { page } = suite;
    await loadClip();
    const before = await panel();
    assert.equal(before.restoreDisabled, true, 'nothing to restore yet');
    assert.ok(before.input.jerk > 0 && before.input.error === null, `the clip's own numbers, no error column: ${JSON.stringify(before.input)}`);
    assert.match(before.joint ?? '', /left knee \(lfemur\)/, 'the left knee is plotted by default');
    assert.ok(before.plot.input > 300 && before.plot.cleaned === 0, `one curve before a clean-up: ${JSON.stringify(before.plot)}`);
    await addNoise();
    const noisy = await page.evaluate(() => {
      const m = window.playground.current(), c = window.cleanClip;
      let largest = 0;
      for (let i = 0; i < c.positions.length; i++) largest = Math.max(largest, Math.abs(m.positions[i] - c.positions[i]));
      return { same: m === c, frames: m.frames, cleanFrames: c.frames, joints: m.joints.join(), cleanJoints: c.joints.join(), largest, title: $ui('clip-name').textContent };
    });
    assert.equal(noisy.same, false, 'the noisy copy is shown');
    assert.equal(noisy.frames, noisy.cleanFrames);
    assert.equal(noisy.joints, noisy.cleanJoints);
    assert.ok(noisy.largest > 0.05, `the positions moved (largest ${noisy.largest} m)`);
    assert.equal(noisy.title, '35_13-noisy');
    const after = await panel();
    assert.match(after.text, /jitter 3 cm · 1 % outlier frames/);
    assert.ok(after.input.jerk > 3 * before.input.jerk, `noise raises the jerk (${before.input.jerk} → ${after.input.jerk})`);
    assert.ok(after.input.error > 2 && after.input.error < 8, `joint error to the clean clip ${after.input.error} cm`);
    assert.ok(after.plot.original > 300, 'the clean original is plotted too');
    await page.locator('#cleanup-restore').click();
    await waitUntil(page, () => $ui('cleanup-status').dataset.state === 'clip', null, { message: 'Restore shows the clip again' });
    assert.equal(await page.evaluate(() => window.playground.current() === window.cleanClip), true, 'the original clip itself is shown again');
    assert.equal(await page.evaluate(() => $ui('clip-name').textContent), '35_13.amc');
  });

  test('the controls are reached with Tab and work from the keyboard (a slider\'s arrows move it, not the playhead)', async () => {
    const { page } = suite;
    await loadClip();
    await page.evaluate(() => {
      window.playground.pause();
      window.playground.seek(100);
    });
    await page.locator('#cleanup-toggle').focus();
    const focused = () => page.evaluate(() => $uiActive()?.id);
    await page.keyboard.press('Tab');
    assert.equal(await focused(), 'cleanup-method');
    await page.keyboard.press('Tab');
    assert.equal(await focused(), 'cleanup-jitter');
    await page.keyboard.press('ArrowRight');
    assert.equal(await page.evaluate(() => $ui('cleanup-jitter-out').textContent), '3.5 cm');
    assert.equal((await page.evaluate(() => window.playground.state())).frame, 100, 'the playhead did not move');
    for (let i = 0; i < 3; i++) await page.keyboard.press('Tab');
    assert.equal(await focused(), 'cleanup-add-noise');
    await page.keyboard.press('Enter');
    await waitUntil(page, () => $ui('cleanup-status').dataset.state === 'noisy', null, { message: 'Enter on Add noise adds noise' });
    assert.match((await panel()).text, /jitter 3\.5 cm/);
    await page.evaluate(() => {
      const s = $ui('cleanup-jitter');
      s.value = '3';
      s.dispatchEvent(new Event('input'));
    });
  });

  for (const method of ['lowpass', 'manifold', 'map']) {
    test(`Clean up with ${method} shows the input and the cleaned motion side by side with their numbers and angle curves`, async () => {
      const { page } = suite;
      await loadClip();
      await addNoise();
      const input = await page.evaluate(() => (window.noisyInput = window.playground.current()).frames);
      const states = await cleanUp(method);
      assert.ok(states.some((s) => s.state === 'cleaning' && s.cancel && s.progress), `Cancel and the progress bar showed while cleaning: ${JSON.stringify(states)}`);
      const p = await panel();
      assert.equal(p.method, method);
      assert.equal(p.ready, 'both');
      assert.deepEqual(p.labels.sort(), [`cleaned · ${{ map: 'MAP', manifold: 'manifold', lowpass: 'low-pass' }[method]}`, 'input · noisy'].sort(), 'both figures are labelled');
      const shown = await page.evaluate(() => {
        const m = window.playground.current();
        return { frames: m.frames, joints: m.joints.join(), inputJoints: window.noisyInput.joints.join(), isInput: m === window.noisyInput, contacts: m.contacts?.length ?? 0 };
      });
      assert.equal(shown.isInput, false, 'the cleaned motion is the main figure');
      assert.equal(shown.frames, input);
      assert.equal(shown.joints, shown.inputJoints, 'on the input skeleton');
      assert.equal(shown.contacts, 2 * input);
      for (const row of ['input', 'cleaned']) {
        for (const [k, v] of Object.entries(p[row])) assert.ok(Number.isFinite(v), `${row} ${k} is a number: ${JSON.stringify(p[row])}`);
      }
      if (method !== 'map') assert.ok(p.cleaned.jerk < p.input.jerk, `${method} lowers the jerk (${p.input.jerk} → ${p.cleaned.jerk} m/s³)`);
      assert.ok(p.plot.input > 300 && p.plot.cleaned > 300, `both angle curves are drawn: ${JSON.stringify(p.plot)}`);
      assert.equal(p.plot.joint, 'lfemur');
      assert.equal(p.exportDisabled, false);
      assert.match(p.text, /s of motion in (\d+\.\d s|\d+ ms)/);
      if (method === 'map') {
        // The still for the docs: the panel after a clean-up, at 1280 × 800, nothing cut off or overlapping.
        await page.evaluate(() => {
          window.playground.pause();
          window.playground.seek(Math.round(window.playground.current().frames * 0.45));
        });
        await nextFrames(page, 6);
        const out = process.env.UPDATE_DOCS_SCREENSHOT ? path.join(ROOT, 'docs', 'cleanup.png') : path.join(ROOT, 'test-results', 'cleanup.png');
        mkdirSync(path.dirname(out), { recursive: true });
        writeFileSync(out, await page.screenshot({ type: 'png' }));
        const layout = await page.evaluate(() => {
          const card = $ui('cleanup-card'), bar = $ui('controls').getBoundingClientRect();
          const r = card.getBoundingClientRect();
          return { bottom: r.bottom, right: r.right, barTop: bar.top, barRight: bar.right, left: r.left, scroll: card.scrollHeight - card.clientHeight, width: innerWidth, height: innerHeight };
        });
        assert.ok(layout.scroll <= 0, `the panel fits without scrolling (${layout.scroll} px more)`);
        assert.ok(layout.right <= layout.width && layout.bottom <= layout.height, 'the panel is inside the window');
        assert.ok(layout.bottom < layout.barTop || layout.left > layout.barRight, 'the panel clears the playback bar');
      }
    });
  }

  test('Cancel stops a clean-up and keeps the input shown', async () => {
    const { page } = suite;
    await loadClip();
    await addNoise();
    await page.evaluate(() => (window.noisyInput = window.playground.current()));
    await page.selectOption('#cleanup-method', 'map');
    await page.locator('#cleanup-go').click();
    await waitUntil(page, () => $ui('cleanup-status').dataset.state === 'cleaning', null, { message: 'the clean-up starts' });
    await page.locator('#cleanup-cancel').click();
    await waitUntil(page, () => $ui('cleanup-status').dataset.state === 'noisy', null, { message: 'Cancel ends the clean-up' });
    const after = await page.evaluate(() => ({ same: window.playground.current() === window.noisyInput, error: window.playground.lastError(), labels: $uiAll('.figure-label').length }));
    assert.deepEqual(after, { same: true, error: null, labels: 0 });
  });

  test('Export BVH downloads the cleaned motion, which re-imports with the same frame count', async () => {
    const { page } = suite;
    await loadClip();
    await addNoise();
    await cleanUp('lowpass');
    const [download] = await Promise.all([page.waitForEvent('download'), page.locator('#cleanup-export').click()]);
    assert.equal(download.suggestedFilename(), '35_13-lowpass.bvh');
    const text = readFileSync(await download.path(), 'utf8');
    const back = await page.evaluate(async (t) => {
      const m = await window.playground.importMotion(t, 'bvh');
      return { frames: m.frames, shown: window.playground.current().frames };
    }, text);
    assert.equal(back.frames, back.shown);
    // Path mode and back: the cleaned motion and the input beside it come back, with the panel's state.
    await page.evaluate(() => (window.cleanedShown = window.playground.current()));
    await page.locator('#mode-path').click();
    await page.locator('#mode-clip').click();
    const after = await panel();
    assert.equal(await page.evaluate(() => window.playground.current() === window.cleanedShown), true);
    assert.equal(after.state, 'cleaned');
    assert.equal(after.labels.length, 2, 'both figures again');
  });

  test('a skeleton that is not a humanoid (one leg) gets the message, and the scene stays as it was', async () => {
    const { page } = suite;
    await loadClip('rhipjoint');
    await page.selectOption('#cleanup-method', 'map');
    await page.locator('#cleanup-go').click();
    const message = await waitUntil(page, () => window.playground.lastError(), null, { message: 'the error is shown' });
    assert.match(message, /^Clean up: this skeleton is not a humanoid the playground can map: no two legs/);
    assert.ok(await page.locator('.toast.error', { hasText: 'not a humanoid' }).isVisible(), 'as the page\'s message');
    const after = await page.evaluate(() => ({
      same: window.playground.current() === window.cleanClip,
      state: $ui('cleanup-status').dataset.state,
      labels: $uiAll('.figure-label').length,
      sliding: $ui('cleanup-input-sliding').textContent,
    }));
    assert.deepEqual(after, { same: true, state: 'clip', labels: 0, sliding: '—' });
    await page.evaluate(() => $uiAll('.toast').forEach((t) => t.remove()));
  });
});
