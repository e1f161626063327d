// Issue 43 #8: arrays with holes (`[-1, , 1]`, `new Array(3)`) are refused by every check of user arrays with a
// message naming the index, instead of passing (forEach, every and map skip holes) and failing later inside.
import { describe, expect, it } from 'vitest';
import { exportBVH } from '../../web/motion/bvh';
import { validateMotion } from '../../web/motion/validate';
import { checkPathPoints } from '../../web/optimizer/path';
import { checkSchedule } from '../../web/optimizer/liveControl';
import { checkControlSignal } from '../../web/model/latentErdInfo';

/* eslint-disable no-sparse-arrays */
function motion(over: Record<string, unknown> = {}) {
  return { fps: 30, frames: 1, joints: ['a', 'b', 'c'], parents: [-1, 0, 1], positions: [0, 0, 0, 0, 1, 0, 0, 2, 0], ...over };
}

function message(fn: () => unknown): string {
  try {
    fn();
  } catch (e) {
    return (e as Error).message;
  }
  return 'no error';
}

describe('arrays with holes are refused, naming the index', () => {
  it('a motion: parents, joints, positions, contacts', () => {
    expect(message(() => validateMotion(motion({ parents: [-1, , 1] })))).toBe('Invalid motion: parents[1] is missing (the array has a hole there)');
    expect(message(() => validateMotion(motion({ joints: ['a', , 'c'] })))).toMatch(/^Invalid motion: joints\[1\] is missing/);
    const positions = [0, 0, 0, 0, 1, 0, 0, 2, 0];
    delete positions[4];
    expect(message(() => validateMotion(motion({ positions })))).toMatch(/^Invalid motion: positions\[4\] is missing/);
    expect(message(() => validateMotion(motion({ contacts: [1, ,] })))).toMatch(/contacts\[1\] is missing/);
    // Before: accepted, and the export failed inside ("Cannot read properties of undefined").
    expect(() => exportBVH(motion({ parents: [-1, , 1] }) as never)).toThrow(/parents\[1\] is missing/);
    expect(() => validateMotion(motion())).not.toThrow();
  });

  it('followPath points and each pair', () => {
    expect(message(() => checkPathPoints([[0, 0], , [0, 3]]))).toBe('points[1] is missing (the array has a hole there)');
    expect(message(() => checkPathPoints([[0, 0], [0, , ]]))).toMatch(/^points\[1\]\[1\] is missing|^points\[1\] must be a pair/);
    expect(message(() => checkPathPoints([[0, 0], new Array(2)]))).toMatch(/^points\[1\]\[0\] is missing/);
    expect(checkPathPoints([[0, 0], [0, 3]])).toEqual([[0, 0], [0, 3]]);
  });

  it('the latent ERD control signal: a step and the list of steps', () => {
    expect(message(() => checkControlSignal([[1, , 0]], 1))).toBe('control[0][1] is missing (the array has a hole there)');
    expect(message(() => checkControlSignal([[1, 0, 0], , [1, 0, 0]], 3))).toBe('control[1] is missing (the array has a hole there)');
    expect(Array.from(checkControlSignal([[1, 0, 0]], 1))).toEqual([1, 0, 0]);
  });

  it("simulateControl's schedule", () => {
    expect(message(() => checkSchedule([{ t: 0, speed: 1, heading: 0 }, , { t: 2, speed: 1, heading: 0 }]))).toBe('schedule[1] is missing (the array has a hole there)');
    expect(checkSchedule([{ t: 0, speed: 1, heading: 0 }])).toHaveLength(1);
  });

  it('messages stay short whatever the array', () => {
    const huge = new Array(1_000_000);
    huge[0] = [0, 0];
    expect(message(() => checkControlSignal(new Array(5), 5)).length).toBeLessThan(300);
    expect(message(() => checkPathPoints(huge.slice(0, 3))).length).toBeLessThan(300);
  });
});
