// End-to-end tests of the optimiser through the public API in the page: playground.followPath and
// playground.simulateControl (the code the Path and Steer modes run), with their error handling.
import assert from 'node:assert/strict';
import { describe, test } from 'node:test';
import { apiFailure, usePlayground } from './harness.mjs';

const BEND = [[0, 0], [0, 2], [1.5, 3.5]];

/** In-page followPath, returned as plain data. */
function followPath(page, options) {
  return page.evaluate(async (o) => {
    const m = await window.playground.followPath(o);
    return { fps: m.fps, frames: m.frames, joints: m.joints, positions: Array.from(m.positions), contacts: Array.from(m.contacts), stats: m.stats };
  }, options);
}

/** [frame, side] of every foot whose lowest point (ankle, toe or toe tip) is within 4 cm of the floor and moved slower than 1 m/s since the previous frame. */
function restingFeet(m) {
  const J = m.joints.length, P = m.positions;
  const feet = [['LeftFoot', 'LeftToeBase', 'LeftToeBase_end'], ['RightFoot', 'RightToeBase', 'RightToeBase_end']].map((g) => g.map((n) => m.joints.indexOf(n)));
  const out = [];
  for (let f = 1; f < m.frames; f++) {
    feet.forEach((points, side) => {
      const low = points.reduce((a, j) => (P[(f * J + j) * 3 + 1] < P[(f * J + a) * 3 + 1] ? j : a));
      const a = ((f - 1) * J + low) * 3, b = (f * J + low) * 3;
      if (P[b + 1] < 0.04 && Math.hypot(P[b] - P[a], P[b + 2] - P[a + 2]) * m.fps < 1) out.push([f, side]);
    });
  }
  return out;
}

