"""Per-frame motion features for the locomotion generator (Wang, Chai, Xia eq. 3), and back.

x_t = [Δtx, Δtz, Δry, ty, root tilt (3), joint rotations (3 per joint), contact left, contact right]

- Δtx, Δtz: root displacement since the previous frame, in the previous frame's heading frame.
- Δry: change of heading (yaw about +y; heading 0 faces +z, π/2 faces +x).
- ty: root height above the floor.
- Root tilt and joint rotations are rotation vectors (axis × angle) of each rotation relative to a
  fixed reference rotation per joint (its mean over the training data). Human joints stay far from
  180° away from their mean, so this representation has no wrap-around jumps, unlike Euler angles;
  wraparound_report measures that claim on the corpus (in the generator report).
"""
from __future__ import annotations

import numpy as np

from ..mocap.rotations import axis_rotation, matrix_to_rotvec, quat_to_matrix
from ..mocap.skeleton import FIXED_JOINTS, Skeleton, canonical_skeleton, forward_kinematics_matrices


def feature_joints(skel: Skeleton) -> list[int]:
    return [j for j, p in enumerate(skel.parents) if p >= 0 and skel.joints[j] not in FIXED_JOINTS]


def feature_names(skel: Skeleton) -> list[str]:
    names = ["root.dtx", "root.dtz", "root.dry", "root.ty", "root.tilt.x", "root.tilt.y", "root.tilt.z"]
    for j in feature_joints(skel):
        names += [f"{skel.joints[j]}.{a}" for a in "xyz"]
    return names + ["contact.left", "contact.right"]


# ---- rotation vectors -------------------------------------------------------------------------

def rotvec_to_matrix(v: np.ndarray) -> np.ndarray:
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    half = angle / 2
    scale = np.where(angle > 1e-9, np.sin(half) / np.maximum(angle, 1e-12), 0.5)
    q = np.concatenate([v * scale, np.cos(half)], axis=-1)
    return quat_to_matrix(q)


def mean_rotation(m: np.ndarray) -> np.ndarray:
    """Chordal mean of rotation matrices (..., 3, 3) over the first axis."""
    u, _, vt = np.linalg.svd(m.mean(axis=0))
    r = u @ vt
    if np.linalg.det(r) < 0:
        u[:, -1] *= -1
        r = u @ vt
    return r


# ---- heading ------------------------------------------------------------------------------------

def heading_of(root_rot: np.ndarray) -> np.ndarray:
    """Yaw (frames,) of the pelvis's forward (+z) direction projected on the ground."""
    fwd = root_rot[..., :, 2]
    return np.arctan2(fwd[..., 0], fwd[..., 2])


