"""Foot-contact labels from ankle and toe heights and speeds, with hysteresis.

The same rule runs in the browser (web/motion/contacts.ts) for imported clips.
Heights are measured from each joint's own resting height (5th percentile over the clip),
so the rule does not depend on how thick the foot is.
"""
from __future__ import annotations

import numpy as np

# metres and metres per second
CONTACT_THRESHOLDS = {
    "ankle_on": 0.05, "toe_on": 0.04, "speed_on": 0.5,
    "ankle_off": 0.07, "toe_off": 0.06, "speed_off": 0.75,
}


def joint_speed(track: np.ndarray, fps: float) -> np.ndarray:
    """Speed (frames,) of one joint's track (frames, 3) by central differences."""
    if len(track) < 2:
        return np.zeros(len(track))
    return np.linalg.norm(np.gradient(track, axis=0), axis=-1) * fps


def foot_contacts(ankle: np.ndarray, toe: np.ndarray, fps: float, thresholds: dict | None = None) -> np.ndarray:
    """Contact flags (frames,) for one foot from its ankle and toe tracks (frames, 3)."""
    th = thresholds or CONTACT_THRESHOLDS
    h_a = ankle[:, 1] - np.percentile(ankle[:, 1], 5)
    h_t = toe[:, 1] - np.percentile(toe[:, 1], 5)
    v_a, v_t = joint_speed(ankle, fps), joint_speed(toe, fps)
    on = ((h_a < th["ankle_on"]) & (v_a < th["speed_on"])) | ((h_t < th["toe_on"]) & (v_t < th["speed_on"]))
    stay = ((h_a < th["ankle_off"]) & (v_a < th["speed_off"])) | ((h_t < th["toe_off"]) & (v_t < th["speed_off"]))
    out = np.zeros(len(ankle), dtype=np.uint8)
    state = False
    for i in range(len(ankle)):
        state = bool(on[i]) or (state and bool(stay[i]))
        out[i] = state
    return out


def contacts_for(positions: np.ndarray, joints: list[str], fps: float,
                 feet: dict[str, tuple[str, str]]) -> np.ndarray:
    """(frames, 2) contact flags, left then right, for a clip's world positions."""
    cols = []
    for side in ("left", "right"):
        ankle, toe = feet[side]
        cols.append(foot_contacts(positions[:, joints.index(ankle)], positions[:, joints.index(toe)], fps))
    return np.stack(cols, axis=1)
