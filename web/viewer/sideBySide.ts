// Keeping a second figure beside the main one when the two walk their own paths: in Random walk's
// side-by-side view the raw generator frames and the refined ones decode their own root channels, and their
// paths part (metres apart and facing other ways within seconds, measured). For display only, the companion
// is carried along with the main figure by a slowly varying rigid turn and shift on the ground: its heading
// follows the main one's with a lag of `seconds`, its root moves with its own steps (turned by that heading)
// plus a pull towards the main root with the same lag. Its body motion, root jitter and foot sliding are its
// own; measures (foot skating) must use the untransformed frames.

/** Turns (x, z) by `a` about +y: R_y(a)(x, z) = (cos a·x + sin a·z, −sin a·x + cos a·z). */
function turn(a: number, x: number, z: number): [number, number] {
  const c = Math.cos(a), s = Math.sin(a);
  return [c * x + s * z, -s * x + c * z];
}

/** The angle in (−π, π] equal to `a` modulo 2π. */
function wrap(a: number): number {
  return a - 2 * Math.PI * Math.round(a / (2 * Math.PI));
}

export class CompanionAligner {
  private started = false;
  /** Heading added to the companion (rad). */
  private yaw = 0;
  /** Where the companion's root is drawn (x, z). */
  private qx = 0;
  private qz = 0;
  /** The companion's own root (x, z) in the previous frame. */
  private px = 0;
  private pz = 0;
  private readonly rate: number;

  /** `joints` per frame, root = joint 0; the lag is `seconds` at `fps`. */
  constructor(private readonly joints: number, fps: number, seconds = 1.5) {
    this.rate = 1 - Math.exp(-1 / (seconds * fps));
  }

  reset(): void {
    this.started = false;
  }

  /**
   * The next frames of both (positions frames × joints × 3, headings per frame, radians) → the companion's
   * frames as drawn, placed on the main figure's root (add a side offset when drawing).
   */
  align(companion: Float32Array, companionHeading: Float32Array, main: Float32Array, mainHeading: Float32Array): Float32Array {
    const J = this.joints, n = J * 3;
    const frames = companionHeading.length;
    if (companion.length !== frames * n || main.length !== frames * n || mainHeading.length !== frames) {
      throw new Error(`CompanionAligner: ${frames} companion frames do not match the main motion's ${mainHeading.length}`);
    }
    const out = new Float32Array(companion.length);
    const k = this.rate;
    for (let f = 0; f < frames; f++) {
      const o = f * n;
      const rx = companion[o], rz = companion[o + 2];
      const mx = main[o], mz = main[o + 2];
      if (!this.started) {
        this.started = true;
        this.yaw = wrap(mainHeading[f] - companionHeading[f]);
        this.qx = mx;
        this.qz = mz;
      } else {
        this.yaw += k * wrap(mainHeading[f] - companionHeading[f] - this.yaw);
        const [sx, sz] = turn(this.yaw, rx - this.px, rz - this.pz);
        const ax = this.qx + sx, az = this.qz + sz;
        this.qx = ax + k * (mx - ax);
        this.qz = az + k * (mz - az);
      }
      this.px = rx;
      this.pz = rz;
      for (let j = 0; j < J; j++) {
        const p = o + j * 3;
        const [x, z] = turn(this.yaw, companion[p] - rx, companion[p + 2] - rz);
        out[p] = this.qx + x;
        out[p + 1] = companion[p + 1];
        out[p + 2] = this.qz + z;
      }
    }
    return out;
  }
}
