"""Retargeting CMU clips (ASF/AMC or the common BVH conversion) onto the canonical skeleton.

Each canonical segment takes the world rotation of the CMU bone that owns it, corrected by the
fixed rotation between the canonical and the source rest directions, so every segment points
exactly where the source bone points while bone lengths become canonical. Root translation is
scaled by the ratio of leg lengths, and the clip is shifted vertically so the feet meet the floor.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import asf_amc, bvh
from .rotations import matrix_to_quat, rotation_between
from .skeleton import GROUND_POINTS, Skeleton, canonical_skeleton, forward_kinematics_matrices

# CMU ASF bone -> (BVH joint that owns its rotation, BVH joint at the end of the bone) in the common conversion.
CMU_BVH_BONES = {
    "lhipjoint": ("LHipJoint", "LeftUpLeg"), "lfemur": ("LeftUpLeg", "LeftLeg"), "ltibia": ("LeftLeg", "LeftFoot"),
    "lfoot": ("LeftFoot", "LeftToeBase"), "ltoes": ("LeftToeBase", "LeftToeBase_end"),
    "rhipjoint": ("RHipJoint", "RightUpLeg"), "rfemur": ("RightUpLeg", "RightLeg"), "rtibia": ("RightLeg", "RightFoot"),
    "rfoot": ("RightFoot", "RightToeBase"), "rtoes": ("RightToeBase", "RightToeBase_end"),
    "lowerback": ("LowerBack", "Spine"), "upperback": ("Spine", "Spine1"), "thorax": ("Spine1", "Neck"),
    "lowerneck": ("Neck", "Neck1"), "upperneck": ("Neck1", "Head"), "head": ("Head", "Head_end"),
    "lclavicle": ("LeftShoulder", "LeftArm"), "lhumerus": ("LeftArm", "LeftForeArm"), "lradius": ("LeftForeArm", "LeftHand"),
    "lwrist": ("LeftHand", "LeftFingerBase"), "lhand": ("LeftFingerBase", "LeftHandIndex1"),
    "rclavicle": ("RightShoulder", "RightArm"), "rhumerus": ("RightArm", "RightForeArm"), "rradius": ("RightForeArm", "RightHand"),
    "rwrist": ("RightHand", "RightFingerBase"), "rhand": ("RightFingerBase", "RightHandIndex1"),
}


# Canonical segments that keep their rest pose relative to their parent:
# - pelvis to hip joints: no degrees of freedom in CMU; copying each subject's rest correction would give
#   every subject a different fixed hip rotation;
# - hands: CMU hand markers are noisy (the hand bone flips by up to 180 degrees between frames), so the
#   hand continues the forearm (it still turns with the forearm's twist).
RIGID_BONES = ("lhipjoint", "rhipjoint", "lhand", "rhand")


@dataclass
class SourceMotion:
    """A CMU clip as world bone rotations, independent of the file format."""
    name: str
    fps: float
    root: np.ndarray  # (frames, 3) in source units
    rotations: dict[str, np.ndarray]  # ASF bone name (and 'root') -> (frames, 3, 3) world rotation
    rest: dict[str, np.ndarray]  # ASF bone name -> rest vector in source units (may be zero)

    @property
    def leg_length(self) -> float:
        return float(sum(np.linalg.norm(self.rest[b]) for b in ("lfemur", "ltibia", "rfemur", "rtibia")) / 2)


@dataclass
class CanonicalClip:
    name: str
    fps: float
    root: np.ndarray  # (frames, 3) metres
    rotations: np.ndarray  # (frames, joints, 4) local quaternions x, y, z, w
    positions: np.ndarray  # (frames, joints, 3) metres, feet on the floor

    @property
    def frames(self) -> int:
        return self.root.shape[0]


def source_from_amc(asf_path: Path, amc_path: Path, fps: float = 120.0) -> SourceMotion:
    skel = asf_amc.load_asf(asf_path)
    motion = asf_amc.load_amc(amc_path, skel)
    trans, rots = asf_amc.global_rotations(skel, motion)
    rest = {b: skel.rest_vector(b) for b in skel.bones}
    return SourceMotion(Path(amc_path).name, fps, trans, rots, rest)


def source_from_cmu_bvh(path: Path) -> SourceMotion:
    clip = bvh.load_bvh(path)
    # Some conversions begin with placeholder frames (a T-pose with the root exactly at the origin): drop them.
    placeholder = np.all(clip.motion[:, :3] == 0, axis=1)
    first_real = int(np.argmin(placeholder)) if not placeholder.all() else 0
    clip.motion = clip.motion[first_real:]
    rots, pos = bvh.global_transforms(clip)
    missing = [j for pair in CMU_BVH_BONES.values() for j in pair if not _has(clip, j)] + ([] if _has(clip, "Hips") else ["Hips"])
    if missing:
        raise ValueError(f"{path}: not a CMU 31-bone BVH (no joint {missing[0]!r})")
    rotations = {"root": rots[:, clip.index("Hips")]}
    rest = {}
    for bone, (owner, end) in CMU_BVH_BONES.items():
        rotations[bone] = rots[:, clip.index(owner)]
        rest[bone] = clip.joints[clip.index(end)].offset.astype(np.float64)
    return SourceMotion(Path(path).name, clip.fps, pos[:, clip.index("Hips")], rotations, rest)


def _has(clip: bvh.BvhClip, name: str) -> bool:
    return any(j.name == name for j in clip.joints)


def retarget(src: SourceMotion, skel: Skeleton | None = None) -> CanonicalClip:
    skel = skel or canonical_skeleton()
    frames = src.root.shape[0]
    world = np.zeros((frames, len(skel.joints), 3, 3))
    for j, bones in enumerate(skel.source_bones):
        if not bones:
            world[:, j] = src.rotations["root"]
            continue
        if bones[0] in RIGID_BONES:
            world[:, j] = world[:, skel.parents[j]]
            continue
        owner = bones[0]
        rest = src.rest[owner]
        # Correction taking the canonical rest direction onto the source's; undefined for zero-length bones.
        fix = rotation_between(skel.offsets[j], rest) if np.linalg.norm(rest) > 1e-6 else np.eye(3)
        world[:, j] = src.rotations[owner] @ fix
    local = np.zeros_like(world)
    for j, p in enumerate(skel.parents):
        local[:, j] = world[:, j] if p < 0 else np.swapaxes(world[:, p], -1, -2) @ world[:, j]
    root = src.root * (skel.leg_length / src.leg_length)
    positions = forward_kinematics_matrices(skel, root, local)
    clip = CanonicalClip(src.name, src.fps, root, matrix_to_quat(local), positions)
    return put_on_floor(clip, skel)


def floor_samples(positions: np.ndarray, fps: float, skel: Skeleton, window_s: float = 0.5) -> np.ndarray:
    """(x, z, y) of the lowest foot point in each half second: in walking and running a foot is planted there."""
    ground = positions[:, [skel.index(n) for n in GROUND_POINTS]]
    lowest = ground[:, :, 1].argmin(axis=1)
    points = ground[np.arange(len(ground)), lowest]
    step = max(1, int(round(window_s * fps)))
    samples = [points[a + points[a:a + step, 1].argmin()] for a in range(0, len(points), step)]
    return np.array(samples)[:, [0, 2, 1]]


def fit_floor(samples: np.ndarray, prior_span: float = 0.5, above: float = 0.03) -> np.ndarray:
    """Floor plane (a, b, c) with y = a x + b z + c under the samples.

    Mocap floors are often tilted by a degree or so in capture coordinates, enough to put the feet
    5 cm into or above the ground at the far end of a walk. Slopes are shrunk toward zero where the
    samples span little ground, and samples well above the plane (airborne moments) are dropped.
    """
    keep = np.ones(len(samples), dtype=bool)
    plane = np.array([0.0, 0.0, float(np.median(samples[:, 2]))])
    for _ in range(4):
        s = samples[keep]
        centre = s[:, :2].mean(axis=0)
        a = np.c_[s[:, :2] - centre, np.ones(len(s))]
        reg = np.diag([prior_span ** 2 * len(s) * 0.1] * 2 + [0.0])
        coef = np.linalg.solve(a.T @ a + reg, a.T @ s[:, 2])
        plane = np.array([coef[0], coef[1], coef[2] - coef[:2] @ centre])
        residual = samples[:, 2] - (samples[:, :2] @ plane[:2] + plane[2])
        new_keep = residual < above
        if new_keep.sum() < 2 or (new_keep == keep).all():
            break
        keep = new_keep
    return plane


def put_on_floor(clip: CanonicalClip, skel: Skeleton | None = None) -> CanonicalClip:
    """Shift each frame vertically by the fitted floor height under the root."""
    skel = skel or canonical_skeleton()
    plane = fit_floor(floor_samples(clip.positions, clip.fps, skel))
    shift = clip.root[:, 0] * plane[0] + clip.root[:, 2] * plane[1] + plane[2]
    # In each second some foot touches the floor: put the typical lowest foot point of a second at zero.
    lowest = clip.positions[:, [skel.index(n) for n in GROUND_POINTS], 1].min(axis=1) - shift
    step = max(1, int(round(clip.fps)))
    shift += np.median([lowest[a:a + step].min() for a in range(0, len(lowest), step)])
    clip.root = clip.root - np.c_[np.zeros_like(shift), shift, np.zeros_like(shift)]
    clip.positions = clip.positions - shift[:, None, None] * np.array([0.0, 1.0, 0.0])
    return clip
