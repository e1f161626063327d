// What scripts/evaluate-control.mjs (the generator with the MAP optimiser) and scripts/evaluate-latent-erd.mjs
// measure alike, so the two reports compare directly: the live-control scenarios and small helpers.

/** Control scenarios of docs/models/control.md: a change at t = 3 s from a steady start; each runs `seconds` (default SIM_SECONDS). */
export const SCENARIOS = {
  'turn 90°': { kind: 'heading', change: 90, schedule: [{ t: 0, speed: 1.2, heading: 0 }, { t: 3, speed: 1.2, heading: Math.PI / 2 }] },
  // Issue 43's schedule, run 8 s as it was reported (the others run SIM_SECONDS): the Steer sliding target is on it.
  'turn 90°, 8 s': { kind: 'heading', change: 90, seconds: 8, schedule: [{ t: 0, speed: 1.2, heading: 0 }, { t: 3, speed: 1.2, heading: Math.PI / 2 }] },
  'turn 180°': { kind: 'heading', change: 180, schedule: [{ t: 0, speed: 1.2, heading: 0 }, { t: 3, speed: 1.2, heading: Math.PI }] },
  'speed 0.8 → 1.5 m/s': { kind: 'speed', schedule: [{ t: 0, speed: 0.8, heading: 0 }, { t: 3, speed: 1.5, heading: 0 }] },
  'speed 1.5 → 0.8 m/s': { kind: 'speed', schedule: [{ t: 0, speed: 1.5, heading: 0 }, { t: 3, speed: 0.8, heading: 0 }] },
  'run 2.5 → 3.2 m/s': { kind: 'speed', gait: 'run', schedule: [{ t: 0, speed: 2.5, heading: 0 }, { t: 3, speed: 3.2, heading: 0 }] },
};
export const SIM_SECONDS = 6;

/** Angle wrapped to (−π, π]. */
export const wrap = (a) => {
  let d = a % (2 * Math.PI);
  if (d > Math.PI) d -= 2 * Math.PI;
  if (d <= -Math.PI) d += 2 * Math.PI;
  return d;
};
export const mean = (v) => v.reduce((a, b) => a + b, 0) / v.length;
export const percentile = (v, p) => {
  const s = [...v].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor((p / 100) * s.length))];
};

/** Mean root speed (m/s) over the whole motion. */
export function rootSpeed(m) {
  const J = m.joints.length;
  let d = 0;
  for (let f = 1; f < m.frames; f++) d += Math.hypot(m.positions[f * J * 3] - m.positions[(f - 1) * J * 3], m.positions[f * J * 3 + 2] - m.positions[(f - 1) * J * 3 + 2]);
  return (d * m.fps) / Math.max(1, m.frames - 1);
}

const DEG = Math.PI / 180;

/** Seconds after the change until the heading is within 15° of the new target (Infinity if never). */
export function headingResponse(sim, change) {
  const f0 = Math.round(change.t * sim.fps);
  for (let f = f0; f < sim.frames; f++) if (Math.abs(wrap(sim.heading[f] - change.heading)) <= 15 * DEG) return (f - f0) / sim.fps;
  return Infinity;
}

/**
 * One live-control result row, measured the same way for every model: the heading response (seconds, Infinity
 * if never; heading scenarios also say whether it was reached and their limit from `targets`), the speed 1 s
 * after the change and its error, the compute per frame (p95, max) and the skating of the run.
 */
export function controlRow(name, scenario, seed, sim, targets) {
  const change = scenario.schedule[1];
  const f1 = Math.min(sim.frames - 1, Math.round((change.t + 1) * sim.fps));
  const heading = scenario.kind === 'heading';
  const response = heading ? headingResponse(sim, change) : null;
  return {
    scenario: name, seed, kind: scenario.kind,
    headingResponse: response,
    ...(heading ? { reached: Number.isFinite(response), limit: scenario.change === 90 ? targets.heading90 : targets.heading180 } : {}),
    speedAt1s: sim.speed[f1],
    speedError: Math.abs(sim.speed[f1] - change.speed),
    p95ms: percentile(sim.computeMs, 95),
    maxMs: Math.max(...sim.computeMs),
    skating: sim.skating,
    sliding: sim.sliding,
  };
}
