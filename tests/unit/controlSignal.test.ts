// The latent ERD's control signal: web/motion/control.ts against training/control.py on
// tests/fixtures/control_signal.json (python -m training.fixtures.control_signal; the cases are in
// training/fixtures/control_signal_parity.py). Single calls must agree within 1e-9; the closed-loop path runs
// are rerun here frame by frame from the same start (control.ts's own follower and step) and must stay within
// 1e-6 of Python's over the whole run. Then behaviour the signal must have, whatever Python says.
import { describe, expect, it } from 'vitest';
import * as control from '../../web/motion/control';
import {
  ARRIVED,
  controlAlongPath,
  controlFromTrajectory,
  controlTowardHeading,
  integrateControl,
  MAX_TURN_RATE,
  PolylinePath,
  randomControl,
  RANDOM_SEGMENT,
  rotateToLocal,
  stepRoot,
  wrap,
  type Root,
} from '../../web/motion/control';
import { pathCoverage } from '../../web/motion/pathCoverage';
import { Rng } from '../../web/motion/random';
import { readRepoFile } from './corpus';

interface PathCase {
  name: string;
  points: [number, number][];
  arc: number[];
  length: number;
  point_at: [number, [number, number]][];
  project: [[number, number], number, number, number][];
  start: [number, number, number];
  speed: number;
  frames: number;
  /** x, z, heading of each frame before its signal. */
  states: number[];
  control: number[];
  progress: number[];
}
interface Fixture {
  fps: number;
  constants: Record<string, number | number[]>;
  wrap: { angles: number[]; wrapped: number[] };
  from_trajectory: { xz: number[]; heading: number[]; control: number[] };
  integrate: { control: number[]; start: [number, number, number]; xz: number[]; heading: number[] };
  toward_heading: { heading: number; target: number; speed: number; control: number[] }[];
  paths: PathCase[];
  random: { seed: number; frames: number; fps: number; control: number[] }[];
}

const fixture = JSON.parse(readRepoFile('tests/fixtures/control_signal.json')) as Fixture;
const BENCHMARK = JSON.parse(readRepoFile('tests/fixtures/benchmark_paths.json')) as { paths: Record<string, { points: number[][] }> };
const FPS = fixture.fps;

/** The largest |a − b| (angles: wrapped, so −π + ε and π − ε are 2ε apart); throws on different lengths. */
function maxDiff(a: ArrayLike<number>, b: ArrayLike<number>, angle = false): number {
  if (a.length !== b.length) throw new Error(`lengths differ: ${a.length} and ${b.length}`);
  let worst = 0;
  for (let i = 0; i < a.length; i++) {
    const d = angle ? Math.abs(wrap(a[i] - b[i])) : Math.abs(a[i] - b[i]);
    worst = Math.max(worst, Number.isNaN(d) ? Infinity : d);
  }
  return worst;
}
const every = (values: ArrayLike<number>, stride: number, offset: number) => Array.from(values).filter((_, i) => i % stride === offset);

/** The closed loop as the fixture runs it: the follower's signal from the walker's state, then one step. */
function follow(path: PolylinePath, start: Root, speed: number, frames: number) {
  const states: number[] = [], signals: number[] = [], progress: number[] = [];
  let root = start, p = 0;
  for (let t = 0; t < frames; t++) {
    states.push(root.x, root.z, root.heading);
    const out = controlAlongPath(path, root.x, root.z, root.heading, p, speed);
    p = out.progress;
    signals.push(...out.control);
    progress.push(p);
    root = stepRoot(root, out.control, FPS);
  }
  return { states, signals, progress, end: root };
}

