// tests/fixtures/footlock_reference.json (python -m training.fixtures.footlock, training/fixtures/footlock_reference.py):
// generator streams before and after the foot lock, their contact labels, labels + lock, and the low-foot measure.
// Read by footLock.test.ts and contactLabels.test.ts.
import { readRepoFile } from './corpus';

export interface FootStream {
  seed_name: string;
  temperature: number;
  frames: number;
  positions: number[];
  /** The model's contact bits. */
  contacts: number[];
  locked_legs: number[];
  labels: number[];
  label_margin: number;
  planted_legs: number[];
  low_foot: { mean: number | null; pairs: number };
}

export interface FootFixture {
  joints: string[];
  parents: number[];
  offsets: number[];
  fps: number;
  legs: string[];
  settings: { toe_ground_height: number; blend_in_frames: number; blend_out_frames: number; reach: number; pole_bias: number; flat_pitch: number; steep_pitch: number; release_lift: number };
  label_thresholds: Record<string, number>;
  near_floor: number;
  streams: FootStream[];
}

export const footFixture = JSON.parse(readRepoFile('tests/fixtures/footlock_reference.json')) as FootFixture;
