// End-to-end tests of the optimiser modes in the page: Path mode (draw a stroke on the ground with the
// mouse, Go, the optimised walk plays with its stats; bad strokes keep what was there; Clear; Export BVH)
// and Steer mode (keys, a gamepad and the on-screen stick set the target; the stream advances and the
// character follows). Run with `node --test tests/e2e/pathMode.test.mjs`.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { describe, test } from 'node:test';
import { drawStroke, nextFrames, usePlayground, waitUntil } from './harness.mjs';

const STATS = /error mean (\d+\.\d) cm · max (\d+\.\d) cm · (\d+) % of the path · (\d+\.\d) s for (\d+\.\d) s of motion/;

/** A straight stroke across the middle of the view, `n` + 1 points. */
function line(x0, x1, y, n = 30) {
  return Array.from({ length: n + 1 }, (_, i) => [x0 + ((x1 - x0) * i) / n, y]);
}

const pathState = (page) =>
  page.evaluate(() => {
    const s = $ui('path-status');
    return { state: s.dataset.state, text: s.textContent };
  });

/** In-page summary of the shown motion: size, finiteness, root travel (m) and start-to-end distance. */
const shown = (page) =>
  page.evaluate(() => {
    const m = window.playground.current();
    if (!m) return null;
    const J = m.joints.length, P = m.positions;
    let finite = true, travel = 0;
    for (let i = 0; i < P.length; i++) if (!Number.isFinite(P[i])) finite = false;
    for (let f = 1; f < m.frames; f++) travel += Math.hypot(P[f * J * 3] - P[(f - 1) * J * 3], P[f * J * 3 + 2] - P[(f - 1) * J * 3 + 2]);
    const e = (m.frames - 1) * J * 3;
    return {
      frames: m.frames, fps: m.fps, joints: J, length: P.length, finite, travel,
      span: Math.hypot(P[e] - P[0], P[e + 2] - P[2]),
      contacts: m.contacts?.length ?? null,
      playing: window.playground.state().playing,
      same: m === window.pathBefore,
    };
  });

const readout = (page) =>
  page.evaluate(() => {
    const d = $ui('steer-readout').dataset;
    return {
      targetSpeed: Number(d.targetSpeed), targetHeading: Number(d.targetHeading), speed: d.speed === '' ? NaN : Number(d.speed), heading: d.heading === '' ? NaN : Number(d.heading),
      frame: Number($ui('steer-status').dataset.frame),
      slider: Number($ui('steer-speed').value),
      sliderText: $ui('steer-speed-out').textContent,
    };
  });

/**
 * The readout once it has refreshed after this call. It refreshes every 100 ms in the Steer mode's
 * animation loop, which applies the keys, the gamepad and the on-screen stick first in the same tick, so
 * any input given before this call shows in it.
 */
async function freshReadout(page) {
  await page.evaluate(
    () =>
      new Promise((resolve) => {
        const observer = new MutationObserver(() => {
          observer.disconnect();
          resolve();
        });
        observer.observe($ui('steer-readout'), { attributes: true });
      }),
  );
  return readout(page);
}

/** Angle a − b wrapped to (−π, π]. */
const angle = (a, b) => Math.atan2(Math.sin(a - b), Math.cos(a - b));

/**
 * Holds `key` until `until` (run in the page with `arg`) is true of the readout, then lets go; returns
 * the readout after the release. `what` says what the key should do.
 */
async function holdUntil(page, key, until, arg, what) {
  await page.keyboard.down(key);
  try {
    await waitUntil(page, until, arg, { timeout: 20_000, message: what });
  } finally {
    await page.keyboard.up(key);
  }
  return freshReadout(page);
}

/** A 60-frame generated clip shown in Clip mode: what leaving a live mode must come back to. */
async function showClipToComeBackTo(page) {
  await page.click('#mode-clip');
  await page.evaluate(async () => {
    const m = await window.playground.generate({ model: 'generator', frames: 60, seed: 1 });
    window.playground.show(m, 'clip');
  });
}

/** Path mode from an empty stage (Path mode keeps its path and walk while away). */
async function enterEmptyPathMode(page) {
  await page.click('#mode-path');
  if (await page.locator('#path-clear').isEnabled()) await page.click('#path-clear');
}

/**
 * Path mode with a walk along a stroke done: a 60-frame clip shown first (to come back to), then Path
 * mode from empty, the stroke drawn, Go, and the optimiser finished. Returns the drawn path's length (m).
 */
