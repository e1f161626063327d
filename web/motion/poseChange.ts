// Per-second pose change (Zhou et al., Fig. 2): the mean speed of the joints relative to the root, in
// m/s, averaged over each whole second. A frozen dance drops towards 0. Same definition as
// training/metrics.py `pose_change_per_second`: per frame transition t → t+1,
//   speed(t) = mean over all joints (the root included, at 0) of |(p_j − p_root)(t+1) − (p_j − p_root)(t)| · fps,
// and second k is the mean of speed(k·n … k·n + n − 1) with n = round(fps); a partial second is not reported.

/** Streams frames in and reports each second as it completes. */
export class PoseChangeMeter {
  private readonly step: number;
  private previous: Float64Array | null = null;
  private sum = 0;
  private count = 0;

  constructor(private readonly joints: number, private readonly fps: number) {
    if (!Number.isInteger(joints) || joints < 1) throw new Error(`PoseChangeMeter: joints must be a positive integer, got ${joints}`);
    if (!(fps > 0)) throw new Error(`PoseChangeMeter: fps must be positive, got ${fps}`);
    this.step = Math.max(1, Math.round(fps));
  }

  /** Forgets everything: the next frame starts a new motion. */
  reset(): void {
    this.previous = null;
    this.sum = 0;
    this.count = 0;
  }

  /** Adds `positions` (frames × joints × 3, continuing the previous call's motion); returns the seconds completed by them. */
  push(positions: ArrayLike<number>): number[] {
    const J = this.joints;
    if (positions.length % (J * 3) !== 0) throw new Error(`PoseChangeMeter: ${positions.length} values is not a whole number of ${J}-joint frames`);
    const frames = positions.length / (J * 3);
    const done: number[] = [];
    const local = new Float64Array(J * 3);
    for (let f = 0; f < frames; f++) {
      const b = f * J * 3;
      for (let k = 0; k < J * 3; k++) local[k] = positions[b + k] - positions[b + (k % 3)];
      const prev = this.previous;
      if (prev) {
        let total = 0;
        for (let j = 0; j < J; j++) {
          total += Math.hypot(local[j * 3] - prev[j * 3], local[j * 3 + 1] - prev[j * 3 + 1], local[j * 3 + 2] - prev[j * 3 + 2]);
        }
        this.sum += (total / J) * this.fps;
        if (++this.count === this.step) {
          done.push(this.sum / this.step);
          this.sum = 0;
          this.count = 0;
        }
        prev.set(local);
      } else {
        this.previous = local.slice();
      }
    }
    return done;
  }
}

/** Pose change of each whole second of a motion (frames × joints × 3). */
export function poseChangePerSecond(positions: ArrayLike<number>, joints: number, fps: number): number[] {
  return new PoseChangeMeter(joints, fps).push(positions);
}
