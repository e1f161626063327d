"""Inverse kinematics of canonical points onto the canonical skeleton's rotations: the Python port of the page's
CanonicalIK (web/model/featureEncode.ts), vectorised over frames.

Rotations follow the canonical skeleton's bone-end convention (training/mocap/skeleton.py): the world rotation G_j at
point j turns the segment that ends at j, p_j = p_parent + G_j · offset_j, G_j = G_parent · L_j. Points fix each
segment's direction but not its twist about itself. The twist is the one that makes the joint's own local rotation
and its children's most likely under a prior (each joint's reference rotation, with the spread of the generator's
normalisation): the knee's plane sets the thigh's twist, the shoulders the chest's. Fixed joints (pelvis to hip, the
hand segments) stay at their reference, as in training.

One difference from the page: the page scans the whole turn on a stream's first frame only and then searches near the
last frame's twist; here every frame gets the whole scan (frames are solved together), then the same golden-section
refinement. Used by training.own (a user's folder) and training/data/bandai.py (the Bandai Namco set).
tests/python/test_own.py checks the rows it gives against tests/fixtures/feature_encoding.json within the
tolerances the page's IK is held to.
"""
from __future__ import annotations

import numpy as np

from .rotations import matrix_to_rotvec
from .skeleton import FIXED_JOINTS, Skeleton

TWIST_SCAN = np.pi / 12  # coarse scan step (rad), as on the page
GOLDEN_STEPS = 16
FIXED_CHILD_SIGMA = 0.1  # rad: a fixed child's direction error in the twist cost


def _normalise(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > 1e-12, v / np.maximum(n, 1e-12), 0.0)


def _axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about unit `axis` (..., 3) by `angle` (...)."""
    x, y, z = axis[..., 0], axis[..., 1], axis[..., 2]
    c, s = np.cos(angle), np.sin(angle)
    t = 1 - c
    rows = [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def swing(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The shortest rotation (..., 3, 3) taking direction a onto direction b (identity where either is zero)."""
    a, b = _normalise(a), _normalise(b)
    c = np.sum(a * b, axis=-1)
    axis = np.cross(a, b)
    s = np.linalg.norm(axis, axis=-1)
    # Opposite directions: half a turn about any axis square to a.
    other = np.where(np.abs(a[..., :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
    axis = np.where((s < 1e-9)[..., None], np.cross(a, other), axis)
    angle = np.arctan2(s, c)
    return _axis_angle(_normalise(axis), angle)


def best_rotation(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """The rotation (frames, 3, 3) taking the directions src (k, 3) closest onto dst (frames, k, 3) (Kabsch)."""
    h = np.einsum("ki,fkj->fij", src, dst)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.swapaxes(vt, -1, -2) @ np.swapaxes(u, -1, -2)))
    fix = np.broadcast_to(np.eye(3), h.shape).copy()
    fix[:, 2, 2] = d
    return np.swapaxes(vt, -1, -2) @ fix @ np.swapaxes(u, -1, -2)


class CanonicalIK:
    """World rotations of canonical points; `references` (joints, 3, 3): each joint's reference local rotation
    ([0] the root tilt's), `sigma` (joints, 3): the spread of each feature joint's rotation vector."""

    def __init__(self, skel: Skeleton, references: np.ndarray, sigma: np.ndarray):
        self.skel = skel
        self.refs = references
        self.sigma = sigma
        self.fixed = {skel.index(n) for n in FIXED_JOINTS}
        self.children = [[k for k, p in enumerate(skel.parents) if p == j] for j in range(len(skel.parents))]

    def _zscore(self, j: int, local: np.ndarray) -> np.ndarray:
        v = matrix_to_rotvec(self.refs[j].T @ local)
        return np.sum((v / self.sigma[j]) ** 2, axis=-1)

    def _cost(self, j: int, parent_world: np.ndarray, g: np.ndarray, points: np.ndarray) -> np.ndarray:
        offsets = self.skel.offsets
        total = self._zscore(j, np.swapaxes(parent_world, -1, -2) @ g)
        for k in self.children[j]:
            rest = g @ self.refs[k]
            predicted = rest @ offsets[k]
            observed = points[:, k] - points[:, j]
            if k in self.fixed:
                cos = np.clip(np.sum(_normalise(predicted) * _normalise(observed), axis=-1), -1, 1)
                total = total + (np.arccos(cos) / FIXED_CHILD_SIGMA) ** 2
            else:
                local = np.swapaxes(g, -1, -2) @ swing(predicted, observed) @ rest
                total = total + self._zscore(k, local)
        return total

    def solve(self, points: np.ndarray) -> np.ndarray:
        """World rotations (frames, joints, 3, 3) of points (frames, joints, 3)."""
        skel, refs = self.skel, self.refs
        frames, joints = points.shape[:2]
        world = np.zeros((frames, joints, 3, 3))
        kids = self.children[0]
        src = _normalise(np.stack([refs[c] @ skel.offsets[c] for c in kids]))
        world[:, 0] = best_rotation(src, _normalise(points[:, kids] - points[:, :1]))
        for j in range(1, joints):
            p = skel.parents[j]
            parent = world[:, p]
            g = parent @ refs[j]
            if j not in self.fixed:
                d = points[:, j] - points[:, p]
                g = swing(g @ skel.offsets[j], d) @ g
                g = self._best_twist(j, _normalise(d), g, parent, points)
            world[:, j] = g
        return world

    def _best_twist(self, j: int, axis: np.ndarray, g: np.ndarray, parent: np.ndarray, points: np.ndarray) -> np.ndarray:
        def at(theta: np.ndarray) -> np.ndarray:
            return self._cost(j, parent, _axis_angle(axis, theta) @ g, points)

        frames = len(g)
        best, best_cost = np.zeros(frames), at(np.zeros(frames))
        for theta in np.arange(-np.pi + TWIST_SCAN, np.pi - 1e-9, TWIST_SCAN):
            c = at(np.full(frames, theta))
            better = c < best_cost
            best, best_cost = np.where(better, theta, best), np.where(better, c, best_cost)
        lo, hi = best - TWIST_SCAN, best + TWIST_SCAN
        phi = (np.sqrt(5) - 1) / 2
        a, b = hi - phi * (hi - lo), lo + phi * (hi - lo)
        ca, cb = at(a), at(b)
        for _ in range(GOLDEN_STEPS):
            left = ca < cb
            hi, lo = np.where(left, b, hi), np.where(left, lo, a)
            na, nb = hi - phi * (hi - lo), lo + phi * (hi - lo)
            a_new, b_new = np.where(left, na, b), np.where(left, a, nb)
            # One new cost per frame and step: where the left half was kept, a is new; else b.
            fresh = at(np.where(left, a_new, b_new))
            ca, cb = np.where(left, fresh, cb), np.where(left, ca, fresh)
            a, b = a_new, b_new
        theta = np.where(ca < cb, a, b)
        return _axis_angle(axis, theta) @ g


def local_rotations(world: np.ndarray, parents: list[int]) -> np.ndarray:
    """Local rotations (frames, joints, 3, 3) of world ones: L_j = G_parent^T G_j."""
    local = world.copy()
    for j, p in enumerate(parents):
        if p >= 0:
            local[:, j] = np.swapaxes(world[:, p], -1, -2) @ world[:, j]
    return local
