// Issue 17: the page's glTF and BVH exports open correctly in Blender. In the page (window.playground): a CMU
// BVH clip imported, a refined generator walk and an acLSTM salsa dance, each exported as GLB and BVH with the
// T-pose rest (and the CMU clip with its own 'clip' rest as well; and 120 frames of it with a joint named
// `<b>x</b>.y:z`); then one Blender process
// (tests/blender/check_import.py) imports every file with its own importer, plays it, and reads each bone's
// head against the positions the page had: at most 1 mm on every frame. Skipped when `blender` is not on PATH.
// Set BLENDER_KEEP_DIR to keep the exported files and the expected positions there.
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { corpusText, launchBrowser, openPlayground, ROOT, startServer, waitUntil } from './harness.mjs';

const CMU_CLIP = 'cmu/bvh/07_04.bvh.gz';
const TOLERANCE_M = 0.001;
const CHECK_SCRIPT = path.join(ROOT, 'tests', 'blender', 'check_import.py');

/** The blender executable on PATH (BLENDER overrides), or null. */
function findBlender() {
  if (process.env.BLENDER) return existsSync(process.env.BLENDER) ? process.env.BLENDER : null;
  for (const dir of (process.env.PATH ?? '').split(path.delimiter)) {
    const candidate = path.join(dir || '.', 'blender');
    if (existsSync(candidate)) return candidate;
  }
  return null;
}

/** Runs Blender in the background on the script; resolves with its exit code, stdout and stderr. */
function runBlender(blender, args, timeoutMs) {
  return new Promise((resolve, reject) => {
    const child = spawn(blender, ['-b', '--factory-startup', '-noaudio', '-P', CHECK_SCRIPT, '--', ...args], { stdio: ['ignore', 'pipe', 'pipe'] });
    let stdout = '';
    let stderr = '';
    child.stdout.on('data', (d) => (stdout += d));
    child.stderr.on('data', (d) => (stderr += d));
    const timer = setTimeout(() => child.kill('SIGKILL'), timeoutMs);
    child.on('error', (e) => {
      clearTimeout(timer);
      reject(e);
    });
    child.on('close', (code, signal) => {
      clearTimeout(timer);
      resolve({ code, signal, stdout, stderr });
    });
  });
}

/**
 * In-page: the three motions and their exports. Per motion: fps, frames, the positions (plain numbers), the
 * joint names as each file writes them (gltf.ts gltfJointNames, bvh.ts bvhJointNames: the modules the page
 * runs, from the dev server) and the exports asked for.
 */
function exportInPage(page, cmuText) {
  return page.evaluate(async (cmuText) => {
    const pg = window.playground;
    const { gltfJointNames } = await import('/motion/gltf.ts');
    const { bvhJointNames } = await import('/motion/bvh.ts');
    const motions = {
      cmu: { motion: await pg.importMotion(cmuText, 'bvh'), rests: ['tpose', 'clip'] },
      walk: { motion: await pg.generate({ model: 'generator', frames: 150, seed: 3, refine: true }), rests: ['tpose'] },
      dance: { motion: await pg.generate({ model: 'aclstm', style: 'salsa', seed: 1, frames: 150 }), rests: ['tpose'] },
    };
    // The CMU clip's first 120 frames with a joint named with markup and characters glTF names and Blender's
    // BVH reader could trip on.
    const cmu = motions.cmu.motion;
    const J = cmu.joints.length;
    const odd = {
      ...cmu, frames: 120, positions: cmu.positions.slice(0, 120 * J * 3), contacts: undefined,
      joints: cmu.joints.map((n) => (n === 'LeftToeBase' ? '<b>x</b>.y:z' : n)),
    };
    motions.odd = { motion: odd, rests: ['tpose'] };
    const out = {};
    for (const [key, { motion: m, rests }] of Object.entries(motions)) {
      const files = [];
      for (const restPose of rests) {
        files.push({ kind: 'glb', restPose, bytes: Array.from(pg.exportGLB(m, { restPose })) });
        files.push({ kind: 'bvh', restPose, text: pg.exportBVH(m, { restPose }) });
      }
      out[key] = {
        fps: m.fps, frames: m.frames, joints: m.joints, positions: Array.from(m.positions),
        names: { glb: gltfJointNames(m.joints), bvh: bvhJointNames(m.joints) }, files,
      };
    }
    return out;
  }, cmuText);
}

