"""Adversarial refiner R and discriminator D (Wang, Chai, Xia §4.2, Figs. 4 and 5, eqs. 11 and 12).

R (causal, streams frame by frame right behind the generator):
    R_input = [x, p_end(x), v_end(x)]                                    (eq. 11)
    R(x)    = FC2(LSTM(relu(FC1(R_input)))) + x                          (residual)
x is the generator's normalised feature frame (training/data/features.py, contacts included), so R refines the
contact bits too. FC2 starts at zero, so an untrained R is the identity.

D (sees whole windows, bidirectional):
    d_input = [p_end(x), v_end(x), contacts(x)]                           (eq. 12 plus the contact bits, §4.3)
    optionally + the rest of x (training.refiner.train --d-input pose): D then judges the whole pose, not only the end effectors
    or, with --d-input joints, [p_all, v_all, contacts(x)]: every joint's root-frame position and velocity, what the refiner
    report's two-sample classifiers see (JointFeatures)
    D(x)    = FC2(BiLSTM(relu(FC1(d_input))))   -> one logit per frame

End effectors (END_EFFECTORS: wrists, ankles, toes, top of the head) are expressed in the character's root
frame: positions relative to the root's ground point (x, z) with the heading removed, y = height above the
floor; velocities are world velocities (m/s) expressed in the previous frame's heading frame,
    v_t = fps * ((dtx_t, 0, dtz_t) + R_y(dry_t) q_t - q_{t-1}),
where q_t are the root-frame positions. Both are computed here from the features with a differentiable torch
port of FeatureCodec.decode + forward kinematics (FeatureGeometry), so gradients reach R through them.
"""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from ..data.features import feature_joints
from ..mocap.skeleton import Skeleton, canonical_skeleton

END_EFFECTORS = ("LeftHand", "RightHand", "LeftFoot", "LeftToeBase", "RightFoot", "RightToeBase", "Head_end")


def rotvec_to_matrix(v: torch.Tensor) -> torch.Tensor:
    """Rodrigues' formula, (..., 3) -> (..., 3, 3); smooth and finite at zero (gradients too)."""
    theta2 = (v * v).sum(-1, keepdim=True)
    theta = torch.sqrt(theta2 + 1e-12)
    a = torch.sin(theta) / theta                       # sin(t) / t
    half = torch.sin(0.5 * theta) / theta
    b = 2.0 * half * half                              # (1 - cos t) / t^2, without cancellation
    x, y, z = v[..., 0:1], v[..., 1:2], v[..., 2:3]
    zero = torch.zeros_like(x)
    k = torch.cat([zero, -z, y, z, zero, -x, -y, x, zero], dim=-1).reshape(*v.shape[:-1], 3, 3)
    eye = torch.eye(3, dtype=v.dtype, device=v.device)
    return eye + a.unsqueeze(-1) * k + b.unsqueeze(-1) * (k @ k)


def yaw_matrix(angle: torch.Tensor) -> torch.Tensor:
    """Rotations about +y, (...,) -> (..., 3, 3), same convention as rotations.axis_rotation('y')."""
    c, s = torch.cos(angle), torch.sin(angle)
    one, zero = torch.ones_like(angle), torch.zeros_like(angle)
    return torch.stack([c, zero, s, zero, one, zero, -s, zero, c], dim=-1).reshape(*angle.shape, 3, 3)


