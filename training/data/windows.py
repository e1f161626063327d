"""Per-frame motion rows for the motion manifold (Holden et al.; Yearsley §3.2.1) and the models built on it
(the latent ERD; later the VAE-LSTM and clean-up), and the corpus of them: CMU walking and running at 30 fps,
split into training and validation by clip exactly as the generator's corpus (data/locomotion.py).

A row is [joint positions (joints × 3) in the root's ground-projected facing frame, the control signal
(forward, sideways, turn; training/control.py), contact left, contact right]: 75 + 3 + 2 = 80 values on the
canonical skeleton.

The root's ground trajectory is the hips' ground projection and the facing is the normal of the
hips-plus-shoulders across vector, both smoothed over SMOOTH_SIGMA seconds: the signal then carries the
walker's course and not the sway of each step, the way a stick or a drawn path gives it, and the sway stays
in the positions.

30 fps rather than 60: the generator's corpus and cache are at 30 fps, a 4 s window is 120 frames, and two
poolings (1:4) give a latent step of 133 ms, the same as the thesis's 1:8 at 60 fps, at half the cost.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..control import control_from_trajectory, integrate_control
from ..mocap.skeleton import canonical_skeleton, forward_kinematics
from .features import mirror_clip
from .locomotion import FPS, RUN_WEIGHT, SPEED_FACTORS, LocomotionClip, change_speed, is_validation

WINDOW = 120  # frames: 4 s at 30 fps
SMOOTH_SIGMA = 0.167  # seconds
POSITION_STD_FLOOR = 0.01  # metres: near-constant channels are not blown up by normalisation
JOINTS = canonical_skeleton().joints
POSITION_DIM = 3 * len(JOINTS)
CONTROL_SLICE = slice(POSITION_DIM, POSITION_DIM + 3)
CONTACT_SLICE = slice(POSITION_DIM + 3, POSITION_DIM + 5)
ROW_DIM = POSITION_DIM + 5


def smooth(x: np.ndarray, sigma_frames: float) -> np.ndarray:
    """Gaussian smoothing along axis 0 with edge padding."""
    r = int(np.ceil(3 * sigma_frames))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma_frames) ** 2)
    k /= k.sum()
    pad = np.concatenate([np.repeat(x[:1], r, 0), x, np.repeat(x[-1:], r, 0)])
    return sum(k[i] * pad[i:i + len(x)] for i in range(2 * r + 1))


def ground_frame(positions: np.ndarray, fps: float = FPS):
    """Smoothed root ground trajectory (frames, 2) and facing headings (frames,) of world positions."""
    j = JOINTS.index
    across = (positions[:, j("LeftUpLeg")] - positions[:, j("RightUpLeg")]
              + positions[:, j("LeftArm")] - positions[:, j("RightArm")])
    forward = np.stack([-across[:, 2], across[:, 0]], axis=1)  # across × up, on the ground (x, z)
    forward = smooth(forward / np.linalg.norm(forward, axis=1, keepdims=True), SMOOTH_SIGMA * fps)
    heading = np.arctan2(forward[:, 0], forward[:, 1])
    xz = smooth(positions[:, 0, [0, 2]], SMOOTH_SIGMA * fps)
    return xz, heading


def to_local(positions: np.ndarray, xz: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """World positions (frames, joints, 3) in each frame's ground facing frame (x left, y up, z forward)."""
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    dx, dz = positions[..., 0] - xz[:, None, 0], positions[..., 2] - xz[:, None, 1]
    return np.stack([c * dx - s * dz, positions[..., 1], s * dx + c * dz], axis=-1)


def to_world(local: np.ndarray, xz: np.ndarray, heading: np.ndarray) -> np.ndarray:
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    lx, lz = local[..., 0], local[..., 2]
    return np.stack([c * lx + s * lz + xz[:, None, 0], local[..., 1], -s * lx + c * lz + xz[:, None, 1]], axis=-1)


def motion_rows(positions: np.ndarray, contacts: np.ndarray, fps: float = FPS) -> np.ndarray:
    """Rows (frames, ROW_DIM) of a clip's world positions (frames, joints, 3) and contacts (frames, 2)."""
    xz, heading = ground_frame(positions, fps)
    local = to_local(positions, xz, heading).reshape(len(positions), -1)
    control = control_from_trajectory(xz, heading, fps)
    return np.concatenate([local, control, contacts.astype(np.float64)], axis=1)


