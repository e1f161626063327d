"""The low-dimensional control signal of the latent ERD (Yearsley §3.2.1, Ch. 6): per frame, the root's
forward velocity, sideways velocity (m/s, in its own ground-projected facing frame) and turning speed
(rad/s, positive turns from +z towards +x).

The same rules run in the browser (web/motion/control.ts); tests/fixtures/control_signal.json checks the
two against each other (python -m training.fixtures.control_signal).

- `control_from_trajectory`: the signal of a ground trajectory (real clips, for training and evaluation).
- `integrate_control`: back from the signal to a trajectory (what the page does with the decoded signal).
- `control_toward_heading`: a stick (direction and speed) as a signal.
- `control_along_path`: closed-loop path following by pure pursuit: the signal that turns the character
  from where it is now towards a point a little further along the path.

Frame t's signal is the motion from frame t to frame t+1: root_{t+1} = root_t + R(heading_t)·[side, fwd]/fps.
"""
from __future__ import annotations

import math

import numpy as np

# How sharply the stick and the path follower turn: the heading error is closed in TURN_TIME seconds,
# at most MAX_TURN_RATE rad/s (the corpus's turns reach about 3 rad/s; 2.5 keeps inside its range). At 0.5 s
# the proportional tail alone took 0.8 s from the end of the saturated turn to within 15°, and the latent
# ERD's 180° turns took 1.2–1.6 s in the page (limit 1.5 s); 0.25 s halves the tail.
TURN_TIME = 0.25
MAX_TURN_RATE = 2.5
# Pure pursuit looks LOOKAHEAD_SECONDS of travel ahead along the path, and at least MIN_LOOKAHEAD metres.
LOOKAHEAD_SECONDS = 0.6
MIN_LOOKAHEAD = 0.5
# The follower searches for itself along the path from its last arc length to PROGRESS_AHEAD further, so a
# path that crosses itself is not short-cut (as web/optimizer trackArc), and never behind it: where a path
# doubles back, the leg it walked lies under the leg it walks. Of the stretches within NEAR_TIE metres as near as
# the nearest, it is on the earliest: the leg it came up and the leg it goes back on lie within a drawing's jitter.
PROGRESS_AHEAD = 1.2
NEAR_TIE = 0.05
# It slows down over the last STOP_SECONDS of travel so it stops at the end instead of overshooting, and
# stands still once it is within ARRIVED metres of the end (else the slow-down never quite finishes).
STOP_SECONDS = 0.5
ARRIVED = 0.05
# A bend sharper than SHARP_BEND rad (from the path's direction where the walker is) stops the look-ahead:
# pure pursuit would cut across it (a reversal whole), so the walker is steered to the bend itself, slowing as
# it nears (as at the end), looks past it once within BEND_REACH metres of it, and speeds up again as it slowed.
# Its forward speed falls with the heading error, full within FULL_SPEED_ERROR rad and none from STILL_ERROR on,
# so a reversal turns on the spot rather than walking a loop off the path.
SHARP_BEND = math.pi / 4
BEND_REACH = 0.1
FULL_SPEED_ERROR = math.pi / 9
STILL_ERROR = math.pi / 4


def wrap(a):
    """Angle wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def rotate_to_local(dx, dz, heading):
    """World ground displacement (dx, dz) in the frame of a walker facing `heading`: (sideways, forward)."""
    c, s = np.cos(heading), np.sin(heading)
    return c * dx - s * dz, s * dx + c * dz


def control_from_trajectory(xz: np.ndarray, heading: np.ndarray, fps: float) -> np.ndarray:
    """(frames, 3) [forward, sideways, turn] of a ground trajectory xz (frames, 2) with headings (frames,).
    The last frame repeats the one before it."""
    d = np.diff(xz, axis=0)
    side, fwd = rotate_to_local(d[:, 0], d[:, 1], heading[:-1])
    turn = wrap(np.diff(heading))
    out = np.stack([fwd, side, turn], axis=1) * fps
    return np.concatenate([out, out[-1:]], axis=0) if len(out) else np.zeros((len(xz), 3))


def integrate_control(control: np.ndarray, fps: float, start_xz=(0.0, 0.0), start_heading: float = 0.0):
    """The ground trajectory (frames, 2) and headings (frames,) a signal (frames, 3) traces from a start:
    frame 0 is the start, frame t+1 applies frame t's signal."""
    n = len(control)
    xz = np.zeros((n, 2))
    heading = np.zeros(n)
    x, z, h = float(start_xz[0]), float(start_xz[1]), float(start_heading)
    for t in range(n):
        xz[t] = x, z
        heading[t] = h
        fwd, side, turn = (float(v) / fps for v in control[t])
        c, s = math.cos(h), math.sin(h)
        x += c * side + s * fwd
        z += -s * side + c * fwd
        h = float(wrap(h + turn))
    return xz, heading