async function walkAStroke(page, points) {
  await showClipToComeBackTo(page);
  await enterEmptyPathMode(page);
  await drawStroke(page, points);
  const drawn = await pathState(page);
  assert.equal(drawn.state, 'drawn', `the stroke is a path (${drawn.text})`);
  await page.click('#path-go');
  await waitUntil(page, () => $ui('path-status').dataset.state !== 'optimising', null, { timeout: 180_000, message: 'the optimiser finishes' });
  const done = await pathState(page);
  assert.equal(done.state, 'done', `the walk arrived (${done.text}; last error ${await page.evaluate(() => window.playground.lastError())})`);
  return Number(/path (\d+\.\d) m/.exec(drawn.text)?.[1]);
}

describe('Path and Steer modes', { timeout: 400_000 }, () => {
  const suite = usePlayground();

  test('Path mode: a drawn stroke is walked; stats, the result plays, Export BVH saves it', async () => {
    const page = suite.page;
    await showClipToComeBackTo(page);
    await enterEmptyPathMode(page);
    const ui = await page.evaluate(() => ({
      path: $uiFrame().classList.contains('path-mode'),
      pressed: $ui('mode-path').getAttribute('aria-pressed'),
      controls: getComputedStyle($ui('path-controls')).display,
      current: window.playground.current(),
      go: $ui('path-go').disabled,
      progress: $ui('path-progress').hidden,
    }));
    assert.deepEqual(ui, { path: true, pressed: 'true', controls: 'flex', current: null, go: true, progress: true });
    assert.equal((await pathState(page)).state, 'empty');

    // Left to right across the middle of the view: the orbit controls must not turn the view meanwhile.
    await drawStroke(page, line(0.3, 0.7, 0.45));
    const drawn = await pathState(page);
    assert.equal(drawn.state, 'drawn');
    const length = Number(/path (\d+\.\d) m/.exec(drawn.text)?.[1]);
    assert.ok(length > 2 && length < 15, `a stroke of a few metres (${drawn.text})`);
    assert.equal(await page.locator('#path-go').isDisabled(), false);

    await page.click('#path-go');
    const busy = await page.evaluate(() => ({
      state: $ui('path-status').dataset.state,
      progress: $ui('path-progress').hidden,
      go: $ui('path-go').disabled,
    }));
    assert.deepEqual(busy, { state: 'optimising', progress: false, go: true }, 'the progress bar shows while optimising');
    await waitUntil(page, () => $ui('path-status').dataset.state !== 'optimising', null, { timeout: 180_000, message: 'the optimiser finishes' });
    const done = await pathState(page);
    assert.equal(done.state, 'done', `the walk arrived (${done.text}; last error ${await page.evaluate(() => window.playground.lastError())})`);
    const stats = STATS.exec(done.text);
    assert.ok(stats, `the status shows the stats: ${done.text}`);
    const [mean, max, progress, optimiseS, motionS] = stats.slice(1).map(Number);
    assert.ok(mean <= max && max < 100, `errors in cm (${mean}, ${max})`);
    assert.ok(progress >= 80, `most of the path is walked (${progress} %)`);
    // The optimisation time is shown (the regex); how it compares with the motion's duration is `npm run bench`'s path-follow.
    assert.ok(motionS > 1, `a walk of more than a second (${optimiseS} s for ${motionS} s)`);
    assert.match(done.text, /drawn path.*walked \(root\)/, 'the legend names both lines');

    const m = await shown(page);
    assert.equal(m.fps, 30);
    assert.equal(m.joints, 25);
    assert.ok(m.frames > 30, `${m.frames} frames`);
    assert.equal(m.length, m.frames * 25 * 3);
    assert.ok(m.finite, 'finite positions');
    assert.equal(m.contacts, m.frames * 2);
    assert.equal(m.playing, true, 'the walk plays');
    assert.ok(Math.abs(m.span - length) < 0.25 * length, `a straight stroke is walked end to end (${m.span.toFixed(2)} m of ${length} m)`);
    assert.ok(Math.abs((m.frames - 1) / 30 - motionS) < 0.1, 'the stats describe the shown motion');
    assert.equal(await page.evaluate(() => $uiFrame().classList.contains('path-mode')), true, 'still in Path mode');
    assert.equal(await page.locator('#path-progress').isHidden(), true);

    const [download] = await Promise.all([page.waitForEvent('download'), page.locator('#export-menu-btn').click().then(() => page.locator('#export-btn').click())]);
    assert.equal(download.suggestedFilename(), 'path-walk.bvh');
    const back = await page.evaluate((text) => window.playground.importMotion(text, 'bvh').then((r) => r.frames), readFileSync(await download.path(), 'utf8'));
    assert.equal(back, m.frames, 'the export holds the walk');
  });

  test('Path mode: a click or a too-short stroke keeps the path and the walk; redrawing replaces the path', async () => {
    const page = suite.page;
    await walkAStroke(page, line(0.3, 0.7, 0.45));
    await page.evaluate(() => (window.pathBefore = window.playground.current()));
    const before = await pathState(page);
    assert.equal(before.state, 'done');

    const box = await page.locator('canvas.viewer-canvas').boundingBox();
    await page.mouse.click(box.x + box.width * 0.5, box.y + box.height * 0.3);
    await nextFrames(page, 2);
    assert.deepEqual(await pathState(page), before, 'a click changes nothing');

    await drawStroke(page, line(0.5, 0.515, 0.3, 4));
    const error = await page.evaluate(() => window.playground.lastError());
    assert.match(String(error), /^Path: that stroke is 0\.\d\d m long; draw at least 0\.5 m\. The previous path is kept\.$/);
    assert.equal(await page.locator('.toast.error').last().textContent().then((t) => t.includes('draw at least 0.5 m')), true, 'the message is on the page');
    assert.deepEqual(await pathState(page), before, 'the status (and path) are kept');
    assert.equal((await shown(page)).same, true, 'the walk is kept');

    await drawStroke(page, line(0.35, 0.6, 0.35));
    const redrawn = await pathState(page);
    assert.equal(redrawn.state, 'drawn');
    assert.match(redrawn.text, /Go walks it \(showing the walk along the previous path\)/);
    assert.equal((await shown(page)).same, true, 'the previous walk plays until Go');
  });

  test('Path mode: Clip restores the clip, coming back shows the walk, Clear empties the stage', async () => {
    const page = suite.page;
    // A walk done, then a new path drawn (waiting for Go, the walk still shown).
    await walkAStroke(page, line(0.3, 0.7, 0.45));
    await page.evaluate(() => (window.pathBefore = window.playground.current()));
    await drawStroke(page, line(0.35, 0.6, 0.35));
    assert.equal((await pathState(page)).state, 'drawn');

    await page.click('#mode-clip');
    const clip = await shown(page);
    assert.equal(clip.frames, 60, 'the clip shown before Path mode is back');
    assert.equal(await page.evaluate(() => $uiFrame().classList.contains('path-mode')), false);

    await page.click('#mode-path');
    const again = await shown(page);
    assert.equal(again.same, true, 'the walk is shown again');
    assert.equal((await pathState(page)).state, 'drawn', 'with the path drawn since');

    await page.click('#path-clear');
    assert.equal(await page.evaluate(() => window.playground.current()), null);
    assert.equal((await pathState(page)).state, 'empty');
    assert.equal(await page.locator('#path-go').isDisabled(), true);
    assert.equal(await page.locator('#export-btn').isDisabled(), true);
    await page.click('#mode-clip');
    assert.equal((await shown(page)).frames, 60);
  });

  test('Steer mode: keys, a gamepad and the on-screen stick set the target; the character follows', async () => {
    const page = suite.page;
    await showClipToComeBackTo(page);
    await page.click('#mode-steer');
    await waitUntil(page, () => Number($ui('steer-status').dataset.frame) > 15, null, { timeout: 120_000, message: 'the steered stream starts' });
    const start = await readout(page);
    assert.equal(start.targetSpeed, 1.2, 'default target speed');
    assert.equal(start.targetHeading, 0, 'the stream starts facing +z');
    assert.ok(Math.abs(start.speed - 1.2) < 0.6, `achieved speed near the target (${start.speed})`);
    assert.equal(await page.locator('#steer-readout').isVisible(), true);
    assert.equal(await page.locator('#steer-joystick').isVisible(), true);
    assert.equal(await page.locator('#timeline').isVisible(), false, 'live: no timeline');

    // ← turns the target heading left (toward +x: a growing heading) while held, without stepping playback;
    // it stops when let go. (The rate, 90° a second, is `npm run bench`'s steer-keys.)
    const turned = await holdUntil(page, 'ArrowLeft', () => Number($ui('steer-readout').dataset.targetHeading) > 0.8, null, '← turns the target heading left past 0.8 rad');
    assert.ok(turned.targetHeading > 0.8 && turned.targetHeading < Math.PI, `heading after ← (${turned.targetHeading.toFixed(2)} rad)`);
    assert.equal(await page.evaluate(() => window.playground.state().playing), true, '← steers instead of stepping frames');
    const f = turned.frame;
    await waitUntil(page, (f) => Number($ui('steer-status').dataset.frame) > f + 6, f, { timeout: 60_000, message: 'the stream goes on' });
    assert.equal((await freshReadout(page)).targetHeading, turned.targetHeading, 'a released key stops turning');
    // The character turns to it.
    await waitUntil(
      page,
      (h) => Math.abs(Math.atan2(Math.sin(Number($ui('steer-readout').dataset.heading) - h), Math.cos(Number($ui('steer-readout').dataset.heading) - h))) < 0.4,
      turned.targetHeading,
      { timeout: 60_000, message: 'the character turns to face the target heading' },
    );

    // D turns right; ↑ speeds up (the slider follows).
    const right = await holdUntil(page, 'd', (h) => Number($ui('steer-readout').dataset.targetHeading) < h - 0.3, turned.targetHeading, 'D turns the target heading right by 0.3 rad');
    assert.ok(right.targetHeading < turned.targetHeading - 0.3, `D turns right (${turned.targetHeading.toFixed(2)} → ${right.targetHeading.toFixed(2)})`);
    const faster = await holdUntil(page, 'ArrowUp', () => Number($ui('steer-readout').dataset.targetSpeed) > 1.5, null, '↑ raises the target speed past 1.5 m/s');
    assert.ok(faster.targetSpeed > 1.5, `↑ raises the target speed (${faster.targetSpeed})`);
    assert.ok(Math.abs(faster.slider - faster.targetSpeed) <= 0.026, `the slider follows (${faster.slider})`);
    assert.ok(Math.abs(Number.parseFloat(faster.sliderText) - faster.targetSpeed) <= 0.051, `so does its output (${faster.sliderText})`);

    // A gamepad's left stick: up and right are a quarter turn apart (relative to the camera); letting go stops.
    await page.evaluate(() => {
      window.stick = [0, 0];
      Object.defineProperty(navigator, 'getGamepads', { configurable: true, value: () => [{ connected: true, axes: window.stick, buttons: [] }] });
    });
    await page.evaluate(() => (window.stick = [0, -1]));
    const up = await freshReadout(page);
    await page.evaluate(() => (window.stick = [1, 0]));
    const stickRight = await freshReadout(page);
    assert.ok(Math.abs(angle(stickRight.targetHeading, up.targetHeading) + Math.PI / 2) < 0.4, `right is 90° clockwise of up (${up.targetHeading.toFixed(2)}, ${stickRight.targetHeading.toFixed(2)})`);
    assert.equal(stickRight.targetSpeed, faster.targetSpeed, 'full stick: the slider speed');
    await page.evaluate(() => (window.stick = [0, 0]));
    assert.equal((await freshReadout(page)).targetSpeed, 0, 'a released stick stops');

    // A key gives the full speed back.
    await page.keyboard.press('ArrowUp');
    const keys = await freshReadout(page);
    assert.ok(Math.abs(keys.targetSpeed - keys.slider) <= 0.026, `↑ after the stick: the slider's speed again (${keys.targetSpeed} of ${keys.slider})`);

    // The on-screen stick: dragged half way up asks for about half the speed; letting go stops.
    const pad = await page.locator('#steer-joystick').boundingBox();
    const cx = pad.x + pad.width / 2, cy = pad.y + pad.height / 2;
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx, cy - pad.height * 0.35, { steps: 4 });
    const dragged = await freshReadout(page);
    assert.ok(dragged.targetSpeed > 0.2 * dragged.slider && dragged.targetSpeed < 0.8 * dragged.slider, `half a stick, part of the speed (${dragged.targetSpeed} of ${dragged.slider})`);
    await page.mouse.up();
    assert.equal((await freshReadout(page)).targetSpeed, 0, 'a released on-screen stick stops');

    // The stream kept going all along, with sound frames.
    const f0 = (await readout(page)).frame;
    await waitUntil(page, (f) => Number($ui('steer-status').dataset.frame) > f + 20, f0, { timeout: 60_000, message: 'the stream goes on' });
    const live = await shown(page);
    assert.equal(live.joints, 25);
    assert.ok(live.finite, 'finite positions');

    await page.click('#mode-clip');
    assert.equal((await shown(page)).frames, 60, 'the clip is back');
    assert.equal(await page.locator('#steer-readout').isVisible(), false);
  });
});
