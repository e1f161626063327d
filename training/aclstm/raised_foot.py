"""How often a dancer holds a foot high: the check the freeze rule cannot make (issue 42).

The freeze rule and the jitter budget judge how much a dance moves. A dancer standing on one leg with the other
foot at knee height and waving it moves plenty, so they pass it. Real dance rarely does that: over every clip of the
acLSTM set, the higher ankle is more than RAISED_FOOT_M above the frame's lowest point in 0.2% of salsa frames, 14.5%
of Indian and 6.1% of martial-arts frames.

A run's *raised-foot share* is that share over its frames. It is judged against the style's clips (all of them,
training and held-out, at their source rates, each clip alone): at most the real share plus RAISED_MARGIN
(percentage points, as a share), since a ratio means nothing against salsa's 0.2%.
"""
from __future__ import annotations

import numpy as np

from ..data.dance import STYLES, DanceClip

RAISED_FOOT_M = 0.3   # the higher ankle this far above the frame's lowest point: a raised foot
RAISED_MARGIN = 0.15  # a run may hold a foot up this much more often than the real clips (share of frames)
ANKLES = ("lFoot", "rFoot")


def raised_foot_mask(pos: np.ndarray, names: list[str]) -> np.ndarray:
    """pos (frames, points, 3) metres, y up -> per frame: is the higher ankle more than RAISED_FOOT_M above the lowest point."""
    lowest = pos[:, :, 1].min(axis=1)
    higher = pos[:, [names.index(a) for a in ANKLES], 1].max(axis=1)
    return higher - lowest > RAISED_FOOT_M


def raised_foot_share(pos: np.ndarray, names: list[str]) -> float:
    return float(raised_foot_mask(pos, names).mean())


def real_raised_foot(clips: list[DanceClip], names: list[str], styles: tuple[str, ...] | list[str] = STYLES) -> dict:
    """Per style, the raised-foot share of all its clips (frames of every clip counted alone, never joined)."""
    out = {}
    for style in styles:
        masks = [raised_foot_mask(c.positions, names) for c in clips if c.style == style]
        out[style] = float(np.concatenate(masks).mean())
    return out


def raised_foot_limit(real_share: float) -> float:
    return real_share + RAISED_MARGIN
