"""What the ERDs train on: whole clips as sequences of steps, each step with the control signal of the step
after it (Yearsley §6.1.2: the control of t+1 goes in with the frame of t).

- Latent space: the autoencoder's latent of the whole clip (it is fully convolutional, so a clip encodes in
  one pass), one step per 4 frames (133 ms); the control of a step is the signal of its 4 frames, 12 values.
- Pose space (the baseline): the rows themselves, one step per frame, with that frame's 3 control values.

Both are normalised: latents by their own training mean and spread, the control by the rows' normalisation.

The latent ERD may read the control smoothed over `control_sigma` frames: the course, the way a stick, a
drawn path or random control gives it. The rows' own signal still sways with every stride (the root
trajectory is smoothed over only 0.17 s), and an ERD that reads that sway uses it as its clock: driven by the
same held-out control made smooth, the first shipped ERD moved its pose 22% less, and 43% less with the
control held constant.
"""
from __future__ import annotations

import numpy as np
import torch

from ..data.windows import CONTROL_SLICE, WindowCorpus, smooth
from ..models.autoencoder import POOLING, MotionAutoencoder

LATENT_STD_FLOOR = 1e-2


def encode_clip(model: MotionAutoencoder, rows: np.ndarray) -> np.ndarray:
    """Latent steps (frames // 4, latent) of a normalised clip, cut to a multiple of 4 frames."""
    n = len(rows) // POOLING * POOLING
    with torch.no_grad():
        return model.encode(torch.from_numpy(rows[None, :n])).numpy()[0]


def step_control(rows: np.ndarray, steps: int, sigma: float = 0.0) -> np.ndarray:
    """(steps, 4 × 3) the normalised control of each latent step's frames, from the first frame of `rows`,
    smoothed over `sigma` frames (a Gaussian over all of `rows`) when sigma > 0."""
    control = rows[:, CONTROL_SLICE]
    if sigma > 0:
        control = smooth(control, sigma)
    return control[:steps * POOLING].reshape(steps, POOLING * 3).astype(np.float32)


class StepSequences:
    """Sequences x (steps, dim) with the control of the next step (steps - 1, control), and batches of them."""

    def __init__(self, xs: list[np.ndarray], controls: list[np.ndarray], weights: np.ndarray):
        keep = [i for i, x in enumerate(xs) if len(x) >= 3]
        self.xs = [xs[i].astype(np.float32) for i in keep]
        self.controls = [controls[i].astype(np.float32) for i in keep]
        w = weights[keep]
        self.weights = w / w.sum()
        self.dim, self.control_dim = self.xs[0].shape[1], self.controls[0].shape[1]

    def batch(self, rng: np.random.Generator, size: int, steps: int):
        """Inputs (size, steps, dim), next-step controls, targets, and a mask of real targets."""
        x = np.zeros((size, steps + 1, self.dim), np.float32)
        c = np.zeros((size, steps, self.control_dim), np.float32)
        mask = np.zeros((size, steps), np.float32)
        for i, k in enumerate(rng.choice(len(self.xs), size=size, p=self.weights)):
            seq, con = self.xs[k], self.controls[k]
            start = int(rng.integers(0, max(1, len(seq) - steps)))
            w = seq[start:start + steps + 1]
            x[i, :len(w)] = w
            c[i, :len(w) - 1] = con[start + 1:start + len(w)]
            mask[i, :len(w) - 1] = 1
        x = torch.from_numpy(x)
        return x[:, :-1], torch.from_numpy(c), x[:, 1:], torch.from_numpy(mask)


def latent_sequences(model: MotionAutoencoder, corpus: WindowCorpus, control_sigma: float = 0.0):
    """Training and held-out StepSequences in latent space, and the latent mean and spread."""
    def raw(seqs):
        zs = [encode_clip(model, s) for s in seqs]
        return zs, [step_control(s, len(z), control_sigma) for s, z in zip(seqs, zs)]

    train_z, train_c = raw(corpus.train)
    valid_z, valid_c = raw(corpus.valid)
    allz = np.concatenate(train_z)
    mean, std = allz.mean(axis=0), np.maximum(allz.std(axis=0), LATENT_STD_FLOOR)
    norm = lambda zs: [(z - mean) / std for z in zs]
    ones = np.ones(len(valid_z))
    return (StepSequences(norm(train_z), train_c, corpus.weights), StepSequences(norm(valid_z), valid_c, ones), mean, std)


def pose_sequences(corpus: WindowCorpus):
    """Training and held-out StepSequences in pose space (rows are already normalised)."""
    con = lambda seqs: [s[:, CONTROL_SLICE] for s in seqs]
    return (StepSequences(corpus.train, con(corpus.train), corpus.weights),
            StepSequences(corpus.valid, con(corpus.valid), np.ones(len(corpus.valid))))