def wrap_angle(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


# ---- encode / decode ----------------------------------------------------------------------------

class FeatureCodec:
    """Converts between clips (root positions, local rotations, contacts) and feature rows."""

    def __init__(self, skel: Skeleton | None = None, references: np.ndarray | None = None):
        self.skel = skel or canonical_skeleton()
        self.joints = feature_joints(self.skel)
        # references[0] is the root tilt's reference, references[j] joint j's (fixed joints sit there)
        self.references = references if references is not None else np.tile(np.eye(3), (len(self.skel.joints), 1, 1))
        self.dim = 7 + 3 * len(self.joints) + 2

    def fit_references(self, rotations: np.ndarray) -> None:
        """Set each joint's reference to its mean local rotation in (frames, joints, 4) quaternions."""
        mats = quat_to_matrix(rotations)
        refs = [mean_rotation(self._tilt(mats[:, 0]))] + [mean_rotation(mats[:, j]) for j in range(1, mats.shape[1])]
        self.references = np.stack(refs)

    def _tilt(self, root_rot: np.ndarray) -> np.ndarray:
        yaw = heading_of(root_rot)
        return np.swapaxes(axis_rotation("y", yaw), -1, -2) @ root_rot

    def encode(self, root: np.ndarray, rotations: np.ndarray, contacts: np.ndarray) -> np.ndarray:
        """Features (frames - 1, dim) for frames 1..n-1 of one clip."""
        mats = quat_to_matrix(rotations)
        yaw = heading_of(mats[:, 0])
        delta = root[1:] - root[:-1]
        back = np.swapaxes(axis_rotation("y", yaw[:-1]), -1, -2)
        local = np.einsum("fij,fj->fi", back, delta)
        dry = wrap_angle(yaw[1:] - yaw[:-1])
        tilt = self._tilt(mats[1:, 0])
        cols = [local[:, [0]], local[:, [2]], dry[:, None], root[1:, [1]],
                matrix_to_rotvec(np.swapaxes(self.references[0], -1, -2) @ tilt)]
        for j in self.joints:
            cols.append(matrix_to_rotvec(np.swapaxes(self.references[j], -1, -2) @ mats[1:, j]))
        cols.append(contacts[1:].astype(np.float64))
        return np.concatenate(cols, axis=1)

    def decode(self, features: np.ndarray, start_xz=(0.0, 0.0), start_heading: float = 0.0):
        """Root positions (frames, 3), local rotation matrices (frames, joints, 3, 3), contacts (frames, 2)."""
        frames = len(features)
        yaw = start_heading + np.cumsum(features[:, 2])
        prev_yaw = np.concatenate([[start_heading], yaw[:-1]])
        step = np.stack([features[:, 0], np.zeros(frames), features[:, 1]], axis=1)
        world_step = np.einsum("fij,fj->fi", axis_rotation("y", prev_yaw), step)
        root = np.cumsum(world_step, axis=0) + [start_xz[0], 0.0, start_xz[1]]
        root[:, 1] = features[:, 3]
        local = np.repeat(self.references[None], frames, axis=0)  # fixed joints stay at their reference
        tilt = self.references[0] @ rotvec_to_matrix(features[:, 4:7])
        local[:, 0] = axis_rotation("y", yaw) @ tilt
        for k, j in enumerate(self.joints):
            local[:, j] = self.references[j] @ rotvec_to_matrix(features[:, 7 + 3 * k: 10 + 3 * k])
        contacts = (features[:, -2:] > 0.5).astype(np.uint8)
        return root, local, contacts

    def positions(self, features: np.ndarray, **kw) -> np.ndarray:
        root, local, _ = self.decode(features, **kw)
        return forward_kinematics_matrices(self.skel, root, local)


def mirror_clip(root: np.ndarray, rotations: np.ndarray, contacts: np.ndarray, skel: Skeleton | None = None):
    """Left/right mirror image (x -> -x) of a clip on the symmetric canonical skeleton."""
    skel = skel or canonical_skeleton()
    q = rotations[:, skel.mirror_map] * np.array([1.0, -1.0, -1.0, 1.0])
    return root * np.array([-1.0, 1.0, 1.0]), q, contacts[:, ::-1].copy()


def wraparound_report(rotations: np.ndarray, clip_starts: list[int], small_turn: float = 0.2) -> dict:
    """Wrap-around check: the largest jump in each representation between consecutive frames (same clip)
    whose true rotation changes by less than `small_turn` radians. A jump there is an artefact of the
    representation, not of the motion."""
    from ..mocap.rotations import matrix_to_euler_zyx

    codec = FeatureCodec()
    codec.fit_references(rotations)
    mats = quat_to_matrix(rotations[:, codec.joints])
    euler = matrix_to_euler_zyx(mats)
    rv = matrix_to_rotvec(np.swapaxes(codec.references[codec.joints], -1, -2)[None] @ mats)
    same_clip = np.ones(len(rotations) - 1, dtype=bool)
    same_clip[[s - 1 for s in clip_starts if s > 0]] = False
    true_turn = np.linalg.norm(matrix_to_rotvec(np.swapaxes(mats[:-1], -1, -2) @ mats[1:]), axis=-1)
    smooth = (true_turn < small_turn) & same_clip[:, None]
    jump = lambda a: float(np.linalg.norm(np.diff(a, axis=0), axis=-1)[smooth].max())
    return {"pairs_checked": int(smooth.sum()), "small_turn_rad": small_turn,
            "euler_zyx_max_jump": jump(euler), "rotvec_max_jump": jump(rv),
            "rotvec_max_angle_from_reference": float(np.linalg.norm(rv, axis=-1).max())}