describe('path following and live control in the page', { timeout: 300_000 }, () => {
  const suite = usePlayground();

  test('followPath walks a bent path to its end, close to it, the same way for the same seed', async () => {
    const a = await followPath(suite.page, { points: BEND, gait: 'walk', seed: 4 });
    assert.equal(a.fps, 30);
    assert.ok(a.frames > 60, `a 3.6 m walk takes more than 2 s (got ${a.frames} frames)`);
    assert.equal(a.positions.length, a.frames * a.joints.length * 3);
    assert.equal(a.contacts.length, a.frames * 2);
    assert.ok(a.positions.every(Number.isFinite));
    assert.ok(a.stats.meanError < 0.1, `mean error ${a.stats.meanError}`);
    assert.ok(a.stats.maxError < 0.3, `max error ${a.stats.maxError}`);
    assert.ok(a.stats.arcProgress > 0.95, `arc progress ${a.stats.arcProgress}`);
    assert.ok(a.stats.optimizeMs > 0);
    // The root ends near the path's end, having started at its beginning.
    const last = (a.frames - 1) * a.joints.length * 3;
    assert.ok(Math.hypot(a.positions[0], a.positions[2]) < 0.1);
    assert.ok(Math.hypot(a.positions[last] - 1.5, a.positions[last + 2] - 3.5) < 0.35, `ends at ${a.positions[last]}, ${a.positions[last + 2]}`);
    const b = await followPath(suite.page, { points: BEND, gait: 'walk', seed: 4 });
    assert.deepEqual(b.positions, a.positions);
    const c = await followPath(suite.page, { points: BEND, gait: 'walk', seed: 5 });
    assert.notDeepEqual(c.positions, a.positions);
    // Feet are locked by default; the root (joint 0) is the same either way.
    const raw = await followPath(suite.page, { points: BEND, gait: 'walk', seed: 4, footLock: false });
    assert.ok(a.stats.skating < a.stats.skatingBeforeLock, `skating ${a.stats.skating} vs ${a.stats.skatingBeforeLock} before the lock`);
    assert.ok(Math.abs(raw.stats.skating - a.stats.skatingBeforeLock) < 1e-6);
    // The independent measure (lowest foot point near the floor, no contacts) falls too, and is the unlocked motion's before.
    assert.ok(a.stats.sliding < 0.6 * a.stats.slidingBeforeLock, `sliding ${a.stats.sliding} vs ${a.stats.slidingBeforeLock} before the lock`);
    assert.ok(Math.abs(raw.stats.sliding - a.stats.slidingBeforeLock) < 1e-6);
    // The returned contacts agree with the feet: every foot resting on the floor (lowest point within 4 cm, slower
    // than 1 m/s, in the unlocked motion) is labelled planted; the generator's own bits miss some.
    const missed = (contacts) => restingFeet(raw).filter(([f, side]) => !contacts[f * 2 + side]).length;
    assert.ok(missed(raw.contacts) > 0, 'the bits leave some resting feet free (the check is not vacuous)');
    assert.equal(missed(a.contacts), 0);
    assert.notDeepEqual(raw.positions, a.positions);
    for (let f = 0; f < a.frames; f += 10) {
      const i = f * a.joints.length * 3;
      assert.deepEqual(raw.positions.slice(i, i + 3), a.positions.slice(i, i + 3));
    }
  });

  test('followPath refuses bad input with a message and leaves the scene as it was', async () => {
    await suite.page.evaluate(async () => {
      const m = await window.playground.generate({ model: 'generator', frames: 40, seed: 1 });
      window.playground.show(m, 'before');
    });
    const short = await apiFailure(suite.page, 'followPath', { points: [[0, 0], [0, 0.2]] });
    assert.match(short.message, /^followPath: the path is 0\.20 m long; it must be at least 0\.5 m/);
    assert.equal(short.lastError, short.message);
    assert.equal(short.shown, 40);
    const bad = await apiFailure(suite.page, 'followPath', { points: [[0, 0], [1, null]] });
    assert.match(bad.message, /points\[1\] must be a pair of finite numbers/);
    const gait = await apiFailure(suite.page, 'followPath', { points: BEND, gait: 'crawl' });
    assert.match(gait.message, /gait must be "walk" or "run"/);
    const option = await apiFailure(suite.page, 'followPath', { points: BEND, speed: 2 });
    assert.match(option.message, /unknown option "speed"/);
    const lock = await apiFailure(suite.page, 'followPath', { points: BEND, footLock: 'yes' });
    assert.match(lock.message, /footLock must be true or false/);
  });

  test('a run shorter than a frame gives one frame that show and exportBVH take; a far path is refused with the limit', async () => {
    const r = await suite.page.evaluate(async () => {
      const pg = window.playground;
      const m = await pg.simulateControl({ seconds: 0.01, schedule: [{ t: 0, speed: 1.2, heading: 0 }] });
      pg.show(m, 'blink');
      return { frames: m.frames, shown: pg.state().frames, exported: /Frames: (\d+)/.exec(pg.exportBVH(m))?.[1] };
    });
    assert.deepEqual(r, { frames: 1, shown: 1, exported: '1' });
    const far = await apiFailure(suite.page, 'followPath', { points: [[1e15, 0], [1e15, 5]] });
    assert.match(far.message, /^followPath: points\[0\] \[1000000000000000, 0\] is too far out: x and z must be within ±10000 m/);
    assert.equal(far.shown, 1);
    const nan = await apiFailure(suite.page, 'followPath', { points: [[0, 0], [NaN, 5]] });
    assert.match(nan.message, /points\[1\] must be a pair of finite numbers \[x, z\], got \[NaN, 5\]$/);
  });

  test('simulateControl turns to a new heading and holds the speed; compute is reported per frame', async () => {
    const m = await suite.page.evaluate(async () => {
      const r = await window.playground.simulateControl({ seconds: 4, seed: 2, schedule: [{ t: 0, speed: 1.2, heading: 0 }, { t: 1, speed: 1.2, heading: Math.PI / 2 }] });
      return { frames: r.frames, speed: Array.from(r.speed), heading: Array.from(r.heading), computeMs: Array.from(r.computeMs), positions: Array.from(r.positions), joints: r.joints.length, contacts: r.contacts.length };
    });
    assert.equal(m.frames, 120);
    assert.equal(m.speed.length, 120);
    assert.equal(m.heading.length, 120);
    assert.equal(m.contacts, 240);
    assert.ok(m.positions.every(Number.isFinite));
    assert.ok(m.computeMs.every((v) => v > 0 && Number.isFinite(v)));
    assert.ok(Math.abs(m.heading[20]) < 0.3, `facing +z before the change (${m.heading[20]})`);
    const end = m.heading[119];
    assert.ok(Math.abs(end - Math.PI / 2) < 0.26, `facing +x at the end (${end})`);
    assert.ok(Math.abs(m.speed[119] - 1.2) < 0.35, `speed ${m.speed[119]}`);
    // It walked: the root moved about speed × time.
    const last = 119 * m.joints * 3;
    const travelled = Math.hypot(m.positions[last] - m.positions[0], m.positions[last + 2] - m.positions[2]);
    assert.ok(travelled > 2.5, `travelled ${travelled} m`);
  });

  test('simulateControl refuses bad schedules', async () => {
    const late = await apiFailure(suite.page, 'simulateControl', { seconds: 2, schedule: [{ t: 0.5, speed: 1, heading: 0 }] });
    assert.match(late.message, /^simulateControl: schedule\[0\]\.t must be 0/);
    const fast = await apiFailure(suite.page, 'simulateControl', { seconds: 2, schedule: [{ t: 0, speed: 12, heading: 0 }] });
    assert.match(fast.message, /speed must be a number from 0 to 4/);
    const long = await apiFailure(suite.page, 'simulateControl', { seconds: 6000, schedule: [{ t: 0, speed: 1, heading: 0 }] });
    assert.match(long.message, /seconds must be a number above 0 and at most 600/);
    assert.deepEqual(suite.problems, []);
  });
});
