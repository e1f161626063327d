"""Foot-contact clean-up (Wang, Chai, Xia §4.3): planted feet stay in place and on the ground.

Works on world joint positions (frames, joints, 3) of the canonical skeleton plus the contact bits
(frames, 2: left, right) that the generator or refiner outputs with every frame. Positions rather than
rotations because they are what the viewer draws and the skating measure reads, the browser's Motion holds
positions only, two-bone IK on positions is a handful of vector operations, and bone lengths are kept
exactly by construction (thigh and shin from the IK, the foot moved rigidly). It is causal (each frame
needs only the past), so it runs frame by frame in the live stream; FootLock.step is the per-frame form and
foot_lock() loops it over a clip.

Per foot and frame (toe = LeftToeBase / RightToeBase, the point the skating measure follows):
1. Contact starts: the anchor (x, z) is where the toe is drawn this frame (the raw toe, or the blended toe if
   the foot is still being released from an earlier contact), so locking never jumps. The toe's height
   goes from its height at that frame to TOE_GROUND_HEIGHT over BLEND_IN frames (smoothstep weight
   smoothstep(k / BLEND_IN) in the k-th planted frame, k = 0, 1, ...).
2. Contact held: the toe target is (anchor x, ground height, anchor z).
3. Contact ends: the target goes from where the locked toe was last drawn back to the raw toe over
   BLEND_OUT frames (weight smoothstep(frames left / BLEND_OUT) on the locked position), so the foot does
   not pop. The raw foot may have slid far from the anchor meanwhile, so the catching-up foot is lifted by
   4 w (1 - w) times half the horizontal gap (at most RELEASE_LIFT): it steps over the floor instead of
   dragging along it (without the lift, path-followed feet skimmed the floor at 4-6 m/s after each contact).
4. The heel and the toes are locked with the toe: the heading (horizontal direction) of the foot (ankle to
   toe) and of the toes (toe to toe tip) are held at their headings when the contact started, and blended
   back to the raw ones over the blend-out, like the toe. Both keep their raw pitch, so a heel still lifts;
   how much of a heading is held falls from 1 to 0 as the part pitches from FLAT_PITCH to STEEP_PITCH
   (flatness()), because a steep foot's heel is off the floor and its heading is noise. The ankle target is
   the toe target minus the raw toe-from-ankle vector turned to the held heading (the foot moves rigidly:
   ankle, toe and toe end turned and moved alike). If that ankle target is
   beyond the leg's reach (REACH of thigh + shin), the foot pivots about the locked toe instead, as in a
   heel lift (pivot_foot: the nearest reachable ankle at the foot's length from the toe), the toes staying
   as they are. Two-bone IK puts
   the knee on the circle of valid knees, in the plane of hip, ankle target and the raw knee nudged towards
   the foot's forward direction (so the knee keeps pointing where the raw motion points it, and a nearly
   straight raw leg does not swing the knee about). If even a pivot cannot reach, the ankle stops at the
   reach and the anchor moves to where the toe ends up: the foot then slides with the body instead of
   stretching the leg, and nothing jumps later.
Hip positions and everything above the hips are never changed.
"""
from __future__ import annotations

import numpy as np

from .contact_labels import label_contacts
from .mocap.skeleton import Skeleton, canonical_skeleton

