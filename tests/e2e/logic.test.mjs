// Browser-free checks of the page's small pure modules (playback clock, dynamic resolution, file-kind
// sniffing, joint-side naming), loaded through Vite's SSR module loader so the TypeScript runs as is.
import assert from 'node:assert/strict';
import path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { createServer } from 'vite';
import { ROOT } from './harness.mjs';

describe('page logic', () => {
  let server, playback, quality, files, naming;

  before(async () => {
    server = await createServer({
      configFile: path.join(ROOT, 'vite.config.ts'),
      logLevel: 'warn',
      server: { middlewareMode: true, hmr: false, watch: null },
    });
    playback = await server.ssrLoadModule('/viewer/playback.ts');
    quality = await server.ssrLoadModule('/viewer/quality.ts');
    files = await server.ssrLoadModule('/ui/files.ts');
    naming = await server.ssrLoadModule('/viewer/naming.ts');
  });

  after(async () => {
    await server?.close();
  });

  test('playback is time-based, loops, clamps seeks and speed', () => {
    const p = new playback.Playback();
    p.reset(121, 120); // one second
    assert.equal(p.duration, 1);
    p.advance(0.5);
    assert.equal(p.frame, 0, 'paused: no advance');
    p.playing = true;
    p.advance(0.25);
    assert.equal(p.frame, 30);
    assert.equal(p.frameFloat, 30);
    // The same wall time in many small steps lands on the same frame.
    const q = new playback.Playback();
    q.reset(121, 120);
    q.playing = true;
    for (let i = 0; i < 15; i++) q.advance(0.25 / 15);
    assert.ok(Math.abs(q.frameFloat - 30) < 1e-9);
    p.setSpeed(2);
    p.advance(0.25);
    assert.equal(p.frame, 90);
    p.advance(0.25); // 1.25 s → wraps to 0.25 s
    assert.equal(p.frame, 30);
    assert.equal(p.setSpeed(5), playback.MAX_SPEED);
    assert.equal(p.setSpeed(0), playback.MIN_SPEED);
    p.seek(1000);
    assert.equal(p.frame, 120);
    p.seek(-3);
    assert.equal(p.frame, 0);
    p.seek(7.5);
    assert.equal(p.frame, 7);
    assert.equal(p.frameFloat, 7.5);
    const s = p.state();
    assert.deepEqual(Object.keys(s).sort(), ['fps', 'frame', 'frames', 'playing', 'speed', 'time']);
  });

  test('dynamic resolution steps down when slow, back up when calm, never straight back', () => {
    const r = new quality.DynamicResolution(0.5, 1, 1);
    let now = 0;
    const run = (fps, seconds) => {
      let changed = 0;
      for (let i = 0; i < fps * seconds; i++) {
        now += 1000 / fps;
        if (r.sample(1 / fps, now)) changed++;
      }
      return changed;
    };
    run(60, 3);
    assert.equal(r.scale, 1, 'fast enough: full resolution');
    run(30, 1.1);
    assert.ok(r.scale < 1, 'slow: scaled down');
    const low = r.scale;
    run(30, 10);
    assert.equal(r.scale, 0.5, 'keeps stepping down to the floor');
    run(60, 6);
    assert.equal(r.scale, 0.5, 'for a while, not back up to a level that was just too slow');
    run(60, 12);
    assert.ok(r.scale > 0.5 && r.scale < low, 'then recovers step by step');
    run(60, 60);
    assert.equal(r.scale, 1, 'eventually back to full');
    const fixed = new quality.DynamicResolution(0.5, 1, 0.75, true);
    assert.equal(fixed.scale, 1);
    assert.equal(fixed.sample(1 / 10, 5000), false);
  });

  test('software GL is recognised', () => {
    assert.equal(quality.chooseQuality({ renderer: 'x', software: true }, ''), 'low');
    assert.equal(quality.chooseQuality({ renderer: 'x', software: false }, ''), 'high');
    assert.equal(quality.chooseQuality({ renderer: 'x', software: true }, '?quality=high'), 'high');
    assert.equal(quality.fixedResolution('?resolution=full'), true);
    assert.equal(quality.fixedResolution(''), false);
  });

  test('file kinds from names and contents', () => {
    assert.equal(files.kindFromName('walk.BVH'), 'bvh');
    assert.equal(files.kindFromName('16_11.amc.gz'), 'amc');
    assert.equal(files.kindFromName('16.asf'), 'asf');
    assert.equal(files.kindFromName('notes.txt'), null);
    assert.equal(files.kindFromText('HIERARCHY\nROOT Hips'), 'bvh');
    assert.equal(files.kindFromText('#!OML:ASF x\n:FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0'), 'amc');
    assert.equal(files.kindFromText('# comment\n:version 1.10\n:name VICON\n:units\n'), 'asf');
    assert.equal(files.kindFromText('hello'), null);
    assert.equal(files.baseName('dir/16_11.amc.gz'), '16_11');
  });

  test('joint sides across naming schemes', () => {
    const left = ['LeftUpLeg', 'LHipJoint', 'lfemur', 'ltibia', 'lThigh', 'LThumb_end', 'hand_l', 'Foot.L', 'left_foot'];
    const right = ['RightFoot', 'RHipJoint', 'rhumerus', 'rShin', 'RThumb_end', 'hand_r', 'right_hand', 'rMid1', 'rIndex2_end'];
    const centre = ['Hips', 'root', 'lowerback', 'LowerBack', 'Spine1', 'head', 'Head_end', 'Neck1', 'thorax', 'rib'];
    for (const n of left) assert.equal(naming.sideOf(n), 'left', n);
    for (const n of right) assert.equal(naming.sideOf(n), 'right', n);
    for (const n of centre) assert.equal(naming.sideOf(n), null, n);
    assert.equal(naming.findHead(['root', 'upperneck', 'head']), 2);
    assert.equal(naming.findHead(['Hips', 'Head', 'Head_end']), 1);
  });
});