/** The EXPECTED.json check_import.py reads: per joint (its name in the file) its position on every frame. */
function expectedPositions(clip, names) {
  const J = clip.joints.length;
  const joints = {};
  names.forEach((name, j) => {
    const track = [];
    for (let f = 0; f < clip.frames; f++) {
      const b = (f * J + j) * 3;
      track.push([clip.positions[b], clip.positions[b + 1], clip.positions[b + 2]]);
    }
    joints[name] = track;
  });
  return { fps: clip.fps, frames: Array.from({ length: clip.frames }, (_, f) => f), joints };
}

const BLENDER = findBlender();

/**
 * In-page (issue 40): the CMU clip's first 120 frames on the quaternius character (../shared/characters, served by a
 * route) and on a Mixamo-named, 0.01-scaled rig made in the page, each exported with exportGLB(clip, { character:
 * true }); the expected positions are playground.retarget(clip)'s, keyed by the names the file gives the bones.
 */
function exportCharactersInPage(page, cmuText) {
  return page.evaluate(async ({ cmuText, rigsUrl }) => {
    const pg = window.playground;
    const rigs = await import(rigsUrl);
    const cmu = await pg.importMotion(cmuText, 'bvh');
    const J = cmu.joints.length;
    const clip = { ...cmu, frames: 120, positions: cmu.positions.slice(0, 120 * J * 3), contacts: undefined };
    const sources = { quaternius: 'characters/quaternius-human-male.glb', mixamo: await rigs.makeRig({ naming: 'mixamo', scale: 0.01, pose: 'A' }) };
    const out = {};
    for (const [key, source] of Object.entries(sources)) {
      await pg.loadCharacter(source);
      const bytes = await pg.exportGLB(clip, { character: true, name: key });
      const m = pg.retarget(clip);
      out[key] = { fps: m.fps, frames: m.frames, joints: m.joints, positions: Array.from(m.positions), names: { glb: m.joints.map(rigs.threeNodeName) }, files: [{ kind: 'glb', restPose: 'character', bytes: Array.from(bytes) }] };
    }
    return out;
  }, { cmuText, rigsUrl: `/@fs${ROOT}tests/support/characterRigs.mjs` });
}

