"""The dance models' output filter (issue 42's jitter budget): a causal 2nd-order Butterworth low-pass applied per
channel to the generated features, after the sampler and never fed back (the network reads its own raw draws; the
page draws the filtered frames).

The biquad is designed from `cutoff_hz` and the frame rate by the bilinear transform with the cutoff pre-warped
(K = tan(π·fc/fs)):
    b = [K², 2K², K²] / n,  a = [1, 2(K² - 1) / n, (1 - √2·K + K²) / n],  n = 1 + √2·K + K²,
so the gain is 1 at DC, 1/√2 at the cutoff and 0 at Nyquist. The difference equation, per channel,
    y[t] = b0·x[t] + b1·x[t-1] + b2·x[t-2] - a1·y[t-1] - a2·y[t-2],
keeps the state (x[t-1], x[t-2], y[t-1], y[t-2]); starting it with all four equal to a frame starts the filter at
rest on that frame (its DC gain is 1), as the page starts it on the last seed frame. The same arithmetic is the
mdn graph's display output (training/aclstm/graph.py). The features are affine in the positions per channel and the
DC gain is 1, so filtering normalised or physical features gives the same motion.

Cutoff per style, `choose_cutoff` (the rule): the frequency below which CUTOFF_POWER_SHARE (99%) of the style's
**training** clips' velocity power lies, the velocity being that of every joint relative to the root (the motion the
jitter measure reads, freeze_rule.jitter_cm), at the model's rate, Welch's estimate (Hann segments of WELCH_FRAMES,
half overlapping, each clip alone, summed over clips and channels). Real dance has almost no motion above that
frequency, so what the model puts there is shake; the held-out clips and every judged run play no part in it.
"""
from __future__ import annotations

import numpy as np
import torch

from ..data.dance import MODEL_FPS, STYLES, resample_positions

CUTOFF_POWER_SHARE = 0.99
WELCH_FRAMES = 128  # 4.3 s at 30 fps: 0.23 Hz bins


