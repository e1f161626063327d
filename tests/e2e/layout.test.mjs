// Layout on small screens and in small embeds (issue 17): at phone size (390 × 844, a touch screen) in every
// mode and in a 400 × 300 embed (controls="full" and "minimal") every control lies inside the element (or inside
// a row that scrolls, which lies inside it), none overlaps another control, a card or a readout, every control
// scrolled into view is the one hit at its centre, and every mode button clicks. Touch works: a one-finger drag
// orbits, a drag on the timeline scrubs, a drag on the ground draws a path, a drag on the stick steers. The
// desktop layout (1280 × 800) passes the same checks. On the phone the walking and the dancing figure stand
// whole in the area the top bar, the cards and the panel leave free (the camera frames them there, issue 40).
// Screenshots go to test-results/layout-*.png.
import assert from 'node:assert/strict';
import { mkdirSync } from 'node:fs';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { corpusText, installUiLookups, launchBrowser, nextFrames, ROOT, startServer, waitUntil } from './harness.mjs';

const SHOTS = path.join(ROOT, 'test-results');
const MODES = ['clip', 'walk', 'dance', 'path', 'steer'];

/**
 * Runs in the page: the layout problems of the <motion-playground> matched by `target`, a selector or
 * [hostSelector, scopeSelector] (none = fine).
 * Controls are the visible buttons, inputs, selects and the steering stick; panels are the cards, readouts
 * and bars. Each box is clipped by its clipping ancestors (a row scrolled sideways shows part of itself);
 * boxes that contain one another are not compared. With `scopeSelector` (a popup such as the open Export menu)
 * only the controls inside it are checked, against one another: it may cover the rest, but must itself lie
 * whole inside the element, uncut by any clipping ancestor, and be what a tap on each of its controls hits.
 */
