"""The style check of issue 39: does a generated walk look like the style it was asked for?

A classifier learns to name the style of real Bandai walking (the 7 styles' "walk" clips that are not held out,
mirrored copies too) from the refiner report's 32-frame classifier windows (refiner/measures.py: root-frame joint
positions and velocities, root speed and turning, contacts; about 1 s). It is then asked to name:
- the held-out real walks of each style: how well styles can be told apart at all (the ceiling);
- walks generated in each style: streams from the style's held-out walk seed (pilots.seed_inputs, eq. 26's state),
  several random seeds per style, sampled as the page samples (pilots.sample).
Both give a confusion matrix (rows: the style asked for, columns: the style named), accuracy over windows, and
accuracy over streams (each stream named by the sum of its windows' log-probabilities).
Per style it also compares pace: mean root speed, and cadence (steps per minute: foot-down onsets of both feet by
the contact bits, per minute of motion; and by the feet's spacing, which needs no contact bits) of generated walks
against the real walks of that style.
"""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from ..data.locomotion import is_validation
from ..data.features import mirror_clip
from ..data.style_locomotion import STYLES, StyledClip
from ..mocap.skeleton import canonical_skeleton
from ..refiner.measures import classifier_frames, motion_windows, windows
from .pilots import Candidate, decode, initial_states, sample, seed_inputs

BANDAI_STYLES = STYLES[1:]
FPS = 30.0


class StyleClassifier(nn.Module):
    """The refiner report's window classifier (three 1-D convolutions, mean over time) with one output per style."""

    def __init__(self, inputs: int, styles: int, width: int = 64):
        super().__init__()
        self.net = nn.Sequential(nn.Conv1d(inputs, width, 5, padding=2), nn.ReLU(), nn.Conv1d(width, width, 5, padding=2),
                                 nn.ReLU(), nn.Conv1d(width, width, 5, padding=2, stride=2), nn.ReLU())
        self.out = nn.Linear(width, styles)

    def forward(self, w):  # (B, T, F) -> logits (B, styles)
        return self.out(self.net(w.transpose(1, 2)).mean(-1))


def walk_clips(clips: list[StyledClip], style: str, held_out: bool) -> list[StyledClip]:
    return [c for c in clips if c.style == style and c.content == "walk" and is_validation(c.clip) == held_out]


def real_windows(codec, clips: list[StyledClip], style: str, held_out: bool) -> np.ndarray:
    """Classifier windows of the style's real walks (training side: mirrored copies too)."""
    seqs = []
    for c in walk_clips(clips, style, held_out):
        variants = [(c.clip.root, c.clip.rotations, c.clip.contacts)]
        if not held_out:
            variants.append(mirror_clip(*variants[0]))
        for root, rot, con in variants:
            f = codec.encode(root, rot, con)
            seqs.append(classifier_frames(codec.positions(f), np.cumsum(f[:, 2]), f[:, -2:] > 0.5, FPS))
    return windows(seqs)


def real_positions(codec, c: StyledClip) -> np.ndarray:
    return codec.positions(codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts))


def cadence(contacts: np.ndarray, fps: float = FPS) -> float:
    """Steps per minute: foot-down onsets of both feet (contact bits, frames × 2) per minute."""
    c = np.asarray(contacts) > 0.5
    onsets = (c[1:] & ~c[:-1]).sum()
    return float(onsets / (len(c) / fps) * 60)


def cadence_by_feet(positions: np.ndarray, fps: float = FPS) -> float:
    """Steps per minute without contact bits: the dominant frequency (0.8-4 Hz) of the horizontal distance between
    the two ankles, which closes and opens once per step."""
    skel = canonical_skeleton()
    left, right = skel.index("LeftFoot"), skel.index("RightFoot")
    gap = np.linalg.norm(positions[:, left, [0, 2]] - positions[:, right, [0, 2]], axis=-1)
    gap = (gap - gap.mean()) * np.hanning(len(gap))
    n = 8 * len(gap)  # zero-padded: finer bins than the clip's length gives
    amp = np.abs(np.fft.rfft(gap, n))
    freqs = np.fft.rfftfreq(n, 1 / fps)
    band = (freqs >= 0.8) & (freqs <= 4.0)
    return float(freqs[band][amp[band].argmax()] * 60)


def train_classifier(train: dict[str, np.ndarray], seed: int = 0, steps: int = 1500) -> tuple[StyleClassifier, np.ndarray, np.ndarray]:
    """A StyleClassifier on {style: windows}, each style's windows drawn equally often; its input mean and std."""
    allw = np.concatenate(list(train.values()))
    mean, std = allw.mean(axis=(0, 1)), allw.std(axis=(0, 1)) + 1e-6
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    model = StyleClassifier(allw.shape[-1], len(train))
    optimiser = torch.optim.Adam(model.parameters(), lr=1e-3, weight_decay=1e-4)
    data = [torch.from_numpy(((w - mean) / std).astype(np.float32)) for w in train.values()]
    per = 16
    for _ in range(steps):
        xb, yb = [], []
        for k, w in enumerate(data):
            idx = rng.integers(0, len(w), per)
            xb.append(w[idx]), yb.append(torch.full((per,), k))
        loss = nn.functional.cross_entropy(model(torch.cat(xb)), torch.cat(yb))
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
    return model.eval(), mean, std


