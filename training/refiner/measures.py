"""Measures of the refiner report: end-effector speeds, pooled skating, and the classifier two-sample tests
(a window classifier and a single-frame one, trained from scratch to tell real motion from generated)."""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from .. import metrics
from ..generator.shipped import DecodedMotion
from ..mocap.rotations import axis_rotation

WINDOW, STRIDE = 32, 8
SPEED_POINTS = {"toes": ("LeftToeBase", "RightToeBase"), "hands": ("LeftHand", "RightHand"), "head": ("Head_end",)}


def point_speeds(positions: np.ndarray, fps: float, skel) -> dict[str, np.ndarray]:
    return {k: np.concatenate([np.linalg.norm(np.diff(positions[:, skel.index(n)], axis=0), axis=-1) * fps for n in names])
            for k, names in SPEED_POINTS.items()}


def classifier_frames(positions: np.ndarray, yaw: np.ndarray, contacts: np.ndarray, fps: float) -> np.ndarray:
    """Per-frame classifier input (T - 1, 6J + 2): all joints in the root frame (relative to the root's ground
    point, heading removed), their world velocities in the same frame, and the contact bits."""
    back = axis_rotation("y", -yaw)  # R_y(yaw)^T
    ground = positions[:, :1] * np.array([1.0, 0.0, 1.0])
    local = np.einsum("fij,fkj->fki", back, positions - ground)
    vel = np.einsum("fij,fkj->fki", back[1:], np.diff(positions, axis=0)) * fps
    return np.concatenate([local[1:].reshape(len(vel), -1), vel.reshape(len(vel), -1), contacts[1:].astype(np.float64)], axis=1)


def windows(seqs: list[np.ndarray]) -> np.ndarray:
    return metrics.windows_of(seqs, WINDOW, STRIDE).astype(np.float32)


def motion_windows(seqs: list[DecodedMotion], fps: float) -> np.ndarray:
    """Classifier windows of decoded streams or clips."""
    return windows([classifier_frames(s.positions, s.yaw, s.contacts, fps) for s in seqs])


class WindowClassifier(nn.Module):
    def __init__(self, inputs: int, width: int = 64):
        super().__init__()
        self.net = nn.Sequential(nn.Conv1d(inputs, width, 5, padding=2), nn.ReLU(), nn.Conv1d(width, width, 5, padding=2),
                                 nn.ReLU(), nn.Conv1d(width, width, 5, padding=2, stride=2), nn.ReLU())
        self.out = nn.Linear(width, 1)

    def forward(self, w):  # (B, T, F) -> logits (B,)
        return self.out(self.net(w.transpose(1, 2)).mean(-1)).squeeze(-1)


def with_accelerations(w: np.ndarray, fps: float) -> np.ndarray:
    """Classifier windows (B, T, 6J + 2) with each frame's joint accelerations appended (the change of the velocity
    block to the next frame, x fps): (B, T - 1, 9J + 2)."""
    joints = (w.shape[-1] - 2) // 6
    vel = w[..., 3 * joints:6 * joints]
    return np.concatenate([w[:, 1:], np.diff(vel, axis=1) * fps], axis=-1).astype(np.float32)


# The stronger classifier: the window classifier twice as wide, trained twice as long, on the windows with the
# joints' accelerations added.
STRONG = {"width": 128, "steps": 3000}


