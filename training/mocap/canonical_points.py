"""Any humanoid clip on the canonical skeleton: the humanoid mapper's points (humanoid.py), the points a skeleton lacks
derived from the others, scaled by leg length, resampled to the model's rate, turned into rotations by inverse
kinematics (canonical_ik.py), put on the floor, with foot contacts. Used for a user's folder (training.own) and for
the Bandai Namco set (training/data/bandai.py).

The derived points are the page's rule (web/motion/skeletonMap.ts toCanonical, the Python twin here; the fixture
tests/fixtures/own_canonical.json, python -m training.fixtures.own_canonical, holds this module's answers for the
page's parity test): spine and neck points at fractions between the hips, neck base and head, toe and hand tips beyond
the toe base and wrist, and for a skeleton without toes a toe base ahead of the ankle along the hips' facing.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..paths import MODELS_DIR
from . import bvh
from .canonical_ik import CanonicalIK, local_rotations
from .contacts import contacts_for
from .humanoid import CANONICAL_JOINTS, HumanoidMap, map_humanoid
from .resample import resample_times
from .retarget import CanonicalClip, put_on_floor
from .rotations import matrix_to_quat, quat_to_matrix
from .skeleton import FOOT_POINTS, Skeleton, canonical_skeleton, forward_kinematics_matrices


@dataclass
class RawClip:
    """A clip as a reader gives it: joint names, parents and world positions."""
    name: str  # the file, relative to the data folder
    fps: float
    joints: list[str]
    parents: list[int]
    positions: np.ndarray  # (frames, joints, 3) world, the file's units, y up

    @property
    def seconds(self) -> float:
        return len(self.positions) / self.fps


def read_bvh(path: Path, name: str) -> RawClip:
    """A BVH file (plain or gzipped) as a RawClip; End Sites are points too (a toe or head tip), named <joint>_end."""
    clip = bvh.load_bvh(path)
    _, positions = bvh.global_transforms(clip)
    joints = [f"{clip.joints[j.parent].name}_end" if j.end_site else j.name for j in clip.joints]
    return RawClip(name, clip.fps, joints, [j.parent for j in clip.joints], positions)


# Points placed from others when a skeleton lacks them: at t along from → to (t > 1 beyond `to`); skeletonMap.ts DERIVED.
DERIVED = {
    "Spine": ("Hips", "Neck", 0.33), "Spine1": ("Hips", "Neck", 0.66), "Neck1": ("Neck", "Head", 0.5),
    "Head_end": ("Neck", "Head", 1.5),
    "LeftToeBase_end": ("LeftFoot", "LeftToeBase", 1.5), "RightToeBase_end": ("RightFoot", "RightToeBase", 1.5),
    "LeftHand_end": ("LeftForeArm", "LeftHand", 1.3), "RightHand_end": ("RightForeArm", "RightHand", 1.3),
}
# The toe base of a skeleton without toes (canonical metres): ahead of the ankle and below it, as on the canonical skeleton.
TOE_FORWARD = 0.114
TOE_DOWN = 0.029


@dataclass
class Mapping:
    """How one file's skeleton becomes the canonical points."""
    humanoid: HumanoidMap
    scale: float  # canonical leg length / the file's (hip → knee → ankle), per file unit

    @property
    def scheme(self) -> str:
        return self.humanoid.scheme or "no naming scheme (by proportions)"


def map_skeleton(raw: RawClip, canonical_leg_length: float) -> Mapping:
    """The mapping of a clip's skeleton; raises SkeletonMapError (the mapper's message) for a non-humanoid one."""
    found = map_humanoid(raw.joints, raw.parents, raw.positions)
    idx = {name: found.source[CANONICAL_JOINTS.index(name)] for name in CANONICAL_JOINTS}
    legs = [np.linalg.norm(raw.positions[:, idx[f"{s}UpLeg"]] - raw.positions[:, idx[f"{s}Leg"]], axis=-1)
            + np.linalg.norm(raw.positions[:, idx[f"{s}Leg"]] - raw.positions[:, idx[f"{s}Foot"]], axis=-1)
            for s in ("Left", "Right")]
    length = float(np.mean(legs))
    if not length > 1e-6:
        raise ValueError("its legs have no length")
    return Mapping(found, canonical_leg_length / length)


