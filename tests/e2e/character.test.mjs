// Issue 40, "Bring your own character" and "Export the animated character": a rigged humanoid loaded by
// playground.loadCharacter (a URL, a Blob, bytes), dropped on the page, named by the element's `character` attribute
// or the page's `character=` URL parameter; rigs of other namings made in the page with three.js's GLTFExporter
// (tests/support/characterRigs.mjs: Mixamo-prefixed and 0.01-scaled in an A-pose, VRM 0.x and 1.0 humanoid maps, a
// skeleton facing −z); every mode drawing it live; Compare with two characters side by side; bad files refused with a short message that keeps
// the character and motion shown; the export of the animated character read back by three.js's GLTFLoader.
// The CC0 character ../shared/characters/quaternius-human-male.glb is served to the page by a route, never copied.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { describe, before, test } from 'node:test';
import { corpusText, installUiLookups, ROOT, sitePage, usePlayground, waitUntil } from './harness.mjs';

const CHARACTER = path.resolve(ROOT, '../shared/characters/quaternius-human-male.glb');
const RIGS = `/@fs${ROOT}tests/support/characterRigs.mjs`;
const WALK = 'cmu/bvh/07_04.bvh.gz';
const CORP = { 'Cross-Origin-Resource-Policy': 'same-origin' };

