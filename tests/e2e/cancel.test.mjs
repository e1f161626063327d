// End-to-end tests of cancelling requests (docs/api.md "Cancelling requests"): an API call's `signal`
// (a generate issued behind a long simulateControl resolves once that is aborted; the aborted call
// rejects with an AbortError; an importMotion queued behind a large one and aborted is never parsed), and the modes' own cancels (leaving Path mode or drawing a new path
// cancels the walk being optimised; a new Random walk seed drops the stream start it replaces). The
// page's worker traffic is logged by an init script, so the tests wait on what the worker did, not on
// time. Run with `node --test tests/e2e/cancel.test.mjs`.
import assert from 'node:assert/strict';
import { before, describe, test } from 'node:test';
import { drawStroke, usePlayground, waitUntil } from './harness.mjs';

/**
 * Logs every model worker's traffic in `window.workerLog`: requests sent (`sent`: worker, id, type;
 * cancels as type "cancel" with the id they cancel), progress reports and replies (with the request's type).
 */
function logWorkers() {
  const log = (window.workerLog = { sent: [], progress: [], replies: [] });
  const NativeWorker = window.Worker;
  window.Worker = class extends NativeWorker {
    constructor(url, options) {
      super(url, options);
      const worker = options?.name ?? '';
      const types = new Map();
      this.addEventListener('message', ({ data }) => {
        if (!data || typeof data.id !== 'number') return;
        const entry = { worker, id: data.id, type: types.get(data.id) };
        if ('progress' in data) log.progress.push({ ...entry, progress: data.progress });
        else log.replies.push({ ...entry, ok: data.ok, name: data.name, error: data.error });
      });
      const post = this.postMessage.bind(this);
      this.postMessage = (message, transfer) => {
        if (message?.type === 'cancel') log.sent.push({ worker, id: message.request, type: 'cancel' });
        else {
          types.set(message.id, message.type);
          log.sent.push({ worker, id: message.id, type: message.type });
        }
        post(message, transfer);
      };
    }
  };
}

/** A zig-zag stroke over most of the view (fractions of the canvas): long enough to take a while to walk. */
const ZIGZAG = Array.from({ length: 121 }, (_, i) => {
  const leg = Math.floor(i / 20), t = (i % 20) / 20;
  return [leg % 2 ? 0.85 - 0.7 * t : 0.15 + 0.7 * t, 0.3 + 0.07 * leg + 0.07 * t];
});

const pathState = (page) => page.evaluate(() => ({ state: $ui('path-status').dataset.state, text: $ui('path-status').textContent }));

/** Waits until the generator worker has answered request `type` number `nth` (0-based) and returns the reply. */
function replyTo(page, type, nth, what) {
  return waitUntil(page, ([t, n]) => window.workerLog.replies.filter((r) => r.worker === 'generator' && r.type === t)[n], [type, nth], { timeout: 120_000, message: what });
}

/** Path mode with the zig-zag drawn, Go pressed and the optimiser under way (it has reported progress). */
async function optimiseZigzag(page) {
  await page.click('#mode-path');
  if (await page.locator('#path-clear').isEnabled()) await page.click('#path-clear');
  await drawStroke(page, ZIGZAG, 2);
  const drawn = await pathState(page);
  assert.equal(drawn.state, 'drawn', drawn.text);
  const before = await page.evaluate(() => window.workerLog.progress.length);
  await page.click('#path-go');
  await waitUntil(page, (n) => window.workerLog.progress.slice(n).some((p) => p.type === 'followPath'), before, { timeout: 120_000, message: 'the path follower reports progress' });
  assert.equal((await pathState(page)).state, 'optimising');
}

