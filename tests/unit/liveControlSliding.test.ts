// Steer's foot sliding on a turn (issue 43): 1.2 m/s, a 90° heading change at 3 s, 8 s, through the worker's
// simulateControl (the live controller and the foot lock the page's Steer mode runs). Measured as the control
// report does: the lowest foot point's speed within 4 cm of the floor (lowFootSliding) on the returned motion.
// Most of the sliding was not on the turn but mid-swing: the swing foot's toe tip passing 2–3 cm over the floor
// at 3 m/s, which the foot lock (planted feet only) leaves as it is; the live objective's low-foot term
// (web/optimizer/objective.ts lowFootCost) now ranks particles that lift it higher. Before it, the seed states
// below slid 0.158 (walk 02_01) and 0.388 m/s (walk 16_19); with it 0.126 and 0.124.
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { parseGeneratorInfo } from '../../web/model/generatorInfo';
import { footSkating, lowFootSliding } from '../../web/motion/footSkating';
import { GeneratorCore } from '../../web/runtime/generator/generatorCore';
import { OptimizerRequests } from '../../web/runtime/generator/optimizerRequests';
import { readRepoFile } from './corpus';
import { ort, shippedSession } from './shippedModel';

const info = parseGeneratorInfo(JSON.parse(readRepoFile('public/models/generator.json')), 'public/models/generator.json');
const SCHEDULE = [{ t: 0, speed: 1.2, heading: 0 }, { t: 3, speed: 1.2, heading: Math.PI / 2 }];
let core: GeneratorCore;

beforeAll(async () => {
  core = new GeneratorCore(await shippedSession(info.file), info, ort.Tensor);
});
afterAll(() => core?.release());

describe('Steer on a 90° turn at 1.2 m/s', () => {
  for (const seed of [0, 3]) {
    it(`slides ≤ 0.15 m/s by the lowest foot point and still turns and keeps pace (seed ${seed}, ${['walk 02_01', '', '', 'walk 16_19'][seed]})`, async () => {
      const m = await new OptimizerRequests(core).simulate({ seconds: 8, schedule: SCHEDULE, seed }, () => {});
      expect(m.frames).toBe(240);
      const motion = { fps: info.fps, frames: m.frames, joints: info.skeleton.joints, parents: info.skeleton.parents, positions: m.positions, contacts: m.contacts };
      expect(lowFootSliding(motion)).toBeLessThanOrEqual(0.15);
      expect(footSkating(motion)).toBeLessThanOrEqual(0.15);
      // Within 15° of the new heading 1 s after the change, and at 1.2 ± 0.2 m/s 1 s after it.
      const within = Array.from(m.heading.subarray(90)).findIndex((h) => Math.abs(h - Math.PI / 2) <= (15 * Math.PI) / 180);
      expect(within).toBeGreaterThanOrEqual(0);
      expect(within / info.fps).toBeLessThanOrEqual(1);
      expect(Math.abs(m.speed[120] - 1.2)).toBeLessThanOrEqual(0.2);
    }, 120000);
  }
});