function layoutProblems(target) {
  const [hostSelector, scopeSelector = null] = Array.isArray(target) ? target : [target];
  const TOL = 1;
  const host = document.querySelector(hostSelector);
  const root = host.shadowRoot;
  const hb = host.getBoundingClientRect();
  const hostBox = { left: hb.left, top: hb.top, right: hb.right, bottom: hb.bottom };
  const name = (el) => (el.id ? `#${el.id}` : `${el.tagName.toLowerCase()}.${[...el.classList].join('.')}${el.dataset.layer ? `[${el.dataset.layer}]` : ''}`);
  const shown = (el) => el.checkVisibility({ checkVisibilityCSS: true }) && el.getClientRects().length > 0 && !el.closest('.toasts');
  const parentOf = (el) => el.parentElement ?? (el.parentNode instanceof ShadowRoot ? null : el.parentNode);
  const box = (r) => ({ left: r.left, top: r.top, right: r.right, bottom: r.bottom });
  const meet = (a, b) => ({ left: Math.max(a.left, b.left), top: Math.max(a.top, b.top), right: Math.min(a.right, b.right), bottom: Math.min(a.bottom, b.bottom) });
  const area = (r) => Math.max(0, r.right - r.left) * Math.max(0, r.bottom - r.top);
  const inside = (r, outer) => r.left >= outer.left - TOL && r.top >= outer.top - TOL && r.right <= outer.right + TOL && r.bottom <= outer.bottom + TOL;
  const fmt = (r) => `[${Math.round(r.left)},${Math.round(r.top)} ${Math.round(r.right - r.left)}×${Math.round(r.bottom - r.top)}]`;
  /** The ancestors (inside the shadow root) that clip their content, nearest first. */
  const clippers = (el) => {
    const out = [];
    for (let p = parentOf(el); p; p = parentOf(p)) {
      const s = getComputedStyle(p);
      if (s.overflowX !== 'visible' || s.overflowY !== 'visible') out.push(p);
    }
    return out;
  };
  const scrollable = (el) => {
    const s = getComputedStyle(el);
    return (/auto|scroll/.test(s.overflowX) && el.scrollWidth > el.clientWidth + 1) || (/auto|scroll/.test(s.overflowY) && el.scrollHeight > el.clientHeight + 1);
  };
  /** `el` is (inside) a sticky element and `other` scrolls in the same scrolling panel. */
  const underSticky = (el, other) => {
    let sticky = el;
    while (sticky && getComputedStyle(sticky).position !== 'sticky') sticky = parentOf(sticky);
    if (!sticky) return false;
    const panel = clippers(sticky).find(scrollable);
    return !!panel && panel.contains(other) && !sticky.contains(other);
  };
  const visibleBox = (el) => clippers(el).reduce((r, c) => meet(r, box(c.getBoundingClientRect())), meet(box(el.getBoundingClientRect()), hostBox));

  const scope = scopeSelector ? root.querySelector(scopeSelector) : null;
  const controls = [...(scope ?? root).querySelectorAll('button, input, select, textarea, .joystick')].filter((el) => el.type !== 'file' && shown(el));
  const panels = scope
    ? [...scope.querySelectorAll('output')].filter(shown)
    : [
        ...root.querySelectorAll('.brand, .mode-switch, .model-status, .controls, .skate-card, .plot-card, .cleanup-card, .steer-card, .path-hint, .empty-card, .readout, output, .steer-keys'),
      ].filter((el) => shown(el) && !el.closest('.export-menu'));
  const problems = [];
  if (scope) {
    const full = box(scope.getBoundingClientRect());
    if (!shown(scope)) problems.push(`${name(scope)} is not shown`);
    else if (!inside(full, hostBox)) problems.push(`${name(scope)} ${fmt(full)} is not inside the element ${fmt(hostBox)}`);
    else if (area(visibleBox(scope)) < area(full) - TOL * (full.right - full.left + full.bottom - full.top)) problems.push(`${name(scope)} ${fmt(full)} is cut off: ${fmt(visibleBox(scope))} shows`);
  }

  // Every control inside the element: whole, or partly hidden in a scrolling row that is inside the element.
  for (const el of controls) {
    const full = box(el.getBoundingClientRect());
    if (inside(full, hostBox) && area(visibleBox(el)) >= area(full) - TOL * (full.right - full.left + full.bottom - full.top)) continue;
    const row = clippers(el).find(scrollable);
    if (!row) problems.push(`${name(el)} ${fmt(full)} is cut off and not in a scrolling row`);
    else if (!inside(box(row.getBoundingClientRect()), hostBox)) problems.push(`${name(el)}'s scrolling row ${name(row)} is not inside the element`);
  }

  // Nothing overlaps (as shown: clipped by the scrolling rows).
  const items = [...controls.map((el) => ({ el, control: true })), ...panels.map((el) => ({ el, control: false }))];
  for (const it of items) it.r = visibleBox(it.el);
  for (let i = 0; i < items.length; i++) {
    for (let j = i + 1; j < items.length; j++) {
      const a = items[i], b = items[j];
      if (!a.control && !b.control) {
        // Two panels: only the floating ones (the cards and bars, not the readouts inside the footer) are compared.
        if (a.el.closest('.controls') && b.el.closest('.controls')) continue;
      }
      if (a.el.contains(b.el) || b.el.contains(a.el)) continue;
      // A sticky header covers what scrolls under it in its own panel (the hit test below scrolls each into view).
      if (underSticky(a.el, b.el) || underSticky(b.el, a.el)) continue;
      const m = meet(a.r, b.r);
      if (m.right - m.left > TOL && m.bottom - m.top > TOL) problems.push(`${name(a.el)} ${fmt(a.r)} overlaps ${name(b.el)} ${fmt(b.r)}`);
    }
  }

  // Every control, scrolled into view within its rows, is what a tap at its centre hits.
  for (const el of controls) {
    const rows = clippers(el).filter(scrollable);
    const saved = rows.map((row) => [row.scrollLeft, row.scrollTop]);
    for (const row of rows) {
      const r = el.getBoundingClientRect(), c = row.getBoundingClientRect();
      row.scrollLeft += r.left + r.width / 2 - (c.left + c.width / 2);
      row.scrollTop += r.top + r.height / 2 - (c.top + c.height / 2);
    }
    const r = el.getBoundingClientRect();
    const x = r.left + r.width / 2, y = r.top + r.height / 2;
    const hit = root.elementFromPoint(x, y);
    if (!inside(box(r), hostBox)) problems.push(`${name(el)} ${fmt(r)} is outside the element even scrolled into view`);
    else if (!hit || !(hit === el || el.contains(hit))) problems.push(`a tap on ${name(el)} ${fmt(r)} hits ${hit ? name(hit) : 'nothing'}`);
    rows.forEach((row, k) => ([row.scrollLeft, row.scrollTop] = saved[k]));
  }
  return { problems, controls: controls.length, panels: panels.length };
}