describe('exports open correctly in Blender', { timeout: 600_000 }, () => {
  let server, url, browser, dir;
  before(async () => {
    if (!BLENDER) return;
    ({ server, url } = await startServer());
    browser = await launchBrowser();
    dir = process.env.BLENDER_KEEP_DIR ?? mkdtempSync(path.join(os.tmpdir(), 'blender-export-'));
    mkdirSync(dir, { recursive: true });
  });
  after(async () => {
    await browser?.close();
    await server?.close();
    if (dir && !process.env.BLENDER_KEEP_DIR) rmSync(dir, { recursive: true, force: true });
  });

  test('GLB and BVH of a CMU clip, a refined walk and a salsa dance: every joint within 1 mm on every frame', async (t) => {
    if (!BLENDER) {
      t.skip('Blender not installed: apt-get install blender');
      return;
    }
    const { page, problems, context } = await openPlayground(browser, url);
    await waitUntil(page, () => window.playground.models().some((m) => m.id === 'aclstm') && window.playground.models().some((m) => m.id === 'generator'), null, {
      message: 'the manifest never listed the generator and aclstm models',
    });
    const clips = await exportInPage(page, corpusText(CMU_CLIP));
    assert.deepEqual(problems, [], 'no console or page errors while exporting');
    await context.close();

    const args = [];
    for (const [key, clip] of Object.entries(clips)) {
      for (const file of clip.files) {
        const base = path.join(dir, `${key}-${file.restPose}`);
        const filePath = `${base}.${file.kind}`;
        const expectedPath = `${base}.${file.kind}.expected.json`;
        writeFileSync(filePath, file.kind === 'glb' ? Uint8Array.from(file.bytes) : file.text);
        writeFileSync(expectedPath, JSON.stringify(expectedPositions(clip, clip.names[file.kind])));
        args.push(filePath, expectedPath);
      }
    }

    const started = performance.now();
    const run = await runBlender(BLENDER, args, 480_000);
    const seconds = (performance.now() - started) / 1000;
    t.diagnostic(`Blender ran ${seconds.toFixed(1)} s for ${args.length / 2} files (${path.basename(BLENDER)} -b, one process)`);
    const results = run.stdout.split('\n').filter((l) => l.startsWith('RESULT ')).map((l) => JSON.parse(l.slice(7)));
    for (const r of results) {
      t.diagnostic(
        `${path.basename(r.file)}: max error ${(r.max_error_m * 1000).toFixed(4)} mm (${r.worst_joint ?? '-'} at frame ${r.worst_frame ?? '-'}; ` +
          `${r.joints_checked} joints × ${r.frames_checked} frames; ${r.skinned_meshes} skinned mesh(es)${r.missing_bones.length ? `; no bone for ${r.missing_bones.join(', ')}` : ''})`,
      );
    }
    const tail = `${run.stdout.slice(-2000)}\n${run.stderr.slice(-2000)}`;
    assert.equal(results.length, args.length / 2, `one RESULT line per file from Blender (exit ${run.code} ${run.signal ?? ''}):\n${tail}`);
    for (const r of results) {
      assert.deepEqual(r.missing_bones, [], `${path.basename(r.file)}: a bone for every joint`);
      if (r.file.endsWith('.glb')) assert.equal(r.skinned_meshes, 1, `${path.basename(r.file)}: one mesh skinned to the armature`);
      assert.ok(r.max_error_m <= TOLERANCE_M, `${path.basename(r.file)}: max error ${(r.max_error_m * 1000).toFixed(3)} mm at ${r.worst_joint}, frame ${r.worst_frame} (at most 1 mm)`);
    }
    assert.equal(run.code, 0, `Blender's exit status:\n${tail}`);
  });
  test('the animated character, exportGLB(motion, { character: true }): one armature deforming the mesh, every bone within 1 mm of the page\'s retargeted positions', async (t) => {
    if (!BLENDER) {
      t.skip('Blender not installed: apt-get install blender');
      return;
    }
    const { page, problems, context } = await openPlayground(browser, url);
    const glb = readFileSync(path.resolve(ROOT, '../shared/characters/quaternius-human-male.glb'));
    await context.route(`${url}characters/**`, (route) => route.fulfill({ status: 200, contentType: 'model/gltf-binary', headers: { 'Cross-Origin-Resource-Policy': 'same-origin' }, body: glb }));
    const clips = await exportCharactersInPage(page, corpusText(CMU_CLIP));
    assert.deepEqual(problems, [], 'no console or page errors while exporting');
    await context.close();
    const args = [];
    for (const [key, clip] of Object.entries(clips)) {
      const base = path.join(dir, `character-${key}`);
      writeFileSync(`${base}.glb`, Uint8Array.from(clip.files[0].bytes));
      writeFileSync(`${base}.glb.expected.json`, JSON.stringify(expectedPositions(clip, clip.names.glb)));
      args.push(`${base}.glb`, `${base}.glb.expected.json`);
    }
    const run = await runBlender(BLENDER, args, 480_000);
    const results = run.stdout.split('\n').filter((l) => l.startsWith('RESULT ')).map((l) => JSON.parse(l.slice(7)));
    for (const r of results) {
      t.diagnostic(`${path.basename(r.file)}: max error ${(r.max_error_m * 1000).toFixed(4)} mm (${r.worst_joint ?? '-'} at frame ${r.worst_frame ?? '-'}; ${r.joints_checked} bones × ${r.frames_checked} frames; ${r.skinned_meshes} skinned mesh(es))`);
    }
    const tail = `${run.stdout.slice(-2000)}\n${run.stderr.slice(-2000)}`;
    assert.equal(results.length, args.length / 2, `one RESULT line per file from Blender (exit ${run.code} ${run.signal ?? ''}):\n${tail}`);
    for (const r of results) {
      assert.deepEqual(r.missing_bones, [], `${path.basename(r.file)}: a bone for every bone of the character`);
      assert.equal(r.skinned_meshes, 1, `${path.basename(r.file)}: the mesh deformed by the one armature`);
      assert.ok(r.max_error_m <= TOLERANCE_M, `${path.basename(r.file)}: max error ${(r.max_error_m * 1000).toFixed(3)} mm at ${r.worst_joint}, frame ${r.worst_frame} (at most 1 mm)`);
    }
    assert.equal(run.code, 0, `Blender's exit status:\n${tail}`);
  });
});