def log_probs(model: StyleClassifier, mean, std, w: np.ndarray) -> np.ndarray:
    with torch.no_grad():
        return torch.log_softmax(model(torch.from_numpy(((w - mean) / std).astype(np.float32))), -1).numpy()


def confusion(rows: dict[str, np.ndarray], n: int) -> np.ndarray:
    """rows: {asked style: predicted indices} -> counts (asked × named)."""
    m = np.zeros((len(rows), n), int)
    for i, pred in enumerate(rows.values()):
        m[i] = np.bincount(pred, minlength=n)
    return m


def style_check(cand: Candidate, clips: list[StyledClip], frames: int = 900, stream_seeds: tuple[int, ...] = (1, 2, 3, 4, 5),
                classifier_seed: int = 0, log=lambda line: print(line, flush=True)) -> dict:
    """The check of the module docstring for a style candidate; every number is in the returned dict."""
    codec = cand.codec
    train = {s: real_windows(codec, clips, s, False) for s in BANDAI_STYLES}
    held = {s: real_windows(codec, clips, s, True) for s in BANDAI_STYLES}
    model, mean, std = train_classifier(train, classifier_seed)
    real_pred = {s: log_probs(model, mean, std, w).argmax(-1) for s, w in held.items()}
    real_conf = confusion(real_pred, len(BANDAI_STYLES))
    log(f"style check: real held-out walks named right in {100 * np.trace(real_conf) / real_conf.sum():.1f}% of windows")
    out = {"styles": list(BANDAI_STYLES), "frames_per_stream": frames, "stream_seeds": list(stream_seeds),
           "windows": {"train": {s: len(w) for s, w in train.items()}, "held_out": {s: len(w) for s, w in held.items()}},
           "real_confusion": real_conf.tolist(), "real_accuracy": float(np.trace(real_conf) / real_conf.sum()),
           "pace": {}}
    gen_pred, stream_right, stream_total = {}, 0, 0
    for style in BANDAI_STYLES:
        seeds = [(STYLES.index(style), x) for name, x in seed_inputs(cand, clips, style) if name == f"{style} walk"]
        start = initial_states(cand, seeds)
        motions = [decode(cand, sample(cand, start, frames, np.random.default_rng(s))[0]) for s in stream_seeds]
        preds = []
        for m in motions:
            lp = log_probs(model, mean, std, motion_windows([m], FPS))
            preds.append(lp.argmax(-1))
            stream_right += int(lp.sum(0).argmax() == BANDAI_STYLES.index(style))
            stream_total += 1
        gen_pred[style] = np.concatenate(preds)
        real_walks = [c for c in walk_clips(clips, style, True) + walk_clips(clips, style, False) if len(c.clip.root) >= 2 * FPS]
        real_speed = [float(np.linalg.norm(np.diff(c.clip.root[:, [0, 2]], axis=0), axis=1).mean() * FPS) for c in real_walks]
        gen_speed = [float(np.linalg.norm(np.diff(m.positions[:, 0, [0, 2]], axis=0), axis=1).mean() * FPS) for m in motions]
        out["pace"][style] = {"speed_real": float(np.mean(real_speed)), "speed_generated": float(np.mean(gen_speed)),
                              "cadence_real": float(np.mean([cadence(c.clip.contacts) for c in real_walks])),
                              "cadence_generated": float(np.mean([cadence(m.contacts) for m in motions])),
                              "cadence_by_feet_real": float(np.mean([cadence_by_feet(real_positions(codec, c)) for c in real_walks])),
                              "cadence_by_feet_generated": float(np.mean([cadence_by_feet(m.positions) for m in motions]))}
        p = out["pace"][style]
        log(f"style check [{style}]: named right in {100 * np.mean(gen_pred[style] == BANDAI_STYLES.index(style)):.1f}% of "
            f"windows; speed {p['speed_generated']:.2f} (real {p['speed_real']:.2f}) m/s, cadence "
            f"{p['cadence_generated']:.0f} (real {p['cadence_real']:.0f}) steps/min by contact bits, "
            f"{p['cadence_by_feet_generated']:.0f} (real {p['cadence_by_feet_real']:.0f}) by the feet's spacing")
    conf = confusion(gen_pred, len(BANDAI_STYLES))
    out["generated_confusion"] = conf.tolist()
    out["generated_accuracy"] = float(np.trace(conf) / conf.sum())
    out["generated_stream_accuracy"] = stream_right / stream_total
    log(f"style check: generated walks named right in {100 * out['generated_accuracy']:.1f}% of windows, "
        f"{100 * out['generated_stream_accuracy']:.0f}% of streams (chance {100 / len(BANDAI_STYLES):.0f}%)")
    return out
