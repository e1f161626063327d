// Parity of the frame count after a change of frame rate: web/motion/resample.ts resampledFrames (the clean-up) =
// training/mocap/resample.py resample_times (the dataset loader). tests/fixtures/resampled_frames.json
// (python -m training.fixtures.resampled_frames) holds (frames, fps_in, fps_out) and Python's count: clips of 1-5
// frames between every pair of 120, 60, 30, 29.97, 25 and 24 fps, lengths that land exactly on a frame or just short
// of one, and corpus clips as the loader resamples them. Counts are whole numbers: they must be equal.
import { describe, expect, it } from 'vitest';
import { resampledFrames } from '../../web/motion/resample';
import { readRepoFile } from './corpus';

interface Case {
  frames: number;
  fps_in: number;
  fps_out: number;
  count: number;
  source: string;
}
interface Fixture {
  slack: { python: number; page: number };
  closest_miss: number;
  cases: Case[];
}

const fixture = JSON.parse(readRepoFile('tests/fixtures/resampled_frames.json')) as Fixture;

describe('resampled frame count: web/motion/resample.ts = training/mocap/resample.py', () => {
  it('covers one-frame clips, 29.97 fps and the corpus', () => {
    expect(fixture.cases.length).toBeGreaterThan(200);
    expect(fixture.cases.some((c) => c.frames === 1)).toBe(true);
    expect(fixture.cases.some((c) => c.fps_in === 29.97 || c.fps_out === 29.97)).toBe(true);
    expect(fixture.cases.some((c) => c.source.startsWith('cmu/'))).toBe(true);
    // The two sides' slack before the floor differs (1e-6 in Python, 1e-9 here); no case may fall between them.
    expect(fixture.closest_miss).toBeGreaterThan(fixture.slack.python);
  });

  it('counts the same frames as Python in every case', () => {
    const differing = fixture.cases
      .filter((c) => resampledFrames(c.frames, c.fps_in, c.fps_out) !== c.count)
      .map((c) => `${c.frames} frames ${c.fps_in} → ${c.fps_out} fps (${c.source}): ${resampledFrames(c.frames, c.fps_in, c.fps_out)}, Python ${c.count}`);
    expect(differing).toEqual([]);
  });
});