describe('your own character', { timeout: 600_000 }, () => {
  const suite = usePlayground();
  const pages = new Map();

  before(async () => {
    const glb = readFileSync(CHARACTER);
    // Every page of the context: the character under characters/, site pages under site/.
    await suite.context.route(`${suite.url}characters/**`, (route) => {
      const file = new URL(route.request().url()).pathname.replace(/^\/characters\//, '');
      if (file === 'quaternius-human-male.glb') return route.fulfill({ status: 200, contentType: 'model/gltf-binary', headers: CORP, body: glb });
      if (file === 'truncated.glb') return route.fulfill({ status: 200, contentType: 'model/gltf-binary', headers: CORP, body: glb.subarray(0, 100_000) });
      return route.fulfill({ status: 404, body: 'not here' });
    });
    await suite.context.route(`${suite.url}site/**`, (route) => {
      const file = new URL(route.request().url()).pathname.replace(/^\/site\//, '');
      if (pages.has(file)) return route.fulfill({ status: 200, contentType: 'text/html', body: pages.get(file) });
      if (file === 'characters/quaternius-human-male.glb') return route.fulfill({ status: 200, contentType: 'model/gltf-binary', body: glb });
      if (file === 'characters/truncated.glb') return route.fulfill({ status: 200, contentType: 'model/gltf-binary', body: glb.subarray(0, 100_000) });
      return route.fulfill({ status: 404, body: 'not here' });
    });
    await suite.page.evaluate(async (text) => {
      window.walk = await window.playground.importMotion(text, 'bvh');
    }, corpusText(WALK));
  });

  /** Shows the CMU walk and loads the quaternius character by URL; resolves to what loadCharacter resolved. */
  const loadQuaternius = () =>
    suite.page.evaluate(async () => {
      window.playground.show(window.walk, 'walk');
      return window.playground.loadCharacter('characters/quaternius-human-male.glb');
    });

  test('loadCharacter reads the quaternius rig: Unreal-style names mapped, its height and rest pose; drawn for the shown clip', async () => {
    const { page } = suite;
    const info = await loadQuaternius();
    assert.equal(info.name, 'quaternius-human-male');
    assert.equal(info.bones.length, 66);
    assert.equal(info.parents.length, 66);
    assert.equal(info.mapSource, 'mapped');
    assert.deepEqual(
      [info.mapping.Hips, info.mapping.LeftUpLeg, info.mapping.LeftLeg, info.mapping.LeftFoot, info.mapping.RightArm, info.mapping.RightHand, info.mapping.Head],
      ['pelvis', 'thigh_l', 'calf_l', 'foot_l', 'upperarm_r', 'hand_r', 'head'],
    );
    for (const point of info.missing) assert.ok(!(point in info.mapping), `${point} is both mapped and missing`);
    assert.ok(info.height > 1.5 && info.height < 1.9, `height ${info.height} m`);
    assert.equal(info.restPose.rotations.length, 66);
    assert.equal(info.restPose.translations.length, 66);
    // Rest positions in metres: the feet near the floor, the head ~height up.
    const ys = info.restPose.positions.map((p) => p[1]);
    assert.ok(Math.min(...ys) > -0.05 && Math.min(...ys) < 0.1, `lowest rest point ${Math.min(...ys)} m`);
    assert.ok(Math.abs(Math.max(...ys) - info.height) < 0.05, `highest rest point ${Math.max(...ys)} m vs height ${info.height}`);
    const drawn = await waitUntil(page, () => window.playground.stats().characterVertices === 7399 && window.playground.stats(), null, { message: 'the character is drawn' });
    assert.equal(drawn.look, 'character');
    assert.deepEqual(await page.evaluate(() => window.playground.character()?.name), 'quaternius-human-male');
    // Retargeted onto its own skeleton: its bone names, the shown clip's frames, feet on the floor.
    const r = await page.evaluate(() => {
      const m = window.playground.retarget(window.walk);
      const J = m.joints.length;
      let low = Infinity;
      const foot = m.joints.indexOf('ball_l');
      for (let f = 0; f < m.frames; f++) low = Math.min(low, m.positions[(f * J + foot) * 3 + 1]);
      return { joints: m.joints.length, first: m.joints[0], frames: m.frames, shown: window.playground.current().frames, low };
    });
    assert.deepEqual([r.joints, r.first, r.frames], [66, 'root', r.shown]);
    assert.ok(r.low > -0.05 && r.low < 0.08, `the left ball's lowest height ${r.low} m`);
    // The look switch applies to it: none drawn with the stick figure, see-through with it in Both.
    const looks = await page.evaluate(async () => {
      const pg = window.playground;
      const seen = {};
      for (const look of ['skeleton', 'both', 'character']) {
        pg.setView({ look });
        seen[look] = pg.stats().characterVertices;
      }
      return seen;
    });
    assert.deepEqual(looks, { skeleton: 0, both: 7399, character: 7399 });
    // Back to the mannequin.
    await page.evaluate(() => window.playground.clearCharacter());
    await waitUntil(page, () => window.playground.stats().characterVertices !== 7399, null, { message: 'the mannequin is back' });
    assert.equal(await page.evaluate(() => window.playground.character()), null);
  });

  test('rigs of other namings load and retarget facing the source: Mixamo 0.01 in an A-pose, VRM 0.x and 1.0 maps, facing −z, a helper root first', async () => {
    const results = await suite.page.evaluate(async (rigsUrl) => {
      const rigs = await import(rigsUrl);
      const pg = window.playground;
      const cases = {
        mixamo: { naming: 'mixamo', scale: 0.01, pose: 'A' },
        vrm0: { naming: 'vrm', vrm: 0 },
        vrm1: { naming: 'vrm', vrm: 1, pose: 'A' },
        backwards: { naming: 'vrm', facing: -1 },
        helperRoot: { naming: 'mixamo', helperRoot: true },
      };
      const src = window.walk;
      const SJ = src.joints.length;
      const s = (name, f) => Array.from(src.positions.subarray((f * SJ + src.joints.indexOf(name)) * 3, (f * SJ + src.joints.indexOf(name)) * 3 + 3));
      const out = {};
      for (const [key, options] of Object.entries(cases)) {
        const info = await pg.loadCharacter(await rigs.makeRig(options));
        const m = pg.retarget(src);
        const J = m.joints.length;
        const p = (name, f) => Array.from(m.positions.subarray((f * J + m.joints.indexOf(name)) * 3, (f * J + m.joints.indexOf(name)) * 3 + 3));
        // Over the clip: the cosine between the character's hip line (right → left) and the source's, and its hips' height.
        let cos = 0, hipY = 0;
        const [lh, rh, hips] = [info.mapping.LeftUpLeg, info.mapping.RightUpLeg, info.mapping.Hips];
        for (let f = 0; f < m.frames; f++) {
          const a = p(lh, f).map((v, i) => v - p(rh, f)[i]), b = s('LeftUpLeg', f).map((v, i) => v - s('RightUpLeg', f)[i]);
          cos += (a[0] * b[0] + a[2] * b[2]) / (Math.hypot(a[0], a[2]) * Math.hypot(b[0], b[2]) || 1);
          hipY += p(hips, f)[1];
        }
        out[key] = { first: info.bones[0], mapSource: info.mapSource, height: info.height, leftUpLeg: info.mapping.LeftUpLeg, leftHand: info.mapping.LeftHand, missing: info.missing, cos: cos / m.frames, hipY: hipY / m.frames };
      }
      return out;
    }, RIGS);
    assert.equal(results.mixamo.leftUpLeg, 'mixamorig:LeftUpLeg');
    assert.equal(results.mixamo.leftHand, 'mixamorig:LeftHand');
    assert.equal(results.mixamo.mapSource, 'mapped');
    assert.equal(results.vrm0.mapSource, 'vrm0');
    assert.equal(results.vrm1.mapSource, 'vrm1');
    assert.equal(results.vrm0.leftUpLeg, 'leftUpperLeg');
    assert.equal(results.helperRoot.first, 'ik_root', 'the helper root is the rig\'s first bone');
    for (const [key, r] of Object.entries(results)) {
      assert.ok(Math.abs(r.height - 1.72) < 0.03, `${key}: height ${r.height} m (the body is 1.72 m, whatever its units)`);
      assert.ok(r.cos > 0.95, `${key}: the character's hip line follows the source's (mean cosine ${r.cos.toFixed(3)})`);
      assert.ok(r.hipY > 0.75 && r.hipY < 1.05, `${key}: hips at ${r.hipY.toFixed(2)} m`);
    }
  });

  test('a .glb dropped on the page becomes the character', async () => {
    const { page } = suite;
    await page.evaluate(() => window.playground.clearCharacter());
    await page.evaluate(async () => {
      window.playground.show(window.walk, 'walk');
      const bytes = await (await fetch('characters/quaternius-human-male.glb')).arrayBuffer();
      const data = new DataTransfer();
      data.items.add(new File([bytes], 'dropped-hero.glb', { type: 'model/gltf-binary' }));
      $uiFrame().dispatchEvent(new DragEvent('drop', { dataTransfer: data, bubbles: true, cancelable: true }));
    });
    const name = await waitUntil(page, () => window.playground.character()?.name, null, { message: 'the dropped character is loaded' });
    assert.equal(name, 'dropped-hero');
    await waitUntil(page, () => window.playground.stats().characterVertices === 7399, null, { message: 'the dropped character is drawn' });
    assert.equal(await page.evaluate(() => window.playground.current().frames), 450, 'the motion stays');
    // The Export menu offers the export on it.
    assert.equal(await page.evaluate(() => $ui('export-on-character-row').hidden), false);
  });

  test('the character attribute loads one; a bad one fires error with a short reason', async () => {
    pages.set('attr.html', sitePage(`
      <motion-playground id="good" character="characters/quaternius-human-male.glb" controls="minimal"></motion-playground>
      <motion-playground id="far" character="https://example.com/hero.glb" controls="none"></motion-playground>`));
    const page = await suite.context.newPage();
    try {
      await page.goto(`${suite.url}site/attr.html`, { waitUntil: 'load' });
      await waitUntil(page, () => ['good', 'far'].every((id) => window.events.some((e) => e.id === id && e.type === 'load')), null, { timeout: 90_000, message: 'both elements load' });
      const r = await page.evaluate(() => {
        const [good, far] = document.querySelectorAll('motion-playground');
        return {
          good: good.playground.character()?.name ?? null,
          prop: good.character,
          farError: window.events.find((e) => e.id === 'far' && e.type === 'error')?.detail.reason ?? null,
          far: far.playground.character(),
        };
      });
      assert.equal(r.good, 'quaternius-human-male');
      assert.equal(r.prop, 'characters/quaternius-human-male.glb');
      assert.match(r.farError, /^character: .*example\.com.*(origin|allowed)/);
      assert.ok(r.farError.length <= 300);
      assert.equal(r.far, null);
      // Changing the attribute to a broken file fires error and keeps the character.
      await page.evaluate(() => (document.getElementById('good').character = 'characters/truncated.glb'));
      const reason = await waitUntil(page, () => window.events.find((e) => e.id === 'good' && e.type === 'error')?.detail.reason, null, { message: 'the broken file fires error' });
      assert.match(reason, /^character: .*(cut short|could not be read)/);
      assert.equal(await page.evaluate(() => document.getElementById('good').playground.character()?.name), 'quaternius-human-male');
    } finally {
      await page.close();
    }
  });

  test('the page loads the character of its URL parameter character=', async () => {
    const page = await suite.context.newPage();
    try {
      await page.addInitScript(installUiLookups);
      await page.goto(`${suite.url}?mode=clip&character=characters/quaternius-human-male.glb`, { waitUntil: 'load' });
      await page.waitForFunction(() => window.playground !== undefined);
      const name = await waitUntil(page, () => window.playground.character()?.name, null, { timeout: 60_000, message: 'the URL parameter loads the character' });
      assert.equal(name, 'quaternius-human-male');
      assert.match(page.url(), /character=characters/, 'the parameter stays in the link');
    } finally {
      await page.close();
    }
  });

  test('bad files are refused with a short message, and the character and motion shown stay', async () => {
    const { page } = suite;
    await loadQuaternius();
    const r = await page.evaluate(async (rigsUrl) => {
      const rigs = await import(rigsUrl);
      const pg = window.playground;
      const full = new Uint8Array(await (await fetch('characters/quaternius-human-male.glb')).arrayBuffer());
      const bad = {
        noSkin: await rigs.makeRig({ skin: false }),
        truncated: full.slice(0, 200_000),
        noLegs: await rigs.makeRig({ legs: false }),
        notGltf: new TextEncoder().encode('HIERARCHY\nROOT Hips'),
        huge: new Blob([new Uint8Array(33 * 1024 * 1024)]),
        missingUrl: 'characters/nothing.glb',
      };
      const out = {};
      for (const [key, source] of Object.entries(bad)) {
        try {
          await pg.loadCharacter(source);
          out[key] = { message: null };
        } catch (e) {
          out[key] = { message: e.message, lastError: pg.lastError(), character: pg.character()?.name, frames: pg.current()?.frames };
        }
      }
      return out;
    }, RIGS);
    const expected = {
      noSkin: /no skinned mesh/,
      truncated: /cut short|could not be read/,
      noLegs: /not a humanoid.*(leg|foot|feet)/i,
      notGltf: /not a glTF file/,
      huge: /33\.0 MiB; the limit is 32 MiB/,
      missingUrl: /HTTP 404/,
    };
    for (const [key, pattern] of Object.entries(expected)) {
      const o = r[key];
      assert.ok(o.message, `${key} is refused`);
      assert.match(o.message, /^loadCharacter: /, key);
      assert.match(o.message, pattern, key);
      assert.ok(o.message.length <= 300, `${key}: ${o.message.length} characters`);
      assert.equal(o.lastError, o.message, `${key}: shown on the page`);
      assert.equal(o.character, 'quaternius-human-male', `${key}: the character stays`);
      assert.equal(o.frames, 450, `${key}: the motion stays`);
    }
    assert.equal(await page.evaluate(() => window.playground.stats().characterVertices), 7399, 'still drawn');
    // The missing URL's 404 is the browser's own console line: expected here, and the only one.
    const problems = suite.problems.splice(0);
    assert.deepEqual(problems.filter((p) => !/status of 404/.test(p)), []);
  });

  test('exportGLB(motion, { character: true }) reads back in GLTFLoader: one skin, and every bone within 1 mm of retarget() on every frame', async () => {
    const { page } = suite;
    await loadQuaternius();
    const r = await page.evaluate(async (rigsUrl) => {
      const rigs = await import(rigsUrl);
      const pg = window.playground;
      const clip = { ...window.walk, frames: 90, positions: window.walk.positions.slice(0, 90 * window.walk.joints.length * 3), contacts: undefined };
      /** The export of the loaded character read back, against retarget(): the worst bone position error (m). */
      const roundTrip = async () => {
        const bytes = await pg.exportGLB(clip, { character: true, name: 'hero-walk' });
        const expected = pg.retarget(clip);
        const back = await rigs.playBack(bytes, clip.fps, clip.frames, expected.joints);
        let worst = 0;
        expected.joints.forEach((_, k) => {
          for (let f = 0; f < clip.frames; f++) {
            for (let i = 0; i < 3; i++) worst = Math.max(worst, Math.abs(back.positions[k][f * 3 + i] - expected.positions[(f * expected.joints.length + k) * 3 + i]));
          }
        });
        return { bytes, back, worst };
      };
      // A rig whose first bone is a helper root beside the hips' tree: the root the hips hang from is moved.
      await pg.loadCharacter(await rigs.makeRig({ naming: 'mixamo', helperRoot: true }));
      const helper = await roundTrip();
      await pg.loadCharacter('characters/quaternius-human-male.glb');
      const { bytes, back, worst } = await roundTrip();
      const bvh = pg.exportBVH(clip, { character: true });
      const fromBvh = await pg.importMotion(bvh, 'bvh');
      return { bytes: bytes.length, isUint8: bytes instanceof Uint8Array, ...back, positions: undefined, worst, helperWorst: helper.worst, bvhJoints: fromBvh.joints, bvhFrames: fromBvh.frames, plain: pg.exportGLB(clip) instanceof Uint8Array };
    }, RIGS);
    assert.ok(r.helperWorst < 0.001, `helper-root rig: worst bone position error ${(r.helperWorst * 1000).toFixed(3)} mm`);
    assert.ok(r.isUint8 && r.bytes > 100_000, `${r.bytes} bytes`);
    assert.equal(r.plain, true, 'the plain export is still bytes, not a promise');
    assert.equal(r.skinnedMeshes, 1);
    assert.equal(r.bones, 66);
    assert.equal(r.clips, 1);
    assert.equal(r.tracks, 67, 'a rotation per bone and the root translation');
    assert.ok(r.found.every(Boolean), 'every bone is a node of the file');
    assert.ok(r.worst < 0.001, `worst bone position error ${(r.worst * 1000).toFixed(3)} mm`);
    assert.equal(r.bvhFrames, 90);
    assert.ok(r.bvhJoints.includes('thigh_l') && r.bvhJoints.includes('pelvis'), 'the BVH is on the character\'s skeleton');
  });

  test('Compare: Random walk side by side draws two characters, the companion its own', async () => {
    const { page } = suite;
    const companion = await page.evaluate(async (rigsUrl) => {
      const rigs = await import(rigsUrl);
      await window.playground.loadCharacter('characters/quaternius-human-male.glb');
      return window.playground.loadCharacter(await rigs.makeRig({ naming: 'mixamo', scale: 0.01, pose: 'A' }), { companion: true });
    }, RIGS);
    await page.evaluate(() => {
      $ui('mode-walk').click();
      if (!$ui('walk-refine').checked) $ui('walk-refine').click();
      if (!$ui('walk-side-by-side').checked) $ui('walk-side-by-side').click();
    });
    const stats = await waitUntil(page, () => window.playground.stats().companionVertices > 0 && window.playground.stats(), null, { timeout: 180_000, message: 'the companion is drawn as a character' });
    assert.equal(stats.characterVertices, 7399, 'the main figure is the quaternius character');
    assert.equal(stats.companionVertices, companion.vertices, 'the companion is the second character');
    assert.notEqual(companion.vertices, 7399);
    await page.evaluate(() => $ui('mode-clip').click());
  });
  test('every mode draws the character live: Random walk, Dance, Steer stream it chunk after chunk, Path walks it', async () => {
    const { page } = suite;
    await loadQuaternius();
    /** In the page: from the first frame the character is drawn until the stream holds `frames` frames, the frames it was not. */
    const watch = (frames) =>
      page.evaluate(
        (frames) =>
          new Promise((resolve) => {
            let drawn = 0, missed = 0;
            const step = () => {
              const on = window.playground.stats().characterVertices === 7399;
              if (on) drawn++;
              else if (drawn) missed++;
              if ((window.playground.current()?.frames ?? 0) >= frames && drawn) resolve({ drawn, missed, frames: window.playground.current().frames });
              else requestAnimationFrame(step);
            };
            requestAnimationFrame(step);
          }),
        frames,
      );
    for (const mode of ['walk', 'dance', 'steer']) {
      await page.evaluate((mode) => $ui(`mode-${mode}`).click(), mode);
      const r = await Promise.race([watch(240), new Promise((resolve) => setTimeout(() => resolve(null), 240_000))]);
      assert.ok(r, `${mode}: the stream reached 8 s with the character drawn`);
      assert.equal(r.missed, 0, `${mode}: the character stayed drawn over ${r.drawn} frames (${r.frames} streamed frames)`);
    }
    await page.evaluate(() => {
      const el = document.querySelector('motion-playground');
      el.setAttribute('model', 'latent-erd');
      el.setAttribute('path', '0,0;3,1.5;6,0');
      el.setAttribute('mode', 'path');
    });
    await waitUntil(page, () => window.playground.current()?.frames > 60 && window.playground.stats().characterVertices === 7399, null, { timeout: 180_000, message: 'Path mode walks the path as the character' });
    await page.evaluate(() => {
      const el = document.querySelector('motion-playground');
      el.removeAttribute('path');
      el.setAttribute('mode', 'clip');
    });
  });
  test('a live stream whose first window does not map (a foot held high) draws the character from the next window that does', async () => {
    const r = await suite.page.evaluate(async () => {
      const { Viewer } = await import('/viewer/viewer.ts');
      const { parseCharacter, UserCharacterDriver } = await import('/viewer/userCharacter.ts');
      const asset = await parseCharacter(await (await fetch('characters/quaternius-human-male.glb')).arrayBuffer(), 'q.glb');
      const m = window.walk;
      const J = m.joints.length;
      // The walk's first 20 frames with the right leg below the hip lifted 0.6 m: no second foot near the floor.
      const raised = new Set();
      m.parents.forEach((p, j) => { if ((p >= 0 && m.joints[p] === 'RightUpLeg') || raised.has(p)) raised.add(j); });
      const positions = m.positions.slice(0, 120 * J * 3);
      for (let f = 0; f < 20; f++) for (const j of raised) positions[(f * J + j) * 3 + 1] += 0.6;
      const window_ = (n) => ({ ...m, frames: n, positions: positions.slice(0, n * J * 3), contacts: undefined });
      const host = document.createElement('div');
      host.style.cssText = 'position:fixed;left:0;top:0;width:320px;height:240px';
      document.body.appendChild(host);
      const viewer = new Viewer(host);
      try {
        viewer.setCharacterSource((motion) => {
          const driver = new UserCharacterDriver(asset, { lit: false });
          if (driver.setMotion(motion)) return driver;
          driver.dispose();
          return null;
        });
        viewer.setLive(window_(20), undefined, -1);
        const first = viewer.stats().characterVertices;
        viewer.setLive(window_(120), undefined, 0);
        return { raised: raised.size, first, next: viewer.stats().characterVertices };
      } finally {
        viewer.dispose();
        host.remove();
      }
    });
    assert.ok(r.raised >= 3, `the right leg's joints found (${r.raised})`);
    assert.notEqual(r.first, 7399, 'the first window does not retarget onto the character');
    assert.equal(r.next, 7399, 'the next window draws the character');
  });
  test('live chunks are joined smoothly: steps at chunk boundaries no larger than elsewhere, close to one retargeting of the window', async () => {
    const r = await suite.page.evaluate(async () => {
      const { parseCharacter, UserCharacterDriver } = await import('/viewer/userCharacter.ts');
      const asset = await parseCharacter(await (await fetch('characters/quaternius-human-male.glb')).arrayBuffer(), 'q.glb');
      const out = {};
      const sources = { walk: { model: 'generator', frames: 600, seed: 3, refine: true }, dance: { model: 'aclstm', style: 'salsa', seed: 10, frames: 600 } };
      for (const [name, options] of Object.entries(sources)) {
        const m = await window.playground.generate(options);
        const J = m.joints.length;
        const window_ = (start, end) => ({ ...m, frames: end - start, positions: m.positions.slice(start * J * 3, end * J * 3), contacts: m.contacts?.slice(start * 2, end * 2) });
        // Windows as the live modes build them: chunks of 30 frames, at most 300 kept.
        const live = new UserCharacterDriver(asset, { lit: false });
        for (let end = 30; end <= 600; end += 30) live.setMotion(window_(Math.max(0, end - 300), end));
        const whole = new UserCharacterDriver(asset, { lit: false });
        whole.setMotion(window_(300, 600));
        const a = live.retargeted.motion.positions, b = whole.retargeted.motion.positions, B = live.retargeted.motion.joints.length;
        const step = (k, f) => Math.hypot(...[0, 1, 2].map((i) => a[(f * B + k) * 3 + i] - a[((f - 1) * B + k) * 3 + i]));
        const result = {};
        for (const bone of ['pelvis', 'foot_l', 'hand_r']) {
          const k = live.retargeted.motion.joints.indexOf(bone);
          const at = [], elsewhere = [];
          for (let f = 1; f < 300; f++) (f % 30 === 0 ? at : elsewhere).push(step(k, f));
          elsewhere.sort((x, y) => x - y);
          result[bone] = { boundaryMax: Math.max(...at), elsewhereP95: elsewhere[Math.floor(elsewhere.length * 0.95)], elsewhereMax: elsewhere[elsewhere.length - 1] };
        }
        let sum = 0;
        for (let f = 30; f < 300; f++) for (let k = 0; k < B; k++) sum += Math.hypot(...[0, 1, 2].map((i) => a[(f * B + k) * 3 + i] - b[(f * B + k) * 3 + i]));
        out[name] = { ...result, meanFromWhole: sum / (270 * B) };
      }
      return out;
    });
    for (const [name, o] of Object.entries(r)) {
      for (const bone of ['pelvis', 'foot_l', 'hand_r']) {
        const { boundaryMax, elsewhereMax } = o[bone];
        assert.ok(boundaryMax <= elsewhereMax, `${name}, ${bone}: largest step at a chunk boundary ${(boundaryMax * 100).toFixed(1)} cm, elsewhere at most ${(elsewhereMax * 100).toFixed(1)} cm`);
      }
      // The whole window's retargeting measures the source on its own 300 frames, the stream once on its first 5 s
      // (measured: 4.6 cm on the walk, 9.3 cm on the salsa); a chunk retargeted alone ran off by metres.
      assert.ok(o.meanFromWhole < 0.15, `${name}: bones ${(o.meanFromWhole * 100).toFixed(1)} cm from one retargeting of the window on average`);
    }
  });
});
