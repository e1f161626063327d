"""Foot contacts for the motion that is shown: the model's contact bit combined with the foot's own height and
speed, so that a foot resting on the floor is planted (and locked) even when the bit is off, and a foot in the
air is not pulled down because the bit is on.

The generator's bits are often off while a foot is on the floor: in refined 3,000-frame walks about half of the
frames with a foot within 4 cm of the floor had its bit off, and those feet slid at about 0.4 m/s. Real clips
get their contacts from heights and speeds (mocap/contacts.py); generated frames have the model's bit as well,
and both are used here.

Per foot and frame, causal (the live streams label each frame as it arrives; label_contacts runs the same over
a whole motion):
- the foot's lowest point is whichever of its ankle, toe and toe tip is lowest in this frame; h is its height
  above the floor (y = 0, where the canonical skeleton's generated motion stands);
- v is that point's horizontal speed since the previous frame (m/s; 0 in the first frame);
- the foot becomes planted when (h < NEAR and v < SLOW) or (its bit is on and h < BIT_NEAR), and, once planted,
  stays planted while (h < STAY_NEAR and v < STAY_SLOW) or (its bit is on and h < BIT_NEAR).

The same rule runs in the page (web/motion/contactLabels.ts); tests/fixtures/contact_labels.json checks the two.
"""
from __future__ import annotations

import numpy as np

from .metrics import FOOT_GROUP
from .mocap.skeleton import Skeleton, canonical_skeleton

# metres and metres per second
LABEL_THRESHOLDS = {"near": 0.04, "slow": 1.0, "stay_near": 0.06, "stay_slow": 1.5, "bit_near": 0.10}


class ContactLabeller:
    """Streaming labels: call step() once per frame, in order; reset() before a new motion."""

    def __init__(self, skel: Skeleton | None = None, fps: float = 30.0, thresholds: dict | None = None):
        skel = skel or canonical_skeleton()
        self.feet = [[skel.index(n) for n in FOOT_GROUP[side]] for side in ("left", "right")]
        self.fps = fps
        self.th = thresholds or LABEL_THRESHOLDS
        self.reset()

    def reset(self) -> None:
        self.previous: np.ndarray | None = None
        self.planted = [False, False]

    def step(self, positions: np.ndarray, bits) -> np.ndarray:
        """World positions (joints, 3) and the model's contact bits (2,) of one frame -> labels (2,) uint8."""
        th, out = self.th, np.zeros(2, np.uint8)
        for side, points in enumerate(self.feet):
            low = points[int(np.argmin(positions[points, 1]))]
            h = float(positions[low, 1])
            v = 0.0
            if self.previous is not None:
                v = float(np.hypot(positions[low, 0] - self.previous[low, 0], positions[low, 2] - self.previous[low, 2])) * self.fps
            by_bit = bool(bits[side]) and h < th["bit_near"]
            touches = h < th["near"] and v < th["slow"]
            stays = h < th["stay_near"] and v < th["stay_slow"]
            self.planted[side] = by_bit or touches or (self.planted[side] and stays)
            out[side] = self.planted[side]
        self.previous = np.array(positions, np.float64, copy=True)
        return out


def label_contacts(positions: np.ndarray, bits: np.ndarray, fps: float, skel: Skeleton | None = None) -> np.ndarray:
    """Labels (frames, 2) uint8 of a whole motion: positions (frames, joints, 3), model bits (frames, 2)."""
    labeller = ContactLabeller(skel, fps)
    return np.stack([labeller.step(p, b) for p, b in zip(positions, np.asarray(bits) > 0)]) if len(positions) \
        else np.zeros((0, 2), np.uint8)