def two_sample_accuracy(real_train, fake_train, real_test, fake_test, seed: int, steps: int | None = None,
                        kind: str = "window", fps: float = 30.0) -> dict:
    """Train a fresh classifier (balanced batches, Adam) and return its balanced accuracy on the test windows.
    kind: "window" (1-D convolutions over the window), "frame" (an MLP on its first frame) or "strong"
    (STRONG: the window classifier, wider and longer trained, with accelerations). `steps` defaults to 1,500, or
    STRONG's for the stronger one."""
    if kind == "strong":
        real_train, fake_train, real_test, fake_test = (with_accelerations(w, fps) for w in (real_train, fake_train, real_test, fake_test))
    steps = steps or (STRONG["steps"] if kind == "strong" else 1500)
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    mu = real_train.reshape(-1, real_train.shape[-1]).mean(0)
    sd = np.maximum(real_train.reshape(-1, real_train.shape[-1]).std(0), 1e-3)
    norm = lambda w: torch.from_numpy(((w - mu) / sd).astype(np.float32))
    rt, ft, rv, fv = norm(real_train), norm(fake_train), norm(real_test), norm(fake_test)
    model = {"window": lambda n: WindowClassifier(n), "frame": lambda n: FrameClassifier(n),
             "strong": lambda n: WindowClassifier(n, STRONG["width"])}[kind](rt.shape[-1])
    opt = torch.optim.Adam(model.parameters(), lr=1e-3, weight_decay=1e-4)
    loss_fn = nn.BCEWithLogitsLoss()
    for _ in range(steps):
        a, b = rng.integers(0, len(rt), 32), rng.integers(0, len(ft), 32)
        logits = model(torch.cat([rt[a], ft[b]]))
        loss = loss_fn(logits, torch.cat([torch.ones(32), torch.zeros(32)]))
        opt.zero_grad()
        loss.backward()
        opt.step()
    model.eval()
    with torch.no_grad():
        acc_real = float((model(rv) > 0).float().mean())
        acc_fake = float((model(fv) <= 0).float().mean())
    return {"balanced_accuracy": 0.5 * (acc_real + acc_fake), "real_correct": acc_real, "generated_correct": acc_fake}


class FrameClassifier(nn.Module):
    """The single-frame protocol: an MLP over one frame's classifier features (pose, velocities, contacts)."""

    def __init__(self, inputs: int, width: int = 64):
        super().__init__()
        self.net = nn.Sequential(nn.Linear(inputs, width), nn.ReLU(), nn.Linear(width, 1))

    def forward(self, w):  # (B, T, F) -> logits (B,), from the window's first frame
        return self.net(w[:, 0]).squeeze(-1)


def variant_measures(seqs: list[DecodedMotion], fps: float, skel, real_speeds: dict | None) -> tuple[dict, dict, np.ndarray]:
    """Skating, contact share and end-effector speeds pooled over `seqs`; with real_speeds, the W1 distances to them."""
    planted = np.concatenate([metrics.planted_toe_speeds(s.positions, s.contacts, fps, skel) for s in seqs])
    speeds = {k: np.concatenate([point_speeds(s.positions, fps, skel)[k] for s in seqs]) for k in SPEED_POINTS}
    low = np.concatenate([metrics.low_foot_speeds(s.positions, fps, skel) for s in seqs])
    m = {"foot_skating": float(planted.mean()), "planted_toe_speed_p90": float(np.percentile(planted, 90)),
         "planted_pairs": int(len(planted)), "low_foot_sliding": float(low.mean()), "low_foot_pairs": int(len(low)),
         "contact_share": np.concatenate([s.contacts for s in seqs]).mean(0).tolist(),
         "speeds": {k: metrics.summary(v) for k, v in speeds.items()}}
    if real_speeds is not None:
        m["speed_wasserstein"] = {k: metrics.wasserstein_1d(speeds[k], real_speeds[k]) for k in SPEED_POINTS}
    return m, speeds, planted


# Which features give generated motion away: the classifier windows' column groups (6J + 2 columns per frame).
def feature_groups(columns: int) -> dict[str, slice]:
    joints = (columns - 2) // 6
    return {"pose": slice(0, 3 * joints), "velocities": slice(3 * joints, 6 * joints), "contacts": slice(6 * joints, columns)}


def feature_group_accuracies(real_train: np.ndarray, fake_train: np.ndarray, real_test: np.ndarray, fake_test: np.ndarray,
                             seed: int = 0) -> dict:
    """Balanced accuracy of the window and single-frame classifiers given one feature group at a time."""
    out = {}
    for name, cols in feature_groups(real_train.shape[-1]).items():
        out[name] = {kind: two_sample_accuracy(real_train[..., cols], fake_train[..., cols], real_test[..., cols],
                                               fake_test[..., cols], seed, kind=kind)["balanced_accuracy"]
                     for kind in ("window", "frame")}
    return out