describe('cancelling requests', { timeout: 600_000 }, () => {
  const suite = usePlayground();
  before(async () => {
    await suite.page.addInitScript(logWorkers);
    await suite.page.reload({ waitUntil: 'load' });
    await suite.page.waitForFunction(() => window.playground !== undefined && window.workerLog !== undefined, null, { timeout: 20_000 });
    await suite.page.evaluate(() => window.playground.ready);
  });

  test('a generate issued while a long simulateControl runs resolves once that is aborted; the aborted call rejects with an AbortError', async () => {
    const page = suite.page;
    const reference = await page.evaluate(async () => Array.from((await window.playground.generate({ model: 'generator', frames: 10, seed: 3 })).positions));
    const errorBefore = await page.evaluate(() => window.playground.lastError());
    await page.evaluate(() => {
      window.simulation = new AbortController();
      window.simulated = window.playground
        .simulateControl({ seconds: 600, schedule: [{ t: 0, speed: 1.2, heading: 0 }], seed: 1, signal: window.simulation.signal })
        .then(() => 'resolved', (e) => ({ name: e.name, message: e.message }));
    });
    // Ten minutes of motion to optimise: it is running in the worker once it reports progress.
    await waitUntil(page, () => window.workerLog.progress.some((p) => p.type === 'simulateControl'), null, { timeout: 120_000, message: 'the simulation runs in the worker' });

    await page.evaluate(() => {
      window.generated = null;
      window.playground.generate({ model: 'generator', frames: 10, seed: 3 }).then((m) => (window.generated = { frames: m.frames, positions: Array.from(m.positions) }));
      window.simulation.abort();
    });
    // Without the cancel it would wait for ten minutes of motion to be optimised.
    const generated = await waitUntil(page, () => window.generated, null, { timeout: 120_000, message: 'the generate behind the aborted simulation resolves' });
    assert.equal(generated.frames, 10);
    assert.deepEqual(generated.positions, reference, 'the generator is unchanged by the cancelled simulation');
    assert.deepEqual(await page.evaluate(() => window.simulated), { name: 'AbortError', message: 'simulateControl: cancelled' });
    const simulationReply = await replyTo(page, 'simulateControl', 0, 'the worker answers the simulation');
    assert.deepEqual([simulationReply.ok, simulationReply.name], [false, 'AbortError'], 'the worker stopped the simulation part-way');
    assert.equal(await page.evaluate(() => window.playground.lastError()), errorBefore, 'a cancel is not an error shown on the page');

    // The worker goes on normally.
    const short = await page.evaluate(async () => (await window.playground.simulateControl({ seconds: 0.4, schedule: [{ t: 0, speed: 1.2, heading: 0 }] })).frames);
    assert.equal(short, 12);
  });

  test('an importMotion queued behind a large one and aborted rejects with an AbortError and is never parsed; the next import works', async () => {
    const page = suite.page;
    const errorBefore = await page.evaluate(() => window.playground.lastError());
    const r = await page.evaluate(async () => {
      const bvh = (frames) =>
        ['HIERARCHY', 'ROOT Hips', '{', 'OFFSET 0 0 0', 'CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation', 'End Site', '{', 'OFFSET 0 10 0', '}', '}', 'MOTION', `Frames: ${frames}`, 'Frame Time: 0.0333333', ...Array(frames).fill('0 90 0 0 0 0')].join('\n');
      const outcome = (p) => p.then((m) => ({ frames: m.frames }), (e) => ({ name: e.name, message: e.message }));
      const sent = window.workerLog.sent.length;
      const large = outcome(window.playground.importMotion(bvh(400_000), 'bvh'));
      const cancel = new AbortController();
      const queued = outcome(window.playground.importMotion(bvh(2), 'bvh', undefined, { signal: cancel.signal }));
      cancel.abort();
      const queuedOutcome = await queued;
      const next = await outcome(window.playground.importMotion(bvh(3), 'bvh'));
      const imports = window.workerLog.sent.slice(sent).filter((s) => s.worker === 'import');
      const queuedReply = window.workerLog.replies.find((reply) => reply.worker === 'import' && reply.id === imports[1].id);
      return { large: await large, queued: queuedOutcome, next, imports: imports.map((s) => s.type), queuedReply };
    });
    assert.deepEqual(r.queued, { name: 'AbortError', message: 'importMotion: cancelled' });
    assert.deepEqual(r.large, { frames: 400_000 });
    assert.deepEqual(r.next, { frames: 3 });
    assert.deepEqual(r.imports, ['text', 'text', 'cancel', 'text']);
    assert.deepEqual([r.queuedReply.ok, r.queuedReply.error], [false, { name: 'AbortError', message: 'cancelled' }], 'the worker dropped the queued import without parsing it');
    assert.equal(await page.evaluate(() => window.playground.lastError()), errorBefore, 'a cancel is not an error shown on the page');
  });

  test('a signal that has already aborted rejects at once without reaching the worker; a signal that is not one is refused', async () => {
    const page = suite.page;
    const r = await page.evaluate(async () => {
      const sent = window.workerLog.sent.length;
      const outcome = (p) => p.then(() => 'resolved', (e) => ({ name: e.name, message: e.message }));
      const followed = await outcome(window.playground.followPath({ points: [[0, 0], [0, 3]], signal: AbortSignal.abort() }));
      const generated = await outcome(window.playground.generate({ model: 'aclstm', style: 'salsa', frames: 5, seed: 0, signal: AbortSignal.abort() }));
      const imported = await outcome(window.playground.importMotion('HIERARCHY', 'bvh', undefined, { signal: AbortSignal.abort() }));
      const badImport = await outcome(window.playground.importMotion('HIERARCHY', 'bvh', undefined, { signal: 'stop' }));
      const bad = await outcome(window.playground.generate({ model: 'generator', frames: 5, seed: 0, signal: 'stop' }));
      return { followed, generated, imported, badImport, bad, sent: window.workerLog.sent.length - sent, lastError: window.playground.lastError() };
    });
    assert.deepEqual(r.followed, { name: 'AbortError', message: 'followPath: cancelled' });
    assert.deepEqual(r.generated, { name: 'AbortError', message: 'generate: cancelled' });
    assert.deepEqual(r.imported, { name: 'AbortError', message: 'importMotion: cancelled' });
    assert.deepEqual(r.badImport, { name: 'TypeError', message: 'importMotion: signal must be an AbortSignal (an AbortController\'s signal), got "stop"' });
    assert.equal(r.bad.name, 'TypeError');
    assert.match(r.bad.message, /^generate: signal must be an AbortSignal \(an AbortController's signal\), got "stop"$/);
    assert.equal(r.lastError, r.bad.message, 'the refused signal is reported like any bad option');
    assert.equal(r.sent, 0, 'nothing was sent to a worker');
  });

  test('Path mode: switching mode cancels the walk being optimised; drawing a new path cancels it too', async () => {
    const page = suite.page;
    const errorBefore = await page.evaluate(() => window.playground.lastError());
    const followed = () => page.evaluate(() => window.workerLog.replies.filter((r) => r.type === 'followPath').length);

    await optimiseZigzag(page);
    const n = await followed();
    await page.click('#mode-clip');
    const left = await replyTo(page, 'followPath', n, 'the worker answers the path follower');
    assert.deepEqual([left.ok, left.name], [false, 'AbortError'], 'leaving Path mode cancelled the optimisation in the worker');
    await page.click('#mode-path');
    const back = await pathState(page);
    assert.equal(back.state, 'drawn', `the path is kept, not walked (${back.text})`);
    assert.equal(await page.locator('#path-go').isEnabled(), true, 'Go walks it again');

    await optimiseZigzag(page);
    await drawStroke(page, [[0.3, 0.5], [0.5, 0.5], [0.7, 0.55]], 2);
    const redrawn = await replyTo(page, 'followPath', n + 1, 'the worker answers the path follower');
    assert.deepEqual([redrawn.ok, redrawn.name], [false, 'AbortError'], 'a new path cancelled the optimisation of the old one');
    const state = await pathState(page);
    assert.equal(state.state, 'drawn', `the new path waits for Go (${state.text})`);
    assert.equal(await page.evaluate(() => window.playground.lastError()), errorBefore, 'a cancel is not an error shown on the page');
    await page.click('#mode-clip');
  });

  test('Random walk: a new seed drops the stream start it replaces from the worker queue', async () => {
    const page = suite.page;
    await page.click('#mode-clip');
    const starts = () => page.evaluate(() => window.workerLog.sent.filter((s) => s.worker === 'generator' && s.type === 'startStream').map((s) => s.id));
    const before = (await starts()).length;
    const progressBefore = await page.evaluate(() => window.workerLog.progress.length);
    // The worker is busy with a long simulation, so the walk's stream start waits in its queue.
    await page.evaluate(() => {
      window.simulation = new AbortController();
      window.simulated = window.playground.simulateControl({ seconds: 600, schedule: [{ t: 0, speed: 1.2, heading: 0 }], signal: window.simulation.signal }).catch((e) => e.name);
    });
    const simulation = await waitUntil(page, (n) => window.workerLog.progress.slice(n).find((p) => p.type === 'simulateControl')?.id, progressBefore, { timeout: 120_000, message: 'the simulation runs' });
    await page.click('#mode-walk');
    await waitUntil(page, (n) => window.workerLog.sent.filter((s) => s.worker === 'generator' && s.type === 'startStream').length > n, before, { message: 'the walk asks for a stream' });
    await page.locator('#walk-seed').fill('7');
    await page.locator('#walk-seed').dispatchEvent('change');
    await waitUntil(page, (n) => window.workerLog.sent.filter((s) => s.worker === 'generator' && s.type === 'startStream').length > n + 1, before, { message: 'the new seed asks for a new stream' });
    const [first, second] = (await starts()).slice(before);
    const dropped = await waitUntil(page, (id) => window.workerLog.replies.find((r) => r.worker === 'generator' && r.id === id), first, { message: 'the worker answers the replaced start' });
    assert.deepEqual([dropped.ok, dropped.name], [false, 'AbortError'], 'the replaced start was dropped');

    await page.evaluate(() => window.simulation.abort());
    assert.equal(await page.evaluate(() => window.simulated), 'AbortError');
    const started = await waitUntil(page, (id) => window.workerLog.replies.find((r) => r.worker === 'generator' && r.id === id), second, { timeout: 120_000, message: 'the new stream starts' });
    assert.equal(started.ok, true);
    const order = await page.evaluate((ids) => ids.map((id) => window.workerLog.replies.findIndex((r) => r.worker === 'generator' && r.id === id)), [first, simulation, second]);
    assert.ok(order[0] < order[1] && order[1] < order[2], `the replaced start was answered from the queue, before the simulation it waited behind ended (${order})`);
    await waitUntil(page, () => Number($ui('walk-status').dataset.frame) > 0, null, { timeout: 120_000, message: 'the walk plays' });
    await page.click('#mode-clip');
  });
});
