"""The stride a drawn path lacks (vae-lstm.json "stride"; web/runtime/vaeLstmStride.ts does the same).

The model reads the clip's own root velocity smoothed over 10 frames, and what the smoothing leaves of each
stride's sway (the hips surge, sway and twist with every step, a few cm/s and rad/s) is what it steps to: given a
drawn path's constant control it stops stepping within 2-4 s and glides (docs/models/vae-lstm.md). Trained on a
control smoothed over 20 frames, with no sway left, it did not step at all (pilot, 1,750 iterations). So, as Holden
et al. derive foot contacts from the trajectory, the page adds to a drawn control the sway a real walk has at that
speed: the training clips' mean sway over one stride (left-foot contact to left-foot contact), in 16 phase bins, and
the stride's period, per speed band; the gait phase advances by 1/period a second from a phase drawn by the seed.
The root still moves by the drawn control itself.

The sway is the clip's control smoothed as the model reads it minus the same smoothed over SLOW_SIGMA frames (the
path's own course), less its mean over the stride (so it swings about the drawn control and adds no speed), so the
model reads drawn control + sway as it read a real clip's.
"""
from __future__ import annotations

import numpy as np

from ..control import Rng
from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, WindowCorpus, smooth

PHASE_BINS = 16
BAND_EDGES = (0.0, 0.6, 1.0, 1.4, 2.0, float("inf"))  # forward m/s
SLOW_SIGMA = 40.0  # frames: what is left at this smoothing is the path, not the stride
STRIDE_FRAMES = (12, 48)  # a stride (left contact to left contact) this many frames long counts
PHASE_SEED_SALT = 0x2545F491


def fit_stride(corpus: WindowCorpus, control_sigma: float, fps: float) -> dict:
    """vae-lstm.json's "stride" from the unaugmented training clips (every 6th of the augmented copies)."""
    bands: list[list[tuple[float, float, np.ndarray]]] = [[] for _ in BAND_EDGES[:-1]]
    for clip in corpus.train_clips[::6]:
        control = clip.rows[:, CONTROL_SLICE]
        sway = smooth(control, control_sigma) - smooth(control, SLOW_SIGMA)
        left = clip.rows[:, CONTACT_SLICE.start] > 0.5
        onsets = np.flatnonzero(left[1:] & ~left[:-1]) + 1
        for a, b in zip(onsets[:-1], onsets[1:]):
            if not STRIDE_FRAMES[0] <= b - a <= STRIDE_FRAMES[1]:
                continue
            speed = float(control[a:b, 0].mean())
            band = int(np.searchsorted(BAND_EDGES, speed, side="right")) - 1
            at = np.linspace(0, b - a, PHASE_BINS, endpoint=False)
            shape = np.stack([np.interp(at, np.arange(b - a), sway[a:b, k]) for k in range(3)], axis=1)
            # Only the swing about the stride's own mean: the mean is no stride but the clip speeding up (most clips
            # start from rest, and the slow smoothing lags behind), 0.26 m/s at 1.5 m/s and 0.59 at 2.6 before this.
            # Added to a drawn control it made the model read a faster gait than asked, nearer the runs it cannot
            # keep up, and a fast random control's walk sagged to 0.14x the real pose change for seconds.
            shape -= shape.mean(axis=0)
            bands[max(band, 0)].append((speed, (b - a) / fps, shape))
    out = []
    for lo, hi, strides in zip(BAND_EDGES[:-1], BAND_EDGES[1:], bands):
        if not strides:
            continue
        out.append({"from": lo, "to": hi if np.isfinite(hi) else None, "strides": len(strides),
                    "speed": round(float(np.mean([s for s, _, _ in strides])), 4),
                    "period_s": round(float(np.median([p for _, p, _ in strides])), 4),
                    "sway": np.round(np.mean([w for _, _, w in strides], axis=0), 5).tolist()})
    return {"phase_bins": PHASE_BINS, "slow_sigma_frames": SLOW_SIGMA, "bands": out,
            "about": "sway per phase bin [forward m/s, sideways m/s, turn rad/s] added to a drawn control; the phase starts at "
                     "the seed's phase_start and advances 1/period_s a second; period and sway interpolated between the bands' speeds"}


def phase_start(seed: int) -> float:
    """Where in the stride a seed's motion starts, in [0, 1): the first uniform of Rng(seed ^ PHASE_SEED_SALT)."""
    return Rng((seed ^ PHASE_SEED_SALT) & 0xFFFFFFFF).uniform()


def stride_sway(control: np.ndarray, fps: float, stride: dict, phase: float) -> np.ndarray:
    """The sway (frames, 3) for a drawn control (frames, 3) starting at gait phase `phase`: each frame's period and
    sway interpolated linearly between the two bands whose speeds bracket its forward speed (the end bands beyond)."""
    bands = stride["bands"]
    speeds = [b["speed"] for b in bands]
    bins = stride["phase_bins"]
    out = np.zeros((len(control), 3))
    for f in range(len(control)):
        v = float(control[f, 0])
        k = int(np.searchsorted(speeds, v)) - 1
        if k < 0 or k >= len(bands) - 1:
            lo = hi = bands[0] if k < 0 else bands[-1]
            w = 0.0
        else:
            lo, hi = bands[k], bands[k + 1]
            w = (v - lo["speed"]) / (hi["speed"] - lo["speed"])
        x = phase * bins
        i = int(x) % bins
        j = (i + 1) % bins
        a = x - int(x)
        for c in range(3):
            low = lo["sway"][i][c] + a * (lo["sway"][j][c] - lo["sway"][i][c])
            high = hi["sway"][i][c] + a * (hi["sway"][j][c] - hi["sway"][i][c])
            out[f, c] = low + w * (high - low)
        period = lo["period_s"] + w * (hi["period_s"] - lo["period_s"])
        phase = (phase + 1.0 / (period * fps)) % 1.0
    return out