describe('the control signal matches training/control.py', () => {
  it('has the same constants', () => {
    const ported = control as unknown as Record<string, number | readonly number[]>;
    for (const [name, value] of Object.entries(fixture.constants)) expect(ported[name], name).toEqual(value);
  });

  it('wraps angles to [−π, π) as Python\'s float modulo does', () => {
    const got = fixture.wrap.angles.map(wrap);
    expect(maxDiff(got, fixture.wrap.wrapped)).toBeLessThanOrEqual(1e-9);
    for (const a of got) expect(a >= -Math.PI && a < Math.PI, `${a}`).toBe(true);
    expect(wrap(Math.PI)).toBe(-Math.PI); // not π: the interval is half-open as in Python
    expect(wrap(-7)).toBeCloseTo(-7 + 2 * Math.PI, 12); // ((−7 + π) % 2π) − π with JavaScript's % alone is −7 again
  });

  it('controlFromTrajectory: a curving trajectory whose heading wraps across ±π', () => {
    const { xz, heading, control: expected } = fixture.from_trajectory;
    expect(heading.some((h, t) => t > 0 && Math.abs(h - heading[t - 1]) > Math.PI)).toBe(true); // it does wrap
    const got = controlFromTrajectory(xz, heading, FPS);
    expect(got.length).toBe(heading.length * 3);
    expect(maxDiff(got, expected)).toBeLessThanOrEqual(1e-9);
    expect(Math.max(...every(got, 3, 1).map(Math.abs))).toBeGreaterThan(0.05); // a sideways part too
  });

  it('integrateControl: a signal with wrapping turns from a non-zero start', () => {
    const { control: signal, start, xz, heading } = fixture.integrate;
    const got = integrateControl(signal, FPS, { x: start[0], z: start[1], heading: start[2] });
    expect(maxDiff(got.xz, xz)).toBeLessThanOrEqual(1e-9);
    expect(maxDiff(got.heading, heading, true)).toBeLessThanOrEqual(1e-9);
    expect(got.xz[0]).toBe(start[0]); // frame 0 is the start
    expect(got.heading[0]).toBe(start[2]);
  });

  it('controlTowardHeading: wrap-around, clamped and exactly opposite targets', () => {
    for (const c of fixture.toward_heading) {
      expect(maxDiff(controlTowardHeading(c.heading, c.target, c.speed), c.control), `${c.heading} → ${c.target}`).toBeLessThanOrEqual(1e-9);
    }
  });

  for (const c of fixture.paths) {
    it(`PolylinePath: ${c.name}: arc lengths, pointAt and project`, () => {
      const path = new PolylinePath(c.points);
      expect(maxDiff(path.arc, c.arc)).toBeLessThanOrEqual(1e-9);
      expect(Math.abs(path.length - c.length)).toBeLessThanOrEqual(1e-9);
      for (const [s, p] of c.point_at) expect(maxDiff(path.pointAt(s), p), `pointAt(${s})`).toBeLessThanOrEqual(1e-9);
      for (const [[x, z], from, to, s] of c.project) expect(Math.abs(path.project(x, z, from, to) - s), `project(${x}, ${z}, ${from}, ${to})`).toBeLessThanOrEqual(1e-9);
    });

    it(`controlAlongPath closed loop, ${c.frames} frames: ${c.name}`, () => {
      const path = new PolylinePath(c.points);
      const [x, z, heading] = c.start;
      const run = follow(path, { x, z, heading }, c.speed, c.frames);
      expect(maxDiff(every(run.states, 3, 0), every(c.states, 3, 0))).toBeLessThanOrEqual(1e-6);
      expect(maxDiff(every(run.states, 3, 1), every(c.states, 3, 1))).toBeLessThanOrEqual(1e-6);
      expect(maxDiff(every(run.states, 3, 2), every(c.states, 3, 2), true)).toBeLessThanOrEqual(1e-6);
      expect(maxDiff(run.signals, c.control)).toBeLessThanOrEqual(1e-6);
      expect(maxDiff(run.progress, c.progress)).toBeLessThanOrEqual(1e-6);
    });
  }

  it('the loop run passes its crossing on the second branch, not short-cut back to the first', () => {
    const c = fixture.paths.find((p) => p.name.startsWith('loop'))!;
    const path = new PolylinePath(c.points);
    const run = follow(path, { x: c.start[0], z: c.start[1], heading: c.start[2] }, c.speed, c.frames);
    // Progress only grows by about a frame's travel, never jumps back by metres.
    for (let t = 1; t < run.progress.length; t++) expect(run.progress[t] - run.progress[t - 1]).toBeGreaterThan(-0.05);
    expect(run.progress[run.progress.length - 1]).toBeGreaterThan(8.5); // past the crossing at arc 8.5
  });

  it('the ending run reaches the end of its path and stops there: a zero signal within ARRIVED of the end', () => {
    const c = fixture.paths.find((p) => p.name.includes('stops'))!;
    const path = new PolylinePath(c.points);
    const run = follow(path, { x: c.start[0], z: c.start[1], heading: c.start[2] }, c.speed, c.frames);
    const stopped = run.progress.findIndex((p) => path.length - p <= ARRIVED);
    expect(stopped).toBeGreaterThan(0);
    expect(stopped).toBeLessThan(c.frames - 10);
    expect(run.signals.slice(3 * stopped).every((v) => v === 0)).toBe(true);
    expect(c.control.slice(3 * stopped).every((v) => v === 0)).toBe(true); // and so did Python's
  });

  for (const c of fixture.random) {
    it(`randomControl(seed ${c.seed}, ${c.frames} frames, ${c.fps} fps)`, () => {
      const got = randomControl(c.seed, c.frames, c.fps);
      expect(maxDiff(got, c.control)).toBeLessThanOrEqual(1e-9);
      expect(every(got, 3, 1).every((v) => v === 0)).toBe(true);
    });
  }

  it('randomControl: different seeds differ, and 30.25 fps takes segments of 60 frames (round half to even)', () => {
    const [a, b] = fixture.random;
    expect(maxDiff(a.control, b.control)).toBeGreaterThan(0.1);
    // A new target at frame 60 and not at 61: the turn's slope changes most from frame 59 to 60.
    const turn = every(randomControl(3, 130, 30.25), 3, 2);
    const kink = (t: number) => Math.abs(turn[t + 1] - 2 * turn[t] + turn[t - 1]);
    expect(kink(59)).toBeGreaterThan(5 * kink(58));
    expect(kink(59)).toBeGreaterThan(5 * kink(60));
    expect(Math.round(RANDOM_SEGMENT * 30.25)).toBe(61); // what Math.round alone would have used
  });
});

