"""Pace measures of the style check (training/style_generator/style_check.py) on motion whose cadence is known."""
import numpy as np

from training.mocap.skeleton import canonical_skeleton
from training.style_generator.style_check import cadence, cadence_by_feet


def synthetic_walk(steps_per_minute: float, seconds: float = 6.0, fps: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    """Ankles swinging past each other: their spacing closes and opens once per step; contacts alternate per step."""
    skel = canonical_skeleton()
    t = np.arange(int(seconds * fps)) / fps
    stride_hz = steps_per_minute / 120.0  # a stride is two steps
    pos = np.zeros((len(t), len(skel.joints), 3))
    swing = 0.35 * np.sin(2 * np.pi * stride_hz * t)
    pos[:, skel.index("LeftFoot")] = np.stack([0.1 + 0 * t, 0.08 + 0 * t, 1.2 * t + swing], -1)
    pos[:, skel.index("RightFoot")] = np.stack([-0.1 + 0 * t, 0.08 + 0 * t, 1.2 * t - swing], -1)
    left_down = np.sin(2 * np.pi * stride_hz * t) > 0
    contacts = np.stack([left_down, ~left_down], -1).astype(np.uint8)
    return pos, contacts


def test_cadence_by_the_feet_spacing_and_by_the_contact_bits_find_the_steps():
    for spm in (96.0, 114.0, 132.0):
        pos, contacts = synthetic_walk(spm)
        assert abs(cadence_by_feet(pos) - spm) < 3.0
        assert abs(cadence(contacts) - spm) < 0.1 * spm


def test_contact_bit_cadence_counts_flicker_as_steps_and_the_feet_measure_does_not():
    pos, contacts = synthetic_walk(108.0)
    flicker = contacts.copy()
    flicker[::7, 0] = 1 - flicker[::7, 0]  # a chattering contact bit, as generated motion has
    assert cadence(flicker) > 1.3 * 108.0
    assert abs(cadence_by_feet(pos) - 108.0) < 3.0