/** Asserts the layout of the element is sound; returns how many controls and panels it checked. */
async function checkLayout(page, what, hostSelector = 'motion-playground') {
  await nextFrames(page, 2);
  const report = await page.evaluate(layoutProblems, hostSelector);
  assert.deepEqual(report.problems, [], `${what}: every control reachable, nothing overlapping`);
  assert.ok(report.controls >= 8, `${what}: the controls were found (${report.controls})`);
  return report;
}

/**
 * Opens the header's Export menu (a popup: it may cover the stage and the other panels) and checks it: whole
 * inside the element, not cut off, every control in it reachable at its centre; a screenshot; Escape closes it.
 */
async function checkExportMenu(page, what, hostSelector = 'motion-playground', shotName = null) {
  const host = page.locator(hostSelector);
  await host.locator('#export-menu-btn').click({ timeout: 5_000 });
  assert.equal(await host.locator('#export-menu').isVisible(), true, `${what}: the Export menu opens`);
  assert.equal(await host.locator('#export-menu-btn').getAttribute('aria-expanded'), 'true');
  await nextFrames(page, 2);
  if (shotName) await shot(page, shotName, hostSelector === 'motion-playground' ? undefined : host);
  const report = await page.evaluate(layoutProblems, [hostSelector, '#export-menu']);
  assert.deepEqual(report.problems, [], `${what}, Export menu open: the menu whole and every control in it reachable`);
  assert.ok(report.controls >= 6, `${what}: the menu's controls were found (${report.controls})`);
  // Its items are really usable: the rest-pose select takes a choice (the menu stays open) and goes back.
  const rest = host.locator('#rest-pose');
  const was = await rest.inputValue();
  await rest.selectOption(was === 'clip' ? 'tpose' : 'clip', { timeout: 5_000 });
  await rest.selectOption(was, { timeout: 5_000 });
  assert.equal(await host.locator('#export-menu').isVisible(), true, `${what}: a select inside keeps the menu open`);
  await host.locator('#rest-pose').press('Escape');
  assert.equal(await host.locator('#export-menu').isVisible(), false, `${what}: Escape closes the menu`);
}

async function shot(page, name, locator) {
  await nextFrames(page, 2);
  mkdirSync(SHOTS, { recursive: true });
  await (locator ?? page).screenshot({ path: path.join(SHOTS, `layout-${name}.png`) });
}

/** Clicks a mode button (no force: it must be visible, enabled and not covered) and checks the mode took. */
async function clickMode(page, mode, host = page) {
  await host.locator(`#mode-${mode}`).click({ timeout: 5_000 });
  assert.equal(await host.locator(`#mode-${mode}`).getAttribute('aria-pressed'), 'true', `${mode}: its button is pressed`);
  assert.equal(await host.locator('.app').evaluate((el, m) => el.classList.contains(`${m}-mode`), mode), true, `${mode}: the view is in ${mode} mode`);
}

/** One-finger touch drag through CDP from `from` to `to` (page pixels) in `steps` moves; `hold` keeps the finger down. */
async function touchDrag(cdp, from, to, { steps = 8, hold = false } = {}) {
  const point = (t) => ({ x: from[0] + (to[0] - from[0]) * t, y: from[1] + (to[1] - from[1]) * t, id: 1, radiusX: 4, radiusY: 4, force: 1 });
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [point(0)] });
  for (let i = 1; i <= steps; i++) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [point(i / steps)] });
  const end = () => cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  if (hold) return end;
  await end();
  return null;
}

const canvasShot = (page) => page.locator('canvas.viewer-canvas').screenshot();
const pixelsDiffer = (a, b) => a.length !== b.length || !a.equals(b);

/** The canvas once it stands still (two shots a few frames apart the same): the camera has settled. */
async function stillShot(page) {
  let last = await canvasShot(page);
  for (let i = 0; i < 40; i++) {
    await nextFrames(page, 3);
    const next = await canvasShot(page);
    if (!pixelsDiffer(last, next)) return next;
    last = next;
  }
  throw new assert.AssertionError({ message: 'paused, the picture never stood still' });
}

/**
 * Where the paused figure stands on screen and where the overlays leave the stage free, in page pixels. The
 * figure: the bounding box of the bright (mannequin) pixels of the stage drawn with the overlays hidden and
 * the trail and footprints off. The free area: below the lowest top overlay (top bar, cards) over the figure's
 * columns and above the control panel.
 */