describe('control signal behaviour', () => {
  it('stepRoot: forward goes along the heading, sideways to the walker\'s left (+x at heading 0), turns from +z to +x', () => {
    const f = stepRoot({ x: 0, z: 0, heading: Math.PI / 2 }, [3, 0, 0], 3);
    expect(f.x).toBeCloseTo(1, 12);
    expect(f.z).toBeCloseTo(0, 12);
    const s = stepRoot({ x: 0, z: 0, heading: 0 }, [0, 3, 0], 3);
    expect([s.x, s.z]).toEqual([1, 0]);
    expect(stepRoot({ x: 0, z: 0, heading: 0 }, [0, 0, 1], 2).heading).toBe(0.5);
    expect(rotateToLocal(1, 0, 0)).toEqual([1, 0]); // +x is sideways (left) at heading 0
  });

  it('a walker driven by controlAlongPath along a straight 10 m path ends within 0.3 m of the end and stops', () => {
    const path = new PolylinePath([[0, 0], [0, 10]]);
    for (const start of [{ x: 0, z: 0, heading: 0 }, { x: 0.4, z: -0.3, heading: 1.2 }]) {
      const run = follow(path, start, 1.5, 450);
      expect(Math.hypot(run.end.x, run.end.z - 10), JSON.stringify(start)).toBeLessThan(0.3);
      const last = run.states.length - 3;
      const earlier = last - 3 * 30;
      expect(Math.hypot(run.states[last] - run.states[earlier], run.states[last + 1] - run.states[earlier + 1])).toBeLessThan(0.01); // still over its last second
      expect(Math.abs(run.signals[run.signals.length - 3])).toBeLessThan(0.01);
      // Midway (5 s in) it walks at the asked speed, back on the line.
      expect(run.signals[3 * 150]).toBe(1.5);
      expect(Math.abs(run.states[3 * 150])).toBeLessThan(0.05);
    }
  });

  it('a walker driven by controlAlongPath follows a path that doubles back (issue 43) ≥ 95% of its length within 0.15 m, walking or running', () => {
    // The benchmark's back-and-forth scribble: pure pursuit cut each reversal whole (its look-ahead point jumped to
    // the next leg) and the projection jumped to the leg lying under the one walked, 30% followed. Now the walker
    // goes to each tip, slowing, turns on the spot and speeds up again along the next leg.
    const points = BENCHMARK.paths['back-and-forth'].points as [number, number][];
    // And as drawn: a point every 5 cm, each up to 5 mm off (seeded), so the legs that lie on each other do not quite.
    const rng = new Rng(43);
    const drawn: [number, number][] = [];
    for (let i = 0; i + 1 < points.length; i++) {
      const [a, b] = [points[i], points[i + 1]];
      const n = Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / 0.05);
      for (let k = 0; k < n; k++) drawn.push([a[0] + ((b[0] - a[0]) * k) / n + 0.01 * (rng.uniform() - 0.5), a[1] + ((b[1] - a[1]) * k) / n + 0.01 * (rng.uniform() - 0.5)]);
    }
    drawn.push(points[points.length - 1]);
    for (const [path, speed] of [0.6, 1.2, 2.0, 2.8].flatMap((v) => [[new PolylinePath(points), v], [new PolylinePath(drawn), v]] as const)) {
      const run = follow(path, { x: 0, z: 0, heading: 0 }, speed, Math.ceil(((path.length / speed) * 2.5 + 10) * FPS));
      const track: [number, number][] = [];
      for (let t = 0; t < run.states.length; t += 3) track.push([run.states[t], run.states[t + 1]]);
      const label = `${speed} m/s, ${path.points.length} points`;
      expect(pathCoverage(points, track), label).toBeGreaterThanOrEqual(0.95);
      expect(Math.hypot(run.end.x - points[points.length - 1][0], run.end.z - points[points.length - 1][1]), label).toBeLessThan(0.1);
      // It turns on the spot rather than walking a loop: never more than 0.15 m off the path.
      const off = Math.max(...track.map(([x, z]) => {
        const [px, pz] = path.pointAt(path.project(x, z, 0, path.length));
        return Math.hypot(px - x, pz - z);
      }));
      expect(off, label).toBeLessThan(0.15);
    }
  });

  it('controlTowardHeading turns the right way, the short way round, at most MAX_TURN_RATE', () => {
    expect(controlTowardHeading(0, Math.PI / 4, 1)[2]).toBeGreaterThan(0); // towards +x
    expect(controlTowardHeading(0, -Math.PI / 4, 1)[2]).toBeLessThan(0);
    expect(controlTowardHeading(3, -3, 1)[2]).toBeGreaterThan(0); // across ±π, not the long way
    expect(controlTowardHeading(-3, 3, 1)[2]).toBeLessThan(0);
    expect(controlTowardHeading(0, 3, 1)[2]).toBe(MAX_TURN_RATE);
    expect(controlTowardHeading(1, 1, 0.7)).toEqual([0.7, 0, 0]);
    // Held, it brings the walker round to the target heading and walks off that way.
    let root: Root = { x: 0, z: 0, heading: 2.8 };
    for (let t = 0; t < 120; t++) root = stepRoot(root, controlTowardHeading(root.heading, -2.6, 1), FPS);
    expect(Math.abs(wrap(root.heading + 2.6))).toBeLessThan(1e-3);
    const next = stepRoot(root, controlTowardHeading(root.heading, -2.6, 1), FPS);
    expect(Math.atan2(next.x - root.x, next.z - root.z)).toBeCloseTo(-2.6, 3);
  });

  it('integrateControl inverts controlFromTrajectory', () => {
    const { xz, heading } = fixture.from_trajectory;
    const signal = controlFromTrajectory(xz, heading, FPS);
    const back = integrateControl(signal, FPS, { x: xz[0], z: xz[1], heading: heading[0] });
    expect(maxDiff(back.xz, xz)).toBeLessThan(1e-9);
    expect(maxDiff(back.heading, heading, true)).toBeLessThan(1e-9);
    // And the other way round, on a random signal (its last frame is not used by integrateControl).
    const random = randomControl(5, 200, FPS);
    const path = integrateControl(random, FPS, { x: 2, z: -1, heading: 3 });
    const again = controlFromTrajectory(path.xz, path.heading, FPS);
    expect(maxDiff(again.subarray(0, 3 * 199), random.subarray(0, 3 * 199))).toBeLessThan(1e-9);
  });

  it('handles the short cases: one frame gives zeros, a path needs two points', () => {
    expect(Array.from(controlFromTrajectory([1, 2], [0.5], FPS))).toEqual([0, 0, 0]);
    expect(controlFromTrajectory([], [], FPS).length).toBe(0);
    expect(() => new PolylinePath([[0, 0]])).toThrow(/at least 2 points/);
  });
});