def to_canonical(positions: np.ndarray, source: list[int], scale: float) -> np.ndarray:
    """The canonical points (frames, 25, 3) of positions (frames, joints, 3) in file units: mapped points scaled,
    the others derived (toCanonical in web/motion/skeletonMap.ts)."""
    frames = len(positions)
    out = np.zeros((frames, len(CANONICAL_JOINTS), 3))
    at = CANONICAL_JOINTS.index
    for k, j in enumerate(source):
        if j >= 0:
            out[:, k] = positions[:, j] * scale
    for side in ("Left", "Right"):
        toe = at(f"{side}ToeBase")
        if source[toe] >= 0:
            continue
        left = out[:, at("LeftUpLeg")] - out[:, at("RightUpLeg")]
        lx, lz = left[:, 0], left[:, 2]
        n = np.hypot(lx, lz)
        n = np.where(n > 0, n, 1.0)
        ankle = out[:, at(f"{side}Foot")]
        out[:, toe] = ankle + np.stack([-lz / n * TOE_FORWARD, np.full(frames, -TOE_DOWN), lx / n * TOE_FORWARD], axis=1)
    for k, point in enumerate(CANONICAL_JOINTS):
        if point in DERIVED and source[k] < 0:
            a, b, t = DERIVED[point]
            out[:, k] = out[:, at(a)] + t * (out[:, at(b)] - out[:, at(a)])
    return out


def resample_points(points: np.ndarray, src_fps: float, fps: float) -> np.ndarray:
    """Points (frames, joints, 3) at `fps`, linearly interpolated, covering the clip's duration."""
    if abs(src_fps - fps) < 1e-3:
        return points
    t = resample_times(len(points), src_fps, fps)
    i0 = np.minimum(np.floor(t).astype(int), len(points) - 1)
    i1 = np.minimum(i0 + 1, len(points) - 1)
    w = (t - i0)[:, None, None]
    return points[i0] * (1 - w) + points[i1] * w


def ik_prior(models_dir: Path = MODELS_DIR) -> tuple[np.ndarray, np.ndarray]:
    """The IK's prior: the shipped generator's reference rotations (the CMU corpus's mean local rotation per joint of
    the canonical skeleton) and the spread of its rotation features (generator.json's normalisation std)."""
    info = json.loads((models_dir / "generator.json").read_text())
    refs = quat_to_matrix(np.array(info["features"]["references"], np.float64))
    std = np.array(info["normalisation"]["std"], np.float64)
    sigma = np.ones((len(refs), 3))
    for k, j in enumerate(info["features"]["joints"]):
        sigma[j] = std[7 + 3 * k: 10 + 3 * k]
    return refs, sigma


@dataclass
class MappedClip:
    """A clip on the canonical skeleton at the model's rate."""
    name: str  # the file, relative to the data folder
    source_fps: float
    root: np.ndarray       # (frames, 3) metres
    rotations: np.ndarray  # (frames, joints, 4) local quaternions
    positions: np.ndarray  # (frames, joints, 3) metres, feet on the floor (canonical bone lengths)
    contacts: np.ndarray   # (frames, 2)

    @property
    def frames(self) -> int:
        return len(self.root)


def canonical_clip(raw: RawClip, mapping: Mapping, fps: float, ik: CanonicalIK, skel: Skeleton) -> MappedClip:
    points = resample_points(to_canonical(raw.positions, mapping.humanoid.source, mapping.scale), raw.fps, fps)
    local = local_rotations(ik.solve(points), skel.parents)
    root = points[:, 0].copy()
    clip = CanonicalClip(raw.name, fps, root, matrix_to_quat(local), forward_kinematics_matrices(skel, root, local))
    clip = put_on_floor(clip, skel)
    contacts = contacts_for(clip.positions, skel.joints, fps, FOOT_POINTS)
    return MappedClip(raw.name, raw.fps, clip.root, clip.rotations, clip.positions, contacts)


def make_ik(skel: Skeleton | None = None) -> CanonicalIK:
    refs, sigma = ik_prior()
    return CanonicalIK(skel or canonical_skeleton(), refs, sigma)