def control_toward_heading(heading: float, target_heading: float, speed: float) -> np.ndarray:
    """A stick's signal: walk forward at `speed`, turning towards `target_heading`."""
    turn = float(np.clip(wrap(target_heading - heading) / TURN_TIME, -MAX_TURN_RATE, MAX_TURN_RATE))
    return np.array([speed, 0.0, turn])


class PolylinePath:
    """A ground path (points, 2) with arc lengths, as the follower walks it."""

    def __init__(self, points: np.ndarray):
        self.points = np.asarray(points, dtype=np.float64)
        if len(self.points) < 2:
            raise ValueError(f"a PolylinePath needs at least 2 points, got {len(self.points)}")
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        self.arc = np.concatenate([[0.0], np.cumsum(seg)])
        self.length = float(self.arc[-1])

    def segment_at(self, s: float) -> int:
        """Index of the segment at arc length s (at a point, the segment leaving it; kept on the path)."""
        return int(np.clip(np.searchsorted(self.arc, s, side="right") - 1, 0, len(self.points) - 2))

    def point_at(self, s: float) -> np.ndarray:
        s = min(max(s, 0.0), self.length)
        i = self.segment_at(s)
        span = self.arc[i + 1] - self.arc[i]
        t = (s - self.arc[i]) / span if span > 0 else 0.0
        return self.points[i] + (self.points[i + 1] - self.points[i]) * t

    def bend_after(self, s_from: float, s_to: float, angle: float) -> float:
        """Arc length of the first point after s_from and up to s_to where the path's direction has turned more
        than `angle` rad from its direction at s_from (zero-length segments skipped), or inf if there is none."""
        i = self.segment_at(s_from)
        while i < len(self.points) - 2 and self.arc[i + 1] == self.arc[i]:
            i += 1
        a, b = self.points[i], self.points[i + 1]
        along = math.atan2(b[0] - a[0], b[1] - a[1])
        k = i + 1
        while k + 1 < len(self.points) and self.arc[k] <= s_to:
            if self.arc[k + 1] != self.arc[k] and self.arc[k] > s_from:
                p, q = self.points[k], self.points[k + 1]
                if abs(float(wrap(math.atan2(q[0] - p[0], q[1] - p[1]) - along))) > angle:
                    return float(self.arc[k])
            k += 1
        return math.inf

    def bend_before(self, s_from: float, s_to: float, angle: float) -> float:
        """Arc length of the last point before s_from and down to s_to (s_to <= s_from) where the path's direction
        differs by more than `angle` rad from its direction at s_from (zero-length segments skipped), or -inf."""
        i = self.segment_at(s_from)
        while i < len(self.points) - 2 and self.arc[i + 1] == self.arc[i]:
            i += 1
        a, b = self.points[i], self.points[i + 1]
        along = math.atan2(b[0] - a[0], b[1] - a[1])
        k = i
        while k > 0 and self.arc[k] >= s_to:
            if self.arc[k] != self.arc[k - 1]:
                p, q = self.points[k - 1], self.points[k]
                if abs(float(wrap(math.atan2(q[0] - p[0], q[1] - p[1]) - along))) > angle:
                    return float(self.arc[k])
            k -= 1
        return -math.inf

    def project(self, x: float, z: float, s_from: float, s_to: float, tie: float = 0.0) -> float:
        """Arc length of the nearest point to (x, z) on the path between arc lengths s_from and s_to (0 if the
        path has none there); of points less than `tie` m farther than the nearest, the earliest."""
        arcs, distances = [], []
        for i in range(len(self.points) - 1):
            if self.arc[i + 1] < s_from or self.arc[i] > s_to:
                continue
            a, b = self.points[i], self.points[i + 1]
            d = b - a
            len2 = float(d @ d)
            span = float(self.arc[i + 1] - self.arc[i])
            # The part of the segment inside [s_from, s_to], as fractions of it.
            lo = max((s_from - self.arc[i]) / span, 0.0) if span > 0 else 0.0
            hi = min((s_to - self.arc[i]) / span, 1.0) if span > 0 else 0.0
            t = min(max(((x - a[0]) * d[0] + (z - a[1]) * d[1]) / len2, lo), hi) if len2 > 0 else 0.0
            # Held at its end where the path goes on inside the window: the next segment has that point or a nearer one.
            if t == 1 and i + 2 < len(self.points) and self.arc[i + 1] <= s_to:
                continue
            ex, ez = a[0] + d[0] * t - x, a[1] + d[1] * t - z
            arcs.append(float(self.arc[i] + t * span))
            distances.append(math.sqrt(ex * ex + ez * ez))
        nearest = min(distances, default=math.inf)
        for s, dist in zip(arcs, distances):
            if dist <= nearest + tie:
                return s
        return 0.0