# Median height (m) of the toe point (LeftToeBase/RightToeBase) in planted frames of the real training
# clips (walk and run, 30 fps, floor-fitted): 5th-95th percentile 0.007-0.070 m.
TOE_GROUND_HEIGHT = 0.03
BLEND_IN = 3    # frames (0.1 s at 30 fps) to bring a planted toe to the ground height
BLEND_OUT = 6   # frames (0.2 s) to release a lifted foot from its anchor
REACH = 0.999   # fraction of thigh + shin the IK may stretch to
POLE_BIAS = 0.05  # m: how much the foot's forward direction adds to the raw knee's bend direction
# Pitch (radians, ankle-to-toe below level) up to which a planted foot's heading is held fully, and from which it is
# not held at all. A flat foot of the canonical skeleton pitches about 0.35 (ankle 8 cm above a toe 14 cm ahead).
FLAT_PITCH, STEEP_PITCH = 0.6, 1.0
RELEASE_LIFT = 0.08  # m: the most a released foot is lifted while it catches up with its raw position
LEGS = {"left": ("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "LeftToeBase_end"),
        "right": ("RightUpLeg", "RightLeg", "RightFoot", "RightToeBase", "RightToeBase_end")}


def smoothstep(t: float) -> float:
    t = min(max(t, 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def two_bone_ik(hip: np.ndarray, knee: np.ndarray, target: np.ndarray, l1: float, l2: float,
                reach: float = REACH, forward: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Knee and ankle positions with |knee - hip| = l1 and |ankle - knee| = l2, the ankle at `target` or, when
    that is out of reach, as close as the leg allows along the hip-target line. The knee lies in the plane of
    hip, target and the bend direction: the given (raw) knee's offset from the hip-target line plus
    POLE_BIAS times `forward` (the foot's direction), so a nearly straight raw leg, whose knee offset is tiny
    and noisy, still bends forward steadily instead of swinging the knee around."""
    d_vec = target - hip
    d = float(np.linalg.norm(d_vec))
    u = d_vec / d if d > 1e-9 else np.array([0.0, -1.0, 0.0])
    d = min(max(d, abs(l1 - l2) + 1e-6), reach * (l1 + l2))
    pole = knee - hip if forward is None else knee - hip + POLE_BIAS * forward
    bend = pole - np.dot(pole, u) * u  # direction away from the hip-ankle line
    n = float(np.linalg.norm(bend))
    if n < 1e-9:  # raw leg straight: bend forward (+z of the hip-target line's frame)
        bend = np.cross(u, np.array([1.0, 0.0, 0.0]))
        n = float(np.linalg.norm(bend))
        if n < 1e-9:
            bend, n = np.array([0.0, 0.0, 1.0]), 1.0
    bend = bend / n
    a = (l1 * l1 - l2 * l2 + d * d) / (2 * d)  # distance from the hip to the knee's foot point on the line
    r = np.sqrt(max(l1 * l1 - a * a, 0.0))
    return hip + a * u + r * bend, hip + d * u


def pivot_foot(hip: np.ndarray, ankle_target: np.ndarray, toe_target: np.ndarray, reach: float):
    """When the ankle target is beyond `reach` from the hip, the foot pivots about its (locked) toe as a heel
    lifts: the ankle goes to the point nearest its target on the circle of points at the foot's length from
    the toe and at `reach` from the hip. Returns (ankle target, pivoted?) with pivoted = None when the
    target is reachable as it is or when even pivoting cannot reach (the IK then clamps)."""
    if np.linalg.norm(ankle_target - hip) <= reach:
        return ankle_target, None
    r = float(np.linalg.norm(toe_target - ankle_target))  # foot length, ankle to toe
    d_vec = toe_target - hip
    d = float(np.linalg.norm(d_vec))
    if d >= reach + r or d <= abs(reach - r) or d < 1e-9:
        return ankle_target, None
    u = d_vec / d
    a = (reach * reach - r * r + d * d) / (2 * d)
    rho = np.sqrt(max(reach * reach - a * a, 0.0))
    centre = hip + a * u
    off = (ankle_target - centre) - np.dot(ankle_target - centre, u) * u
    n = float(np.linalg.norm(off))
    if n < 1e-9:
        return ankle_target, None
    return centre + rho * off / n, True


def foot_heading(toe_from_ankle: np.ndarray) -> float:
    """Heading (radians, 0 = +z, positive towards +x) of a foot's ankle-to-toe vector on the ground."""
    return float(np.arctan2(toe_from_ankle[0], toe_from_ankle[2]))


def flatness(toe_from_ankle: np.ndarray) -> float:
    """How much the foot's heading is held: 1 while the foot is within FLAT_PITCH of level, falling smoothly to 0 at
    STEEP_PITCH (a foot pointing down has no heading to speak of, and its heel is off the floor)."""
    pitch = float(np.arctan2(-toe_from_ankle[1], np.hypot(toe_from_ankle[0], toe_from_ankle[2])))
    return 1.0 - smoothstep((pitch - FLAT_PITCH) / (STEEP_PITCH - FLAT_PITCH))


def wrap_angle(a: float) -> float:
    """a in [-pi, pi)."""
    return float((a + np.pi) % (2 * np.pi) - np.pi)


def turn_about_y(angle: float) -> np.ndarray:
    """Rotation matrix that adds `angle` to a vector's heading (foot_heading), about the vertical."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


class FootLock:
    """Streaming foot lock: call step() once per frame, in order; reset() before a new clip."""

    def __init__(self, skel: Skeleton | None = None, ground: float = TOE_GROUND_HEIGHT,
                 blend_in: int = BLEND_IN, blend_out: int = BLEND_OUT):
        self.skel = skel or canonical_skeleton()
        self.ground, self.blend_in, self.blend_out = ground, blend_in, blend_out
        self.legs = [tuple(self.skel.index(n) for n in LEGS[side]) for side in ("left", "right")]
        self.lengths = [(float(np.linalg.norm(self.skel.offsets[k])), float(np.linalg.norm(self.skel.offsets[a])))
                        for _, k, a, _, _ in self.legs]
        self.reset()

    def reset(self) -> None:
        self.anchor = [None, None]      # locked toe (x, z) per foot
        self.start_y = [0.0, 0.0]       # toe height when the contact started
        self.locked = [None, None]      # where the locked toe was drawn in the last planted frame
        self.planted = [0, 0]           # frames since the contact started (0 = not planted)
        self.release = [0, 0]           # frames left of the blend-out
        # Held headings (radians, from +z towards +x) of the foot (ankle -> toe) and of the toes (toe -> toe tip) of
        # each planted foot, and the same in its last planted frame (None before any contact).
        self.heading = [(0.0, 0.0), (0.0, 0.0)]
        self.locked_heading = [None, None]

    def step(self, positions: np.ndarray, contacts) -> np.ndarray:
        """One frame: world positions (joints, 3) and contact bits (2,) -> cleaned positions (joints, 3)."""
        out = np.array(positions, dtype=np.float64, copy=True)
        for side, (hip, knee, ankle, toe, toe_end) in enumerate(self.legs):
            raw_toe = out[toe].copy()
            raw_parts = (raw_toe - out[ankle], out[toe_end] - raw_toe)  # the foot and the toes
            raw_heading = tuple(foot_heading(v) for v in raw_parts)
            flat = tuple(flatness(v) for v in raw_parts)
            if contacts[side]:
                if self.planted[side] == 0:  # contact starts where the foot is drawn now: no jump
                    start = self._drawn_toe(side, raw_toe)
                    self.anchor[side], self.start_y[side] = start[[0, 2]], float(start[1])
                    self.heading[side] = self._drawn_heading(side, raw_heading, flat)
                w = smoothstep(self.planted[side] / self.blend_in) if self.blend_in > 0 else 1.0
                self.planted[side] += 1
                target = np.array([self.anchor[side][0], (1 - w) * self.start_y[side] + w * self.ground,
                                   self.anchor[side][1]])
                heading = tuple(r + f * wrap_angle(h - r) for h, r, f in zip(self.heading[side], raw_heading, flat))
            else:
                self.planted[side] = 0
                if self.release[side] <= 0:
                    continue  # free foot: raw pose
                target = self._drawn_toe(side, raw_toe)
                heading = self._drawn_heading(side, raw_heading, flat)
                self.release[side] -= 1
            toe_from_ankle, end_from_toe = (turn_about_y(h - r) @ v for h, r, v in zip(heading, raw_heading, raw_parts))
            ankle_target = target - toe_from_ankle
            l1, l2 = self.lengths[side]
            ankle_target, pivot = pivot_foot(out[hip], ankle_target, target, REACH * (l1 + l2))
            forward = raw_toe - out[ankle]  # the knee follows the raw foot: a steep foot's heading is noise
            forward[1] = 0.0
            forward /= max(float(np.linalg.norm(forward)), 1e-9)
            new_knee, new_ankle = two_bone_ik(out[hip], out[knee], ankle_target, l1, l2, forward=forward)
            if pivot is None:  # the foot moves rigidly with the ankle
                out[toe] = new_ankle + toe_from_ankle
                out[toe_end] = out[toe] + end_from_toe
            else:  # the foot turns about the toe (heel lifts); the toes stay as they are
                out[toe_end] = target + end_from_toe
                out[toe] = target
            out[knee], out[ankle] = new_knee, new_ankle
            if contacts[side]:
                if np.linalg.norm(new_ankle - ankle_target) > 1e-6:
                    self.anchor[side] = out[toe, [0, 2]].copy()  # out of reach: the anchor follows the body
                self.locked[side] = out[toe].copy()
                self.locked_heading[side] = self.heading[side]
                self.release[side] = self.blend_out
        return out

    def _drawn_heading(self, side: int, raw_heading: tuple, flat: tuple) -> tuple:
        """The foot's and the toes' headings this frame if nothing new happens: the raw ones, or during a release the
        blend from the last locked headings to the raw ones (the toe's weight times each part's flatness, the
        shorter way round)."""
        if self.release[side] <= 0 or self.locked_heading[side] is None:
            return raw_heading
        w = smoothstep(self.release[side] / self.blend_out)
        return tuple(r + w * f * wrap_angle(h - r) for h, r, f in zip(self.locked_heading[side], raw_heading, flat))

    def _drawn_toe(self, side: int, raw_toe: np.ndarray) -> np.ndarray:
        """Where the toe is drawn this frame if nothing new happens: the raw toe, or during a release the
        blend from the last locked position to the raw toe (weight smoothstep(frames left / BLEND_OUT)), lifted."""
        if self.release[side] <= 0 or self.locked[side] is None:
            return raw_toe.copy()
        w = smoothstep(self.release[side] / self.blend_out)
        # A foot catching up with its raw position steps over the floor rather than dragging along it: a lift of
        # half the horizontal gap (at most RELEASE_LIFT), zero at both ends of the blend.
        gap = float(np.hypot(self.locked[side][0] - raw_toe[0], self.locked[side][2] - raw_toe[2]))
        out = w * self.locked[side] + (1 - w) * raw_toe
        out[1] += 4 * w * (1 - w) * min(0.5 * gap, RELEASE_LIFT)
        return out


def foot_lock(positions: np.ndarray, contacts: np.ndarray, skel: Skeleton | None = None, **kw) -> np.ndarray:
    """Cleaned world positions (frames, joints, 3) of a clip with contact bits (frames, 2)."""
    lock = FootLock(skel, **kw)
    return np.stack([lock.step(p, c) for p, c in zip(positions, np.asarray(contacts) > 0)])


def plant_feet(positions: np.ndarray, bits: np.ndarray, fps: float, skel: Skeleton | None = None) -> tuple[np.ndarray, np.ndarray]:
    """What every locomotion mode of the page shows: contacts labelled on the motion (contact_labels.py: the model's
    bits with the feet's heights and speeds), then the lock on those labels. Returns (positions, labels)."""
    labels = label_contacts(positions, bits, fps, skel)
    return foot_lock(positions, labels, skel), labels
