// The five benchmark paths of the path-following report and tests (metres, x–z ground plane). Each
// starts at the origin heading +z; the follower starts the character at a path's first point facing
// along it.
import type { GroundPoint } from './path';

function arcPoints(cx: number, cz: number, radius: number, from: number, to: number, count: number, sign: 1 | -1): GroundPoint[] {
  // Angle φ measured so that φ = 0 is the point (cx − sign·r, cz): a circle through the origin for cx = sign·r.
  return Array.from({ length: count + 1 }, (_, i) => {
    const phi = from + ((to - from) * i) / count;
    return [cx - sign * radius * Math.cos(phi), cz + radius * Math.sin(phi)];
  });
}

export const BENCHMARK_PATHS: Record<string, GroundPoint[]> = {
  /** 10 m straight ahead. */
  straight: [
    [0, 0],
    [0, 10],
  ],
  /** A full circle of radius 2 m, turning right (toward +x). */
  circle: arcPoints(2, 0, 2, 0, 2 * Math.PI, 96, 1),
  /** One period of a sine, 1 m amplitude over 8 m. */
  's-curve': Array.from({ length: 81 }, (_, i): GroundPoint => [Math.sin((2 * Math.PI * i) / 80), (8 * i) / 80]),
  /** 5 m ahead, a sharp right-angle turn to the right, 5 m on. */
  corner: [
    [0, 0],
    [0, 5],
    [5, 5],
  ],
  /** Two circles of radius 1.5 m meeting at the origin: right loop, then left loop. */
  'figure-eight': [...arcPoints(1.5, 0, 1.5, 0, 2 * Math.PI, 72, 1), ...arcPoints(-1.5, 0, 1.5, 0, 2 * Math.PI, 72, -1).slice(1)],
};
