// The header's Export menu (issue 17): Export BVH and Export glTF with the rest-pose choice, Snapshot (a PNG
// of the view) and Record (a WebM of the canvas for a chosen length, or until stopped). The video's length is
// read with ffprobe (Debian's ffmpeg); without ffprobe that check is skipped with a message.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { corpusText, usePlayground, waitUntil } from './harness.mjs';

const FFPROBE = (() => {
  try {
    execFileSync('ffprobe', ['-version'], { stdio: 'ignore' });
    return 'ffprobe';
  } catch {
    return null;
  }
})();

/** The video stream's packet times (s), from ffprobe. */
function packetTimes(file) {
  const out = execFileSync(FFPROBE, ['-v', 'error', '-select_streams', 'v:0', '-show_entries', 'packet=pts_time', '-of', 'csv=p=0', file], { encoding: 'utf8' });
  return out.split('\n').map((line) => parseFloat(line)).filter(Number.isFinite); // lines read "0.047000," 
}

describe('Export menu: exports, snapshot and recording', { timeout: 180_000 }, () => {
  const suite = usePlayground();
  let dir;

  before(async () => {
    dir = mkdtempSync(path.join(tmpdir(), 'playground-capture-'));
    await suite.page.evaluate(async (bvh) => {
      const p = window.playground;
      p.show(await p.importMotion(bvh, 'bvh'), '07_04.bvh');
    }, corpusText('cmu/bvh/07_04.bvh.gz'));
  });
  after(() => dir && rmSync(dir, { recursive: true, force: true }));

  /** Opens the menu unless it is open. */
  async function openMenu() {
    const { page } = suite;
    if (!(await page.locator('#export-menu').isVisible())) await page.locator('#export-menu-btn').click();
    await waitUntil(page, () => !$ui('export-menu').hidden, null, { message: 'the Export menu opens' });
  }

  /** Opens the menu (if closed), clicks `id` and saves the download it starts. */
  async function download(id) {
    const { page } = suite;
    await openMenu();
    const [file] = await Promise.all([page.waitForEvent('download', { timeout: 60_000 }), page.locator(id).click()]);
    const to = path.join(dir, file.suggestedFilename());
    await file.saveAs(to);
    return to;
  }

  test('the menu opens from its button, closes on Escape, and the keyboard reaches its items', async () => {
    const { page } = suite;
    await page.locator('#export-menu-btn').click();
    assert.equal(await page.locator('#export-menu').isVisible(), true);
    assert.equal(await page.locator('#export-menu-btn').getAttribute('aria-expanded'), 'true');
    assert.equal(await page.evaluate(() => $uiActive()?.id), 'export-btn', 'focus moves to the first item');
    await page.keyboard.press('Escape');
    assert.equal(await page.locator('#export-menu').isVisible(), false);
    assert.equal(await page.evaluate(() => $uiActive()?.id), 'export-menu-btn', 'focus goes back to the button');
  });

  test('Export BVH and Export glTF follow the rest-pose choice', async () => {
    const { page } = suite;
    const bvh = readFileSync(await download('#export-btn'), 'utf8');
    assert.equal(await page.locator('#export-menu').isVisible(), false, 'an export closes the menu');
    await openMenu();
    await page.locator('#rest-pose').selectOption('clip');
    const bvhClip = readFileSync(await download('#export-btn'), 'utf8');
    const glbClip = readFileSync(await download('#export-glb-btn'));
    await openMenu();
    await page.locator('#rest-pose').selectOption('tpose');
    const glb = readFileSync(await download('#export-glb-btn'));
    const expected = await page.evaluate(() => {
      const p = window.playground, m = p.current();
      return { tpose: p.exportBVH(m, { restPose: 'tpose' }), clip: p.exportBVH(m, { restPose: 'clip' }) };
    });
    assert.equal(bvh, expected.tpose, 'T-pose is the default rest pose');
    assert.equal(bvhClip, expected.clip);
    assert.notEqual(expected.tpose, expected.clip);
    for (const file of [glb, glbClip]) {
      assert.equal(file.subarray(0, 4).toString('latin1'), 'glTF');
      assert.equal(file.readUInt32LE(8), file.length, 'the GLB header gives its length');
      const json = JSON.parse(file.subarray(20, 20 + file.readUInt32LE(12)).toString('utf8'));
      assert.equal(json.skins.length, 1);
      assert.equal(json.animations.length, 1);
      assert.equal(json.meshes.length, 1);
    }
    assert.notDeepEqual(glb, glbClip);
  });

  test('a skeleton without named legs and arms is exported with its own rest pose, and the note says why', async () => {
    const { page } = suite;
    const before = await page.evaluate(() => window.playground.current());
    await page.evaluate(() => {
      const frames = 4;
      const positions = new Float32Array(frames * 2 * 3);
      for (let f = 0; f < frames; f++) positions.set([0.1 * f, 1, 0, 0.1 * f, 1.5, 0], f * 6);
      window.playground.show({ joints: ['Root', 'Top'], parents: [-1, 0], fps: 30, frames, positions }, 'stick');
    });
    const bvh = readFileSync(await download('#export-btn'), 'utf8');
    assert.match(bvh, /^HIERARCHY/);
    const note = await waitUntil(page, () => [...$uiAll('.toast')].map((t) => t.textContent).find((t) => /T-pose/.test(t)), null, { message: 'a note says the T-pose could not be used' });
    assert.match(note, /exported with the clip's own rest pose instead/);
    await page.evaluate((m) => window.playground.show(m, '07_04.bvh'), before);
  });

  test('Snapshot saves a PNG of the view at the canvas size', async () => {
    const { page } = suite;
    // The viewer scales its resolution with the frame time (quality.ts), so on a busy machine the canvas may be
    // resized while the file is saved: the PNG has the size the canvas had just before or just after.
    const canvasSize = () => page.evaluate(() => {
      const c = $uiOne('canvas.viewer-canvas');
      return [c.width, c.height];
    });
    const before = await canvasSize();
    const png = readFileSync(await download('#snapshot-btn'));
    const after = await canvasSize();
    assert.equal(png.subarray(1, 4).toString('latin1'), 'PNG');
    const got = [png.readUInt32BE(16), png.readUInt32BE(20)];
    assert.ok([before, after].some((s) => s[0] === got[0] && s[1] === got[1]), `the PNG (${got}) has the canvas's size (${before} before, ${after} after)`);
    assert.ok(png.length > 20_000, `the image holds a scene, not a blank canvas (${png.length} bytes)`);
  });

  test('Record saves a WebM of the chosen length', { skip: FFPROBE ? false : 'ffprobe not installed (apt-get install ffmpeg): the WebM length is not checked' }, async () => {
    const { page } = suite;
    await openMenu();
    await page.locator('#record-seconds').selectOption('5');
    const recorded = download('#record-btn');
    await waitUntil(page, () => $ui('record-status').dataset.state === 'recording' && !$ui('record-dot').hidden, null, { message: 'the recording starts and the header shows it' });
    const file = await recorded;
    assert.match(path.basename(file), /^07_04\.webm$/);
    assert.equal(readFileSync(file).readUInt32BE(0), 0x1a45dfa3, 'an EBML (WebM) file');
    const times = packetTimes(file);
    const length = times.at(-1) - times[0];
    assert.ok(times.length >= 40, `frames were recorded (${times.length})`);
    assert.ok(Math.abs(length - 5) < 0.6, `the video lasts the 5 s asked for: ${length.toFixed(2)} s over ${times.length} frames`);
    assert.equal(await page.evaluate(() => $ui('record-status').dataset.state), 'saved');
  });

  test('Record until stopped saves when Stop is pressed', { skip: FFPROBE ? false : 'ffprobe not installed (apt-get install ffmpeg)' }, async () => {
    const { page } = suite;
    await openMenu();
    await page.locator('#record-seconds').selectOption('0');
    await page.locator('#record-btn').click();
    await waitUntil(page, () => $ui('record-btn').textContent === 'Stop', null, { message: 'Record becomes Stop' });
    await waitUntil(page, () => /● [1-9]/.test($ui('record-status').textContent), null, { message: 'the status counts the seconds' });
    const [file] = await Promise.all([page.waitForEvent('download'), page.locator('#record-btn').click()]);
    const to = path.join(dir, 'stopped.webm');
    await file.saveAs(to);
    const times = packetTimes(to);
    assert.ok(times.length > 5 && times.at(-1) - times[0] >= 0.8, `what was recorded until Stop is saved (${times.length} frames, ${(times.at(-1) - times[0]).toFixed(2)} s)`);
    assert.equal(await page.evaluate(() => $ui('record-btn').textContent), 'Record');
  });
});