async function figureAndFreeArea(page) {
  await page.evaluate(() => {
    window.playground.pause();
    window.playground.setView({ trail: false, footprints: false });
  });
  const free = await page.evaluate(() => {
    const boxes = (selector) => [...$uiAll(selector)].filter((el) => el.checkVisibility({ checkVisibilityCSS: true })).map((el) => el.getBoundingClientRect());
    return { tops: boxes('.topbar *, .skate-card, .plot-card, .steer-card, .path-hint').map((r) => ({ left: r.left, right: r.right, bottom: r.bottom })), bottom: boxes('#controls')[0].top };
  });
  await page.evaluate(() => { $uiOne('.layout').style.visibility = 'hidden'; });
  const png = await stillShot(page);
  await page.evaluate(() => {
    $uiOne('.layout').style.visibility = '';
    window.playground.setView({ trail: true, footprints: true });
  });
  const stage = await page.locator('canvas.viewer-canvas').boundingBox();
  const figure = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const { data } = g.getImageData(0, 0, c.width, c.height);
    // The ground and sky are dark blue (channels under ~70); the mannequin's skin and grey parts are light.
    let left = Infinity, right = -Infinity, top = Infinity, bottom = -Infinity, count = 0;
    for (let y = 0; y < c.height; y++) {
      for (let x = 0; x < c.width; x++) {
        const i = (y * c.width + x) * 4;
        if (0.3 * data[i] + 0.59 * data[i + 1] + 0.11 * data[i + 2] < 100) continue;
        count++;
        left = Math.min(left, x); right = Math.max(right, x); top = Math.min(top, y); bottom = Math.max(bottom, y);
      }
    }
    return { left, right, top, bottom, count };
  }, png.toString('base64'));
  const box = { left: stage.x + figure.left, right: stage.x + figure.right, top: stage.y + figure.top, bottom: stage.y + figure.bottom, count: figure.count };
  const over = free.tops.filter((r) => r.right > box.left && r.left < box.right);
  return { figure: box, free: { top: Math.max(stage.y, ...over.map((r) => r.bottom)), bottom: free.bottom, left: stage.x, right: stage.x + stage.width } };
}

/** Asserts the figure stands whole inside the free area (head to feet clear of the cards and the panel). */
async function checkFigureInFreeArea(page, what) {
  const { figure, free } = await figureAndFreeArea(page);
  const fmt = (r) => `x ${Math.round(r.left)}–${Math.round(r.right)}, y ${Math.round(r.top)}–${Math.round(r.bottom)}`;
  assert.ok(figure.count > 500, `${what}: the figure is drawn (${figure.count} bright pixels)`);
  assert.ok(
    figure.top >= free.top && figure.bottom <= free.bottom && figure.left >= free.left && figure.right <= free.right,
    `${what}: the figure (${fmt(figure)}) stands inside the area the overlays leave free (${fmt(free)})`,
  );
  assert.ok(figure.bottom - figure.top > 0.3 * (free.bottom - free.top), `${what}: the figure (${fmt(figure)}) is not lost in the distance (free ${fmt(free)})`);
}