def butterworth_lowpass(cutoff_hz: float, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """(b (3,), a (3,) with a[0] = 1) of the 2nd-order Butterworth low-pass at `cutoff_hz` for frames at `fps`."""
    if not 0 < cutoff_hz < fps / 2:
        raise ValueError(f"cutoff {cutoff_hz} Hz must lie between 0 and Nyquist ({fps / 2} Hz)")
    k = np.tan(np.pi * cutoff_hz / fps)
    n = 1 + np.sqrt(2) * k + k * k
    b = np.array([k * k, 2 * k * k, k * k]) / n
    a = np.array([1.0, 2 * (k * k - 1) / n, (1 - np.sqrt(2) * k + k * k) / n])
    return b, a


def gain(b: np.ndarray, a: np.ndarray, freq_hz: np.ndarray | float, fps: float) -> np.ndarray:
    """|H(e^{iω})| of the biquad at `freq_hz`."""
    z = np.exp(-1j * 2 * np.pi * np.asarray(freq_hz) / fps)
    return np.abs((b[0] + b[1] * z + b[2] * z * z) / (a[0] + a[1] * z + a[2] * z * z))


def rest_state(frame: np.ndarray) -> np.ndarray:
    """The filter state (..., 4, D) at rest on `frame` (..., D): x[t-1] = x[t-2] = y[t-1] = y[t-2] = frame."""
    return np.repeat(np.asarray(frame, np.float32)[..., None, :], 4, axis=-2)


class CausalLowPass:
    """The biquad over a batch of rows, each with its own coefficients; torch float32, as the graph computes."""

    def __init__(self, b: np.ndarray, a: np.ndarray, state: np.ndarray):
        """b (B, 3), a (B, 3) or (B, 2) (a1, a2), state (B, 4, D): x[t-1], x[t-2], y[t-1], y[t-2]."""
        b, a = np.atleast_2d(b), np.atleast_2d(a)
        self.b = torch.tensor(b, dtype=torch.float32).unsqueeze(-1)             # (B, 3, 1)
        self.a = torch.tensor(a[:, -2:], dtype=torch.float32).unsqueeze(-1)     # (B, 2, 1): a1, a2
        self.state = torch.as_tensor(np.asarray(state, np.float32)).clone()

    def step(self, x: torch.Tensor) -> torch.Tensor:
        """One frame per row (B, D) -> its filtered frame (B, D)."""
        x1, x2, y1, y2 = self.state.unbind(1)
        y = self.b[:, 0] * x + self.b[:, 1] * x1 + self.b[:, 2] * x2 - self.a[:, 0] * y1 - self.a[:, 1] * y2
        self.state = torch.stack([x, x1, y, y1], 1)
        return y


def lowpass(frames: np.ndarray, b: np.ndarray, a: np.ndarray, initial: np.ndarray | None = None) -> np.ndarray:
    """Filters (frames, D) causally with one biquad, starting at rest on `initial` (D,) (default the first frame)."""
    frames = np.asarray(frames, np.float64)
    return lowpass_rows(frames[None], np.asarray(b)[None], np.asarray(a)[None],
                        (frames[0] if initial is None else np.asarray(initial))[None])[0]


def lowpass_rows(frames: np.ndarray, b: np.ndarray, a: np.ndarray, initial: np.ndarray) -> np.ndarray:
    """Filters (rows, frames, D) causally, each row with its own biquad (b (rows, 3), a (rows, 3)), in float64,
    each starting at rest on its `initial` frame (rows, D)."""
    frames = np.asarray(frames, np.float64)
    b, a = np.asarray(b, np.float64)[:, :, None], np.asarray(a, np.float64)[:, -2:, None]
    x1 = x2 = y1 = y2 = np.asarray(initial, np.float64)
    out = np.empty_like(frames)
    for t in range(frames.shape[1]):
        x = frames[:, t]
        y = b[:, 0] * x + b[:, 1] * x1 + b[:, 2] * x2 - a[:, 0] * y1 - a[:, 1] * y2
        x1, x2, y1, y2 = x, x1, y, y1
        out[:, t] = y
    return out


def velocity_spectrum(clips, style: str, fps: float = MODEL_FPS) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies (Hz), power) of the joints' velocity relative to the root over the style's training clips."""
    window = np.hanning(WELCH_FRAMES)
    power = np.zeros(WELCH_FRAMES // 2 + 1)
    for c in clips:
        if c.style != style or c.held_out:
            continue
        pos = resample_positions(c.positions, c.fps, 0.0, int(c.seconds * fps) - 1, fps=fps)
        vel = np.diff(pos - pos[:, :1], axis=0).reshape(len(pos) - 1, -1) * fps
        for start in range(0, len(vel) - WELCH_FRAMES + 1, WELCH_FRAMES // 2):
            seg = vel[start:start + WELCH_FRAMES]
            seg = (seg - seg.mean(0)) * window[:, None]
            power += (np.abs(np.fft.rfft(seg, axis=0)) ** 2).sum(1)
    return np.fft.rfftfreq(WELCH_FRAMES, 1 / fps), power


def power_share_frequency(freqs: np.ndarray, power: np.ndarray, share: float) -> float:
    """The frequency below which `share` of the power lies (linear between bins)."""
    cum = np.cumsum(power) / power.sum()
    return float(np.interp(share, cum, freqs))


def choose_cutoff(clips, style: str, share: float = CUTOFF_POWER_SHARE, fps: float = MODEL_FPS) -> float:
    """The module docstring's rule: where `share` of the style's training clips' velocity power lies below."""
    return power_share_frequency(*velocity_spectrum(clips, style, fps), share)


def coefficients(block: dict) -> tuple[np.ndarray, np.ndarray]:
    """(b, a) of one style's filter block (style_filters, the JSON's sampling.filter), as lowpass_rows takes them."""
    return np.array(block["b"]), np.array(block["a"])


def style_filters(clips, styles=STYLES, share: float = CUTOFF_POWER_SHARE, fps: float = MODEL_FPS) -> dict:
    """Per style {cutoff_hz, b, a}: the JSON's sampling.filter block."""
    out = {}
    for style in styles:
        cutoff = round(choose_cutoff(clips, style, share, fps), 3)
        b, a = butterworth_lowpass(cutoff, fps)
        out[style] = {"cutoff_hz": cutoff, "b": [float(v) for v in b], "a": [float(v) for v in a]}
    return out
