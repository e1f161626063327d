"""The canonical skeleton that all locomotion data is retargeted to, and its forward kinematics.

Each point is where a bone ends; the rotation stored at a point rotates the segment that ends there
(ASF style): G_j = G_parent(j) @ L_j and p_j = p_parent(j) + G_j @ offset_j. The root's rotation is
the pelvis orientation. Point names follow the common CMU BVH conversion (LeftUpLeg = hip joint,
LeftLeg = knee, LeftFoot = ankle, ...), so imported CMU BVH files and model output share names.

The offsets are fixed numbers (metres, symmetric left/right), made by `python -m training.mocap.rebuild_skeleton`
from the mean bone lengths and directions of all CMU subjects, and stored in canonical_skeleton.json.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from .rotations import quat_to_matrix

SKELETON_JSON = Path(__file__).with_name("canonical_skeleton.json")

# (point, parent point, CMU ASF bones whose lengths add up to the segment; the first one owns the rotation)
CANONICAL_LAYOUT: list[tuple[str, str | None, tuple[str, ...]]] = [
    ("Hips", None, ()),
    ("LeftUpLeg", "Hips", ("lhipjoint",)),
    ("LeftLeg", "LeftUpLeg", ("lfemur",)),
    ("LeftFoot", "LeftLeg", ("ltibia",)),
    ("LeftToeBase", "LeftFoot", ("lfoot",)),
    ("LeftToeBase_end", "LeftToeBase", ("ltoes",)),
    ("RightUpLeg", "Hips", ("rhipjoint",)),
    ("RightLeg", "RightUpLeg", ("rfemur",)),
    ("RightFoot", "RightLeg", ("rtibia",)),
    ("RightToeBase", "RightFoot", ("rfoot",)),
    ("RightToeBase_end", "RightToeBase", ("rtoes",)),
    ("Spine", "Hips", ("lowerback",)),
    ("Spine1", "Spine", ("upperback",)),
    ("Neck", "Spine1", ("thorax",)),
    ("Neck1", "Neck", ("lowerneck",)),
    ("Head", "Neck1", ("upperneck",)),
    ("Head_end", "Head", ("head",)),
    ("LeftArm", "Neck", ("lclavicle",)),
    ("LeftForeArm", "LeftArm", ("lhumerus",)),
    ("LeftHand", "LeftForeArm", ("lradius",)),
    ("LeftHand_end", "LeftHand", ("lhand", "lwrist")),
    ("RightArm", "Neck", ("rclavicle",)),
    ("RightForeArm", "RightArm", ("rhumerus",)),
    ("RightHand", "RightForeArm", ("rradius",)),
    ("RightHand_end", "RightHand", ("rhand", "rwrist")),
]

# Points whose heights and speeds decide foot contact: (ankle, toe) per side.
FOOT_POINTS = {"left": ("LeftFoot", "LeftToeBase"), "right": ("RightFoot", "RightToeBase")}
# Segments that retargeting keeps rigid (retarget.RIGID_BONES): nothing to model (data/features.py), held at their
# reference by the canonical IK (canonical_ik.py).
FIXED_JOINTS = ("LeftUpLeg", "RightUpLeg", "LeftHand_end", "RightHand_end")
# Points that can touch the ground: used to put the feet on the floor.
GROUND_POINTS = ("LeftFoot", "LeftToeBase", "LeftToeBase_end", "RightFoot", "RightToeBase", "RightToeBase_end")


def mirror_name(name: str) -> str:
    for a, b in (("Left", "Right"), ("Right", "Left")):
        if name.startswith(a):
            return b + name[len(a):]
    return name


@dataclass(frozen=True)
class Skeleton:
    joints: list[str]
    parents: list[int]
    offsets: np.ndarray  # (joints, 3) metres
    source_bones: list[tuple[str, ...]]

    def index(self, name: str) -> int:
        return self.joints.index(name)

    @property
    def leg_length(self) -> float:
        """Hip to ankle along the bones (thigh + shin), the scale used for root translation."""
        return float(np.linalg.norm(self.offsets[self.index("LeftLeg")]) + np.linalg.norm(self.offsets[self.index("LeftFoot")]))

    @property
    def mirror_map(self) -> list[int]:
        return [self.index(mirror_name(n)) for n in self.joints]

    def to_json(self) -> dict:
        return {"joints": self.joints, "parents": self.parents,
                "offsets": [round(float(v), 6) for v in self.offsets.reshape(-1)]}


@lru_cache(maxsize=1)
def canonical_skeleton() -> Skeleton:
    data = json.loads(SKELETON_JSON.read_text())
    names = [p for p, _, _ in CANONICAL_LAYOUT]
    if data["joints"] != names:
        raise RuntimeError(f"{SKELETON_JSON} is out of date with CANONICAL_LAYOUT; run python -m training.mocap.rebuild_skeleton")
    return Skeleton(names, data["parents"], np.array(data["offsets"], dtype=np.float64).reshape(-1, 3),
                    [b for _, _, b in CANONICAL_LAYOUT])


def forward_kinematics(skel: Skeleton, root: np.ndarray, local_quats: np.ndarray) -> np.ndarray:
    """World positions (frames, joints, 3) from root positions (frames, 3) and local quaternions (frames, joints, 4)."""
    return forward_kinematics_matrices(skel, root, quat_to_matrix(local_quats))


def forward_kinematics_matrices(skel: Skeleton, root: np.ndarray, local: np.ndarray) -> np.ndarray:
    frames = root.shape[0]
    world = np.zeros((frames, len(skel.joints), 3, 3))
    pos = np.zeros((frames, len(skel.joints), 3))
    for j, p in enumerate(skel.parents):
        if p < 0:
            world[:, j] = local[:, j]
            pos[:, j] = root
        else:
            world[:, j] = world[:, p] @ local[:, j]
            pos[:, j] = pos[:, p] + world[:, j] @ skel.offsets[j]
    return pos


def build_canonical_from_asfs(asf_paths: list[Path]) -> dict:
    """Mean bone lengths (metres) and directions over subjects, made left/right symmetric."""
    from .asf_amc import load_asf

    skels = [load_asf(p) for p in asf_paths]
    names = [p for p, _, _ in CANONICAL_LAYOUT]
    offsets = np.zeros((len(names), 3))
    for j, (_, parent, bones) in enumerate(CANONICAL_LAYOUT):
        if parent is None:
            continue
        length = sum(np.mean([s.bones[b].length * s.metres_per_unit for s in skels]) for b in bones)
        direction = np.mean([s.bones[bones[0]].direction for s in skels], axis=0)
        offsets[j] = direction / np.linalg.norm(direction) * length
    flip = np.array([-1.0, 1.0, 1.0])
    mirror = [names.index(mirror_name(n)) for n in names]
    offsets = 0.5 * (offsets + offsets[mirror] * flip)
    parents = [names.index(p) if p else -1 for _, p, _ in CANONICAL_LAYOUT]
    return {"joints": names, "parents": parents, "offsets": [round(float(v), 6) for v in offsets.reshape(-1)],
            "made_from": [p.name for p in asf_paths]}