def rows_to_world(rows: np.ndarray, fps: float = FPS, start_xz=(0.0, 0.0), start_heading: float = 0.0) -> np.ndarray:
    """World positions (frames, joints, 3) of rows: the root moves by the rows' own control signal."""
    xz, heading = integrate_control(rows[:, CONTROL_SLICE], fps, start_xz, start_heading)
    return to_world(rows[:, :POSITION_DIM].reshape(len(rows), -1, 3), xz, heading)


@dataclass
class RowClip:
    file: str
    category: str
    rows: np.ndarray       # (frames, ROW_DIM), not normalised
    positions: np.ndarray  # (frames, joints, 3) world


def clip_variants(clip: LocomotionClip, augment: bool):
    """(root, rotations, contacts) of the clip, and with `augment` its mirrored and speed-changed copies."""
    if not augment:
        yield clip.root, clip.rotations, clip.contacts
        return
    for factor in SPEED_FACTORS:
        root, rot, con = change_speed(clip, factor)
        yield root, rot, con
        yield mirror_clip(root, rot, con)


def row_clips(clips: list[LocomotionClip], augment: bool) -> list[RowClip]:
    skel = canonical_skeleton()
    out = []
    for c in clips:
        for root, rot, con in clip_variants(c, augment):
            pos = forward_kinematics(skel, root, rot)
            out.append(RowClip(c.file, c.category, motion_rows(pos, con), pos))
    return out


class WindowCorpus:
    """Normalised rows of the training clips (augmented) and the held-out clips, with window sampling."""

    def __init__(self, clips: list[LocomotionClip]):
        self.train_clips = row_clips([c for c in clips if not is_validation(c)], augment=True)
        self.valid_clips = row_clips([c for c in clips if is_validation(c)], augment=False)
        allx = np.concatenate([c.rows for c in self.train_clips])
        self.mean = allx.mean(axis=0)
        self.std = allx.std(axis=0)
        self.std[:POSITION_DIM] = np.maximum(self.std[:POSITION_DIM], POSITION_STD_FLOOR)
        self.std[POSITION_DIM:] = np.maximum(self.std[POSITION_DIM:], 1e-2)
        self.train = [self.normalise(c.rows) for c in self.train_clips]
        self.valid = [self.normalise(c.rows) for c in self.valid_clips]
        lengths = np.array([len(s) for s in self.train], dtype=np.float64)
        run = np.array([RUN_WEIGHT if c.category == "run" else 1.0 for c in self.train_clips])
        self.weights = lengths * run / (lengths * run).sum()
        self.train_frames = int(lengths.sum())
        self.valid_files = sorted({c.file for c in self.valid_clips})

    def normalise(self, rows: np.ndarray) -> np.ndarray:
        return ((rows - self.mean) / self.std).astype(np.float32)

    def denormalise(self, x: np.ndarray) -> np.ndarray:
        return x.astype(np.float64) * self.std + self.mean

    def batch(self, rng: np.random.Generator, size: int, length: int = WINDOW) -> torch.Tensor:
        """(size, length, ROW_DIM) training windows; clips shorter than `length` are edge-padded."""
        out = np.empty((size, length, ROW_DIM), np.float32)
        for i, k in enumerate(rng.choice(len(self.train), size=size, p=self.weights)):
            out[i] = window_at(self.train[k], int(rng.integers(0, max(1, len(self.train[k]) - length + 1))), length)
        return torch.from_numpy(out)

    def valid_windows(self, length: int = WINDOW, stride: int = WINDOW // 2) -> np.ndarray:
        """Every held-out window of `length` frames at `stride` (whole clips only; no clip joined to another)."""
        out = [s[i:i + length] for s in self.valid for i in range(0, len(s) - length + 1, stride)]
        return np.stack(out)


def window_at(seq: np.ndarray, start: int, length: int) -> np.ndarray:
    w = seq[start:start + length]
    if len(w) < length:
        w = np.concatenate([w, np.repeat(w[-1:], length - len(w), 0)])
    return w