describe('layout on a phone and in a small embed', { timeout: 900_000 }, () => {
  let server, url, browser;
  const problems = [];
  before(async () => {
    ({ server, url } = await startServer());
    browser = await launchBrowser();
  });
  after(async () => {
    await browser?.close();
    await server?.close();
  });

  async function open(mode, { width, height, mobile }) {
    const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: 1, isMobile: mobile, hasTouch: mobile });
    const page = await context.newPage();
    page.on('console', (msg) => msg.type() === 'error' && problems.push(`console.error: ${msg.text()}`));
    page.on('pageerror', (err) => problems.push(`pageerror: ${err.message}`));
    await page.addInitScript(installUiLookups);
    // resolution=full pins the render size (it floats otherwise), so a paused picture stands still.
    await page.goto(`${url}?mode=${mode}&resolution=full`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.playground !== undefined, null, { timeout: 20_000 });
    await page.evaluate(() => window.playground.ready);
    return { context, page };
  }

  describe('phone, 390 × 844, touch', () => {
    let context, page, cdp;
    before(async () => {
      ({ context, page } = await open('clip', { width: 390, height: 844, mobile: true }));
      cdp = await context.newCDPSession(page);
    });
    after(() => context?.close());

    test('Clip: the empty view, a clip, the open Clean up panel', async () => {
      await shot(page, 'phone-clip-empty');
      await checkLayout(page, 'phone, Clip, empty');
      const bvh = corpusText('cmu/bvh/07_04.bvh.gz');
      await page.evaluate(async (text) => window.playground.show(await window.playground.importMotion(text, 'bvh'), '07_04'), bvh);
      await waitUntil(page, () => $uiFrame().classList.contains('has-motion'), null, { message: 'the clip is shown' });
      await shot(page, 'phone-clip');
      await checkLayout(page, 'phone, Clip');
      // The page has the link attribute: Share and Embed are in the top bar (checked above with the rest).
      for (const id of ['#share-btn', '#embed-btn']) assert.equal(await page.locator(id).isVisible(), true, `${id} shows on the page`);
      await checkExportMenu(page, 'phone, Clip', 'motion-playground', 'phone-clip-export');
      await page.locator('#cleanup-toggle').click();
      assert.equal(await page.locator('#cleanup-body').isVisible(), true);
      await shot(page, 'phone-clip-cleanup');
      await checkLayout(page, 'phone, Clip, Clean up open');
      await page.locator('#cleanup-toggle').click();
      assert.equal(await page.locator('#cleanup-body').isVisible(), false);
      assert.deepEqual(problems.splice(0), []);
    });

    test('touch in Clip: a one-finger drag on the stage orbits, a drag on the timeline scrubs', async () => {
      await page.evaluate(() => { window.playground.pause(); window.playground.seek(100); });
      const stage = await page.locator('canvas.viewer-canvas').boundingBox();
      const before = await stillShot(page);
      const cy = stage.y + stage.height * 0.45;
      await touchDrag(cdp, [stage.x + stage.width * 0.3, cy], [stage.x + stage.width * 0.75, cy]);
      await nextFrames(page, 20);
      assert.equal(pixelsDiffer(before, await canvasShot(page)), true, 'a one-finger drag turned the camera');
      assert.equal((await page.evaluate(() => window.playground.state())).frame, 100, 'orbiting leaves the frame');

      const bar = await page.locator('#timeline').boundingBox();
      const y = bar.y + bar.height / 2;
      const start = (await page.evaluate(() => window.playground.state())).frame;
      const thumb = bar.x + (bar.width * start) / 449;
      await touchDrag(cdp, [thumb, y], [bar.x + bar.width * 0.8, y]);
      const frame = (await page.evaluate(() => window.playground.state())).frame;
      assert.ok(frame > start + 100, `a drag on the timeline scrubs forward (frame ${start} → ${frame})`);
      assert.deepEqual(problems.splice(0), []);
    });

    test('Random walk and Dance', async () => {
      await clickMode(page, 'walk');
      await waitUntil(page, () => Number($ui('walk-status').dataset.frame) > 10, null, { timeout: 60_000, message: 'the walk runs' });
      await shot(page, 'phone-walk');
      await checkLayout(page, 'phone, Random walk');
      await checkFigureInFreeArea(page, 'phone, Random walk');
      await clickMode(page, 'dance');
      await waitUntil(page, () => Number($ui('dance-status').dataset.frame) > 10, null, { timeout: 60_000, message: 'the dance runs' });
      await shot(page, 'phone-dance');
      await checkLayout(page, 'phone, Dance');
      await checkFigureInFreeArea(page, 'phone, Dance');
      await page.evaluate(() => window.playground.play());
      assert.deepEqual(problems.splice(0), []);
    });

    test('Path: a touch drag on the ground draws a path', async () => {
      await clickMode(page, 'path');
      await shot(page, 'phone-path-empty');
      await checkLayout(page, 'phone, Path, no path');
      assert.equal(await page.locator('#path-go').isDisabled(), true);
      const stage = await page.locator('canvas.viewer-canvas').boundingBox();
      const at = (fx, fy) => [stage.x + fx * stage.width, stage.y + fy * stage.height];
      await touchDrag(cdp, at(0.3, 0.42), at(0.7, 0.36), { steps: 12 });
      await waitUntil(page, () => !$ui('path-go').disabled, null, { timeout: 60_000, message: 'a drawn path enables Go' });
      assert.match(await page.locator('#path-status').textContent(), /path \d/, 'the path status gives the drawn length');
      await shot(page, 'phone-path');
      await checkLayout(page, 'phone, Path, drawn');
      assert.deepEqual(problems.splice(0), []);
    });

    test('Steer: the readout and the stick stay clear of the controls; the stick steers by touch', async () => {
      await clickMode(page, 'steer');
      await waitUntil(page, () => Number($ui('steer-status').dataset.frame) > 15, null, { timeout: 60_000, message: 'the steered stream starts' });
      await shot(page, 'phone-steer');
      await checkLayout(page, 'phone, Steer');
      await checkExportMenu(page, 'phone, Steer', 'motion-playground', 'phone-steer-export');
      const slider = Number(await page.locator('#steer-speed').inputValue());
      const pad = await page.locator('#steer-joystick').boundingBox();
      const cx = pad.x + pad.width / 2, cy = pad.y + pad.height / 2;
      const release = await touchDrag(cdp, [cx, cy], [cx, cy - pad.height * 0.25], { hold: true });
      const held = await waitUntil(
        page,
        (s) => {
          const v = Number($ui('steer-readout').dataset.targetSpeed);
          return v > 0.1 * s && v < 0.9 * s ? { v, text: $ui('steer-target-speed').textContent } : null;
        },
        slider,
        { timeout: 10_000, message: 'half a stick asks for part of the speed' },
      );
      assert.equal(held.text, held.v.toFixed(2), 'the readout shows it');
      await release();
      await waitUntil(page, () => Number($ui('steer-readout').dataset.targetSpeed) === 0, null, { timeout: 10_000, message: 'a released stick stops' });
      assert.deepEqual(problems.splice(0), []);
    });

    test('every mode button clicks', async () => {
      for (const mode of ['clip', 'walk', 'dance', 'path', 'steer', 'clip']) await clickMode(page, mode);
      assert.deepEqual(problems.splice(0), []);
    });
  });

  describe('a 400 × 300 embed', () => {
    let context, page;
    before(async () => {
      ({ context, page } = await open('clip', { width: 880, height: 640, mobile: false }));
      await page.evaluate(() => {
        document.querySelector('motion-playground').remove();
        for (const controls of ['full', 'minimal']) {
          const el = document.createElement('motion-playground');
          el.id = `embed-${controls}`;
          el.setAttribute('mode', 'walk');
          el.setAttribute('controls', controls);
          el.setAttribute('camera-controls', '');
          el.style.cssText = 'width: 400px; height: 300px; margin: 10px; display: inline-block; vertical-align: top';
          document.body.append(el);
        }
      });
      const running = (id) => Number(document.getElementById(id).shadowRoot.getElementById('walk-status').dataset.frame) > 10;
      await waitUntil(page, running, 'embed-full', { timeout: 60_000, message: 'the full embed walks' });
      await waitUntil(page, running, 'embed-minimal', { timeout: 60_000, message: 'the minimal embed walks' });
    });
    after(() => context?.close());

    test('controls="full": every mode laid out, every mode button clicks', async () => {
      const host = page.locator('#embed-full');
      await shot(page, 'embed-full-walk', host);
      await checkLayout(page, 'embed, full, Random walk', '#embed-full');
      for (const id of ['#share-btn', '#embed-btn']) assert.equal(await host.locator(id).isVisible(), false, `${id} hides without the link attribute`);
      await checkExportMenu(page, 'embed, full, Random walk', '#embed-full', 'embed-full-export');
      // With the link attribute the top bar holds Share and Embed too.
      await host.evaluate((el) => el.setAttribute('link', ''));
      for (const id of ['#share-btn', '#embed-btn']) assert.equal(await host.locator(id).isVisible(), true, `${id} shows with the link attribute`);
      await shot(page, 'embed-full-link', host);
      await checkLayout(page, 'embed, full, link, Random walk', '#embed-full');
      await checkExportMenu(page, 'embed, full, link', '#embed-full', 'embed-full-link-export');
      await host.evaluate((el) => el.removeAttribute('link'));
      await clickMode(page, 'dance', host);
      await waitUntil(page, (id) => Number(document.getElementById('embed-full').shadowRoot.getElementById(id).dataset.frame) > 5, 'dance-status', { timeout: 60_000, message: 'the embed dances' });
      await shot(page, 'embed-full-dance', host);
      await checkLayout(page, 'embed, full, Dance', '#embed-full');
      await clickMode(page, 'path', host);
      await shot(page, 'embed-full-path', host);
      await checkLayout(page, 'embed, full, Path', '#embed-full');
      await clickMode(page, 'steer', host);
      await waitUntil(page, (id) => Number(document.getElementById('embed-full').shadowRoot.getElementById(id).dataset.frame) > 15, 'steer-status', { timeout: 60_000, message: 'the embed steers' });
      await shot(page, 'embed-full-steer', host);
      await checkLayout(page, 'embed, full, Steer', '#embed-full');
      await clickMode(page, 'clip', host);
      await shot(page, 'embed-full-clip-empty', host);
      await checkLayout(page, 'embed, full, Clip, empty', '#embed-full');
      const bvh = corpusText('cmu/bvh/07_04.bvh.gz');
      await host.evaluate(async (el, text) => el.playground.show(await el.playground.importMotion(text, 'bvh'), '07_04'), bvh);
      await waitUntil(page, () => document.getElementById('embed-full').shadowRoot.querySelector('.app').classList.contains('has-motion'), null, { message: 'the embed shows the clip' });
      await checkLayout(page, 'embed, full, Clip', '#embed-full');
      await checkExportMenu(page, 'embed, full, Clip', '#embed-full');
      await host.locator('#cleanup-toggle').click();
      await shot(page, 'embed-full-clip', host);
      await checkLayout(page, 'embed, full, Clip, Clean up open', '#embed-full');
      // Scrolled to its end, the panel's header stays in sight and closes it.
      await host.locator('#cleanup-card').evaluate((el) => { el.scrollTop = el.scrollHeight; });
      await shot(page, 'embed-full-clip-scrolled', host);
      await checkLayout(page, 'embed, full, Clip, Clean up scrolled', '#embed-full');
      const headHit = await host.evaluate((el) => {
        const head = el.shadowRoot.getElementById('cleanup-toggle'), r = head.getBoundingClientRect();
        const hit = el.shadowRoot.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
        return { scrolled: el.shadowRoot.getElementById('cleanup-card').scrollTop > 0, hit: !!hit && head.contains(hit) };
      });
      assert.deepEqual(headHit, { scrolled: true, hit: true }, 'scrolled, the header is still where a tap finds it');
      await host.locator('#cleanup-toggle').click();
      for (const mode of ['walk', 'clip']) await clickMode(page, mode, host);
      assert.deepEqual(problems.splice(0), []);
    });

    test('controls="minimal"', async () => {
      const report = await page.evaluate(layoutProblems, '#embed-minimal');
      assert.deepEqual(report.problems, []);
      assert.ok(report.controls >= 1, `the minimal controls were found (${report.controls})`);
      const host = page.locator('#embed-minimal');
      assert.equal(await host.locator('#play-btn').isVisible(), true, 'the play button shows');
      for (const hidden of ['.mode-switch', '#export-menu-btn', '#walk-controls', '.toggles'])
        assert.equal(await host.locator(hidden).isVisible(), false, `${hidden} is hidden`);
      await host.locator('#play-btn').click({ timeout: 5_000 });
      await host.locator('#play-btn').click({ timeout: 5_000 });
      await shot(page, 'embed-minimal', page.locator('#embed-minimal'));
      assert.deepEqual(problems.splice(0), []);
    });
  });

  test('desktop, 1280 × 800: the same checks in Clip (Clean up open) and Random walk', async () => {
    const { context, page } = await open('clip', { width: 1280, height: 800, mobile: false });
    try {
      const bvh = corpusText('cmu/bvh/07_04.bvh.gz');
      await page.evaluate(async (text) => window.playground.show(await window.playground.importMotion(text, 'bvh'), '07_04'), bvh);
      await page.locator('#cleanup-toggle').click();
      await shot(page, 'desktop-clip');
      await checkLayout(page, 'desktop, Clip, Clean up open');
      await checkExportMenu(page, 'desktop, Clip', 'motion-playground', 'desktop-clip-export');
      await clickMode(page, 'walk');
      await waitUntil(page, () => Number($ui('walk-status').dataset.frame) > 10, null, { timeout: 60_000, message: 'the walk runs' });
      await shot(page, 'desktop-walk');
      await checkLayout(page, 'desktop, Random walk');
      assert.deepEqual(problems.splice(0), []);
    } finally {
      await context.close();
    }
  });
});