class FeatureGeometry(nn.Module):
    """Differentiable decoding of physical feature frames (..., D) into root-frame joint positions,
    end-effector positions/velocities and root trajectories. Mirrors FeatureCodec.decode and
    skeleton.forward_kinematics_matrices (tests/python/test_refiner.py checks it against them)."""

    def __init__(self, references: np.ndarray, skel: Skeleton | None = None, fps: float = 30.0,
                 end_effectors=END_EFFECTORS):
        super().__init__()
        self.skel = skel or canonical_skeleton()
        self.fps = float(fps)
        self.parents = list(self.skel.parents)
        self.joints = feature_joints(self.skel)
        self.dim = 7 + 3 * len(self.joints) + 2
        self.end_index = [self.skel.index(n) for n in end_effectors]
        self.end_names = list(end_effectors)
        # Only the joints on a chain from the root to an end effector are needed.
        needed = set()
        for j in self.end_index:
            while j >= 0:
                needed.add(j)
                j = self.parents[j]
        self.needed = sorted(needed)
        self.register_buffer("references", torch.tensor(np.asarray(references), dtype=torch.float32))
        self.register_buffer("offsets", torch.tensor(self.skel.offsets, dtype=torch.float32))

    def local_rotations(self, f: torch.Tensor) -> dict[int, torch.Tensor]:
        """Local rotation matrices of the needed joints; the root's without heading (reference * exp(tilt))."""
        rots = rotvec_to_matrix(f[..., 7:7 + 3 * len(self.joints)].reshape(*f.shape[:-1], len(self.joints), 3))
        out = {0: self.references[0] @ rotvec_to_matrix(f[..., 4:7])}
        for k, j in enumerate(self.joints):
            if j in self.needed:
                out[j] = self.references[j] @ rots[..., k, :, :]
        for j in self.needed:
            if j not in out:  # fixed joints keep their reference
                out[j] = self.references[j].expand(*f.shape[:-1], 3, 3)
        return out

    def root_frame_positions(self, f: torch.Tensor) -> dict[int, torch.Tensor]:
        """Positions (..., 3) of the needed joints relative to the root's ground point, heading removed."""
        local = self.local_rotations(f)
        zero = torch.zeros_like(f[..., 3:4])
        world, pos = {}, {0: torch.cat([zero, f[..., 3:4], zero], dim=-1)}
        world[0] = local[0]
        for j in self.needed:
            p = self.parents[j]
            if p < 0:
                continue
            world[j] = world[p] @ local[j]
            pos[j] = pos[p] + (world[j] @ self.offsets[j].unsqueeze(-1)).squeeze(-1)
        return pos

    def end_positions(self, f: torch.Tensor) -> torch.Tensor:
        """(..., E, 3) root-frame end-effector positions."""
        pos = self.root_frame_positions(f)
        return torch.stack([pos[j] for j in self.end_index], dim=-2)

    def velocities(self, f: torch.Tensor, q: torch.Tensor, q_prev: torch.Tensor) -> torch.Tensor:
        """World velocities (m/s) in the previous frame's heading frame from this frame's root step and turn."""
        step = torch.stack([f[..., 0], torch.zeros_like(f[..., 0]), f[..., 1]], dim=-1).unsqueeze(-2)
        turned = (yaw_matrix(f[..., 2]).unsqueeze(-3) @ q.unsqueeze(-1)).squeeze(-1)
        return self.fps * (step + turned - q_prev)

    def end_effectors(self, f: torch.Tensor, f_prev: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """f (B, T, D) physical frames and f_prev (B, D) the frame before -> p, v (B, T, E, 3)."""
        q = self.end_positions(torch.cat([f_prev.unsqueeze(1), f], dim=1))
        return q[:, 1:], self.velocities(f, q[:, 1:], q[:, :-1])

    def root_trajectory(self, f: torch.Tensor) -> torch.Tensor:
        """World root positions (B, T, 3) integrated from the window's start (origin, heading 0), as decode()."""
        yaw = torch.cumsum(f[..., 2], dim=-1)
        prev_yaw = yaw - f[..., 2]
        c, s = torch.cos(prev_yaw), torch.sin(prev_yaw)
        dx = c * f[..., 0] + s * f[..., 1]
        dz = -s * f[..., 0] + c * f[..., 1]
        return torch.stack([torch.cumsum(dx, -1), f[..., 3], torch.cumsum(dz, -1)], dim=-1)


class ConvDiscriminator(nn.Module):
    """A window discriminator shaped like the refiner report's two-sample window classifier (three 1-D convolutions of
    kernel 5, the last with stride 2, mean pooling, one logit per window), so D judges windows as the test does."""

    def __init__(self, inputs: int, width: int = 64):
        super().__init__()
        self.net = nn.Sequential(nn.Conv1d(inputs, width, 5, padding=2), nn.LeakyReLU(0.2),
                                 nn.Conv1d(width, width, 5, padding=2), nn.LeakyReLU(0.2),
                                 nn.Conv1d(width, width, 5, padding=2, stride=2), nn.LeakyReLU(0.2))
        self.out = nn.Linear(width, 1)

    def forward(self, d: torch.Tensor) -> torch.Tensor:
        """d (B, T, inputs) -> logits (B, 1) of 'real'."""
        return self.out(self.net(d.transpose(1, 2)).mean(-1))


def straight_through_bits(c: torch.Tensor) -> torch.Tensor:
    """Contact bits (> 0.5) in the forward pass, the identity's gradient in the backward pass: D sees clean
    0/1 bits for real and refined motion alike, and R still gets a gradient for its contact outputs."""
    hard = (c > 0.5).to(c.dtype)
    return hard + c - c.detach()


class Refiner(nn.Module):
    def __init__(self, mean: np.ndarray, std: np.ndarray, references: np.ndarray, hidden: int = 96,
                 end_mean: np.ndarray | None = None, end_std: np.ndarray | None = None, fps: float = 30.0):
        super().__init__()
        self.geometry = FeatureGeometry(references, fps=fps)
        self.dim, self.hidden = len(mean), hidden
        self.ends = len(self.geometry.end_index)
        e = 6 * self.ends
        self.register_buffer("mean", torch.tensor(np.asarray(mean), dtype=torch.float32))
        self.register_buffer("std", torch.tensor(np.asarray(std), dtype=torch.float32))
        self.register_buffer("end_mean", torch.zeros(e) if end_mean is None else torch.tensor(end_mean, dtype=torch.float32))
        self.register_buffer("end_std", torch.ones(e) if end_std is None else torch.tensor(end_std, dtype=torch.float32))
        self.fc1 = nn.Linear(self.dim + e, hidden)
        self.lstm = nn.LSTM(hidden, hidden, batch_first=True)
        self.fc2 = nn.Linear(hidden, self.dim)
        nn.init.zeros_(self.fc2.weight)
        nn.init.zeros_(self.fc2.bias)

    def physical(self, x: torch.Tensor) -> torch.Tensor:
        return x * self.std + self.mean

    def end_features(self, x: torch.Tensor, x_prev: torch.Tensor) -> torch.Tensor:
        """Normalised [p_end, v_end] (B, T, 6E) of normalised frames x (B, T, D) after x_prev (B, D)."""
        f = self.physical(torch.cat([x_prev.unsqueeze(1), x], dim=1))
        q = self.geometry.end_positions(f).flatten(-2)
        return self.end_features_from(x, q[:, 1:], q[:, :-1])

    def end_features_from(self, x: torch.Tensor, q: torch.Tensor, q_prev: torch.Tensor) -> torch.Tensor:
        """The same from root-frame end-effector positions q (..., 3E) of x's frames and q_prev of the frames
        before (metres, as FeatureGeometry.end_positions flattened): what the ONNX step takes as inputs."""
        shape = q.shape[:-1] + (self.ends, 3)
        v = self.geometry.velocities(self.physical(x), q.reshape(shape), q_prev.reshape(shape)).flatten(-2)
        return (torch.cat([q, v], dim=-1) - self.end_mean) / self.end_std

    def forward(self, x: torch.Tensor, x_prev: torch.Tensor, state=None):
        """x (B, T, D) normalised generator frames, x_prev (B, D) the frame before x[:, 0] ->
        refined x (B, T, D) normalised, (h, c) each (1, B, H)."""
        e = self.end_features(x, x_prev)
        y, state = self.lstm(torch.relu(self.fc1(torch.cat([x, e], dim=-1))), state)
        return self.fc2(y) + x, state


class Discriminator(nn.Module):
    def __init__(self, inputs: int, hidden: int = 64):
        super().__init__()
        self.fc1 = nn.Linear(inputs, hidden)
        self.lstm = nn.LSTM(hidden, hidden, batch_first=True, bidirectional=True)
        self.fc2 = nn.Linear(2 * hidden, 1)

    def forward(self, d: torch.Tensor) -> torch.Tensor:
        """d (B, T, inputs) -> logits (B, T) of 'real'."""
        y, _ = self.lstm(torch.relu(self.fc1(d)))
        return self.fc2(y).squeeze(-1)


class JointFeatures(nn.Module):
    """Every joint's root-frame position and its velocity (FeatureGeometry over all joints), normalised by statistics
    of real windows: the per-frame view of the refiner report's two-sample classifiers
    (training/refiner/measures.classifier_frames), so a discriminator on it judges what they judge."""

    def __init__(self, references: np.ndarray, mean: np.ndarray, std: np.ndarray, fps: float = 30.0):
        super().__init__()
        self.geometry = FeatureGeometry(references, fps=fps, end_effectors=tuple(canonical_skeleton().joints))
        self.register_buffer("mean", torch.tensor(np.asarray(mean), dtype=torch.float32))
        self.register_buffer("std", torch.tensor(np.asarray(std), dtype=torch.float32))

    def physical(self, f: torch.Tensor, f_prev: torch.Tensor) -> torch.Tensor:
        """Physical frames f (B, T, D) after f_prev (B, D) -> [p_all, v_all] (B, T, 6J), metres and m/s: positions in
        the frame's root frame, velocities turned from the previous frame's heading frame into this frame's, as
        classifier_frames has them (tests/python/test_refiner.py checks the two agree)."""
        p, v = self.geometry.end_effectors(f, f_prev)
        v = (yaw_matrix(-f[..., 2]).unsqueeze(-3) @ v.unsqueeze(-1)).squeeze(-1)
        return torch.cat([p.flatten(-2), v.flatten(-2)], dim=-1)

    def forward(self, f: torch.Tensor, f_prev: torch.Tensor) -> torch.Tensor:
        return (self.physical(f, f_prev) - self.mean) / self.std


DISCRIMINATOR_INPUTS = ("ends", "pose", "joints")


def discriminator_input(refiner: Refiner, x: torch.Tensor, x_prev: torch.Tensor, kind: str = "ends",
                        joints: JointFeatures | None = None) -> torch.Tensor:
    """D's input for normalised frames x after x_prev. kind "ends": [p_end, v_end (normalised as R's input), contact
    bits] (B, T, 6E + 2), eq. 12 with the contacts of §4.3; "pose": that plus the other features of x (root motion,
    tilt, joint rotations; normalised), (B, T, 6E + 2 + D - 2); "joints": [joints(physical x), contact bits]
    (B, T, 6J + 2), the classifiers' view."""
    bits = straight_through_bits(refiner.physical(x)[..., -2:])
    if kind == "joints":
        return torch.cat([joints(refiner.physical(x), refiner.physical(x_prev)), bits], dim=-1)
    e = refiner.end_features(x, x_prev)
    parts = [e, bits] + ([x[..., :-2]] if kind == "pose" else [])
    return torch.cat(parts, dim=-1)


def discriminator_inputs(refiner: Refiner, kind: str) -> int:
    if kind == "joints":
        return 6 * len(canonical_skeleton().joints) + 2
    return 6 * refiner.ends + 2 + (refiner.dim - 2 if kind == "pose" else 0)


class RefinerStep(nn.Module):
    """One streaming step for ONNX:
    (x (B, D), ends (B, 3E), ends_prev (B, 3E), h (1, B, H), c (1, B, H)) -> (x_refined (B, D), h_out, c_out).

    x is the generator's newest normalised frame (contacts as the generator feeds them back); ends are the
    root-frame positions (metres) of END_EFFECTORS of that raw frame, ends_prev those of the raw frame before
    (the caller keeps them; for the first frame, those of the seed frame). The velocities, the normalisation
    and the rest of R are computed in the graph. The forward kinematics stays outside because a graph of
    per-joint small ops costs more than twice the generator step in onnxruntime (measured: 507 nodes,
    0.82 ms against the generator's 0.36 ms at batch 1), while the caller decodes the frame anyway.
    The LSTM is written out at gate level."""

    def __init__(self, refiner: Refiner):
        super().__init__()
        self.r = refiner

    def forward(self, x, ends, ends_prev, h, c):
        r = self.r
        e = r.end_features_from(x, ends, ends_prev)
        y = torch.relu(r.fc1(torch.cat([x, e], dim=-1)))
        gates = y @ r.lstm.weight_ih_l0.T + h[0] @ r.lstm.weight_hh_l0.T + (r.lstm.bias_ih_l0 + r.lstm.bias_hh_l0)
        i, f, g, o = gates.chunk(4, dim=-1)
        c2 = torch.sigmoid(f) * c[0] + torch.sigmoid(i) * torch.tanh(g)
        h2 = torch.sigmoid(o) * torch.tanh(c2)
        return r.fc2(h2) + x, h2.unsqueeze(0), c2.unsqueeze(0)
