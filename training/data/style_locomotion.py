"""The style-conditioned generator's corpus (issue 39): CMU walking and running plus the Bandai Namco stylised
locomotion set (CC BY-NC 4.0: a model trained on it is non-commercial), each clip with a style id.

Styles: 0 is CMU (a style of its own), 1-7 are Bandai's (bandai.STYLES in order). Held out: data/locomotion.py's rule
on each corpus's ranks (every 8th clip by file name per CMU category, per Bandai content and style; bandai.py), so
every style keeps held-out clips of every content it has. Training clips get the Corpus's augmentation: mirrored
copies (features.mirror_clip) and copies played 0.9x and 1.1x as fast (locomotion.change_speed).

Sampling: each style is drawn equally often (1/8 of the windows), and within a style a clip in proportion to its
frames, with CMU's running drawn RUN_WEIGHT times as often as the Corpus draws it (CMU has 1 minute of running in 21;
Bandai's running is 22% of each style already, so it keeps its share). Why equal shares: every style is measured on
its own (held-out NLL, two-sample test, the style check), so each embedding needs about as many updates. Drawing by
frames would hardly differ for the Bandai styles (11.5-12.5 minutes each, 11-12% of the frames) and would give CMU 20%;
equal shares keep CMU at 12.5%. `cmu_share` gives CMU another share of the windows (the Bandai styles split the rest
equally), for a run in which the CMU style must keep up with the shipped CMU-only generator.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from . import bandai
from .features import FeatureCodec, mirror_clip
from .locomotion import RUN_WEIGHT, SPEED_FACTORS, LocomotionClip, change_speed, is_validation, load_clips

CMU_STYLE = "cmu"
STYLES = (CMU_STYLE,) + bandai.STYLES


@dataclass
class StyledClip:
    """A locomotion clip with its corpus, style and content (CMU: its category, walk or run)."""
    clip: LocomotionClip
    corpus: str   # "cmu" or "bandai"
    style: str
    content: str

    @property
    def style_id(self) -> int:
        return STYLES.index(self.style)


def styled_clips(cmu: list[LocomotionClip], bandai_clips: list[bandai.BandaiClip]) -> list[StyledClip]:
    """CMU clips as style "cmu", Bandai clips as their own style (as_locomotion_clip keeps their rank, so the
    locomotion held-out rule holds out Bandai's own held-out clips)."""
    out = [StyledClip(c, "cmu", CMU_STYLE, c.category) for c in cmu]
    out += [StyledClip(bandai.as_locomotion_clip(b), "bandai", b.style, b.content) for b in bandai_clips]
    return out


def load_styled_clips(mocap_flag: str | None = None) -> list[StyledClip]:
    """Every CMU walk/run clip and every Bandai clip, from their caches (built first when missing)."""
    return styled_clips(load_clips(mocap_flag), bandai.load_clips(mocap_flag))


class StyleCorpus:
    """data/locomotion.py's Corpus over styled clips: normalised feature sequences split by clip, each with its style
    id, and window batches that carry the style of each window. `references` (joints, 3, 3): the rotation references to
    encode with (default: fitted to the training clips, as the Corpus does)."""

    def __init__(self, clips: list[StyledClip], references: np.ndarray | None = None,
                 speed_factors=SPEED_FACTORS, mirror: bool = True, cmu_share: float | None = None):
        train = [c for c in clips if not is_validation(c.clip)]
        held = [c for c in clips if is_validation(c.clip)]
        self.codec = FeatureCodec(references=references)
        if references is None:
            self.codec.fit_references(np.concatenate([c.clip.rotations for c in train]))
        seqs, styles, frames = [], [], []
        for c in train:
            run = c.corpus == "cmu" and c.content == "run"
            for factor in speed_factors:
                root, rot, con = change_speed(c.clip, factor)
                for variant in [(root, rot, con)] + ([mirror_clip(root, rot, con)] if mirror else []):
                    seqs.append(self.codec.encode(*variant))
                    styles.append(c.style_id)
                    frames.append(len(seqs[-1]) * (RUN_WEIGHT if run else 1.0))
        allx = np.concatenate(seqs)
        self.mean = allx.mean(axis=0)
        self.std = np.maximum(allx.std(axis=0), 1e-2)
        self.train = [self.normalise(s) for s in seqs]
        self.train_styles = np.array(styles)
        self.weights = sampling_weights(self.train_styles, np.array(frames), cmu_share)
        self.valid = [self.normalise(self.codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts)) for c in held]
        self.valid_styles = np.array([c.style_id for c in held])
        self.valid_contents = [c.content for c in held]
        self.valid_files = [c.clip.file for c in held]
        self.train_frames = len(allx)
        self.train_frames_per_style = {s: int(sum(len(q) for q, k in zip(seqs, styles) if k == i)) for i, s in enumerate(STYLES)}

    def normalise(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.mean) / self.std).astype(np.float32)

    def batch(self, rng: np.random.Generator, size: int, length: int):
        """Windows of length+1 frames (inputs and next-frame targets), padded, a mask of real targets, and each
        window's style id (size,)."""
        x = np.zeros((size, length + 1, self.mean.shape[0]), np.float32)
        mask = np.zeros((size, length), np.float32)
        picks = rng.choice(len(self.train), size=size, p=self.weights)
        for i, k in enumerate(picks):
            seq = self.train[k]
            start = rng.integers(0, max(1, len(seq) - length))
            w = seq[start:start + length + 1]
            x[i, :len(w)] = w
            mask[i, :len(w) - 1] = 1
        return torch.from_numpy(x), torch.from_numpy(mask), torch.from_numpy(self.train_styles[picks].astype(np.int64))


def sampling_weights(styles: np.ndarray, frames: np.ndarray, cmu_share: float | None = None) -> np.ndarray:
    """Each style present gets an equal share (or CMU, style 0, `cmu_share` and the others equal shares of the rest);
    within a style, sequences in proportion to `frames` (already weighted)."""
    w = np.zeros(len(styles))
    present = np.unique(styles)
    if cmu_share is not None and not (0 < cmu_share < 1 and 0 in present and len(present) > 1):
        raise ValueError(f"cmu_share {cmu_share}: needs CMU and another style, and a share between 0 and 1")
    for s in present:
        sel = styles == s
        share = 1 / len(present) if cmu_share is None else cmu_share if s == 0 else (1 - cmu_share) / (len(present) - 1)
        w[sel] = frames[sel] / frames[sel].sum() * share
    return w