def control_along_path(path: PolylinePath, x: float, z: float, heading: float, progress: float, speed: float):
    """The signal that steers a walker at (x, z) facing `heading` along `path` at `speed` (pure pursuit, towards
    a sharp bend before the look-ahead point: SHARP_BEND), and its new progress (arc length) along the path,
    searched from the last one on."""
    s = path.project(x, z, progress, progress + PROGRESS_AHEAD, NEAR_TIE)
    remaining = path.length - s
    if remaining <= ARRIVED:
        return np.array([0.0, 0.0, 0.0]), s
    reach = max(MIN_LOOKAHEAD, speed * LOOKAHEAD_SECONDS)
    ahead = s + reach
    bend = path.bend_after(s, ahead, SHARP_BEND)
    passed = path.bend_before(s, s - reach, SHARP_BEND)
    if bend - s <= BEND_REACH:  # at the bend: look past it, and leave it as from a stop
        passed = bend
        bend = path.bend_after(bend, ahead, SHARP_BEND)
    target = path.point_at(min(ahead, bend))
    want = math.atan2(target[0] - x, target[1] - z)
    # Slowing over STOP_SECONDS into the end or a bend, and speeding up as gently out of a bend.
    slowing = min(remaining, max(bend - s, BEND_REACH), max(s - passed, BEND_REACH))
    error = abs(float(wrap(want - heading)))
    facing = min(max((STILL_ERROR - error) / (STILL_ERROR - FULL_SPEED_ERROR), 0.0), 1.0)
    fwd = min(speed, slowing / STOP_SECONDS) * facing
    return control_toward_heading(heading, want, fwd), s


class Rng:
    """The page's random source (web/model/sampler.ts Rng: mulberry32 and Box–Muller), bit for bit, so a seed
    gives the same random control on both sides."""

    def __init__(self, seed: int):
        self.state = seed & 0xFFFFFFFF
        self.spare: float | None = None

    def uniform(self) -> float:
        m = 0xFFFFFFFF
        self.state = (self.state + 0x6D2B79F5) & m
        s = self.state
        t = _imul(s ^ (s >> 15), 1 | s)
        t = ((t + _imul(t ^ (t >> 7), 61 | t)) & m) ^ t
        return ((t ^ (t >> 14)) & m) / 4294967296

    def normal(self) -> float:
        """Standard normal by Box–Muller, the second value of each pair kept for the next call (as sampler.ts)."""
        if self.spare is not None:
            value, self.spare = self.spare, None
            return value
        u1 = 1 - self.uniform()
        u2 = self.uniform()
        radius = math.sqrt(-2 * math.log(u1))
        self.spare = radius * math.sin(2 * math.pi * u2)
        return radius * math.cos(2 * math.pi * u2)


def _imul(a: int, b: int) -> int:
    return (a * b) & 0xFFFFFFFF


# Random control (generate without `control`): every RANDOM_SEGMENT seconds a new target speed and turn rate
# are drawn, and the signal eases towards them with time constant RANDOM_EASE, so it is smooth. The ranges
# sit inside the corpus's (forward 1st–99th percentile -0.2…3.2 m/s, turn ±2.8 rad/s).
RANDOM_SEGMENT = 2.0
RANDOM_EASE = 0.5
RANDOM_SPEED = (0.4, 2.0)
RANDOM_TURN = 1.2


def random_control(seed: int, frames: int, fps: float) -> np.ndarray:
    """(frames, 3) a smooth random [forward, 0, turn] signal drawn from `seed`."""
    rng = Rng(seed)
    segment = max(1, round(RANDOM_SEGMENT * fps))
    ease = 1 - math.exp(-1 / (RANDOM_EASE * fps))
    fwd, turn = 1.0, 0.0
    target_fwd, target_turn = fwd, turn
    out = np.zeros((frames, 3))
    for t in range(frames):
        if t % segment == 0:
            target_fwd = RANDOM_SPEED[0] + (RANDOM_SPEED[1] - RANDOM_SPEED[0]) * rng.uniform()
            target_turn = RANDOM_TURN * (2 * rng.uniform() - 1)
        fwd += (target_fwd - fwd) * ease
        turn += (target_turn - turn) * ease
        out[t] = fwd, 0.0, turn
    return out
