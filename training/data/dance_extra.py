"""The two CMU dance trials of ../shared/mocap/aclstm-extra/ on the acLSTM standard skeleton (issue 42, "More data").

The acLSTM set (training/data/dance.py) is CMU trials retargeted onto one standard 57-point skeleton. Two of its
trials are missing there and come as other conversions of the same CMU trials: indian 01 (CMU 94_01, the 3ds
Max-friendly BVH) and martial 02 (CMU 135_02, ASF/AMC). `to_standard` is a position retarget onto the standard's
bone lengths, at the source rate (120 fps), frame for frame:

- points: the humanoid mapper (mocap/humanoid.py) finds the canonical points on both skeletons; a standard point
  and a source point at the same canonical point correspond (hips, spine, chest, neck base, head, hip sockets,
  knees, ankles, toe (the standard foot's end site <- the source's toe base), shoulders, elbows, wrists);
- limb bones (thigh, shin, foot; upper arm, forearm): the standard's rest offset turned by the world rotation of the
  source bone, after one rest correction per limb, the rotation taking the standard's rest thigh (upper arm) onto
  the source's. So the thigh and upper arm lie exactly along the source's, and the lower bones keep the standard's
  rest bends on top of the source's (elbow 17 degrees, knee 8): the acLSTM clips do (no elbow of theirs straightens
  past 157 degrees; pure directions straightened ours to 177);
- the other bones between two corresponding points (abdomen, chest, neck -> head): the standard bone along the
  source bone's world direction, with the standard's length, from the root down;
- a corresponding point whose standard parent has no source (the shoulder below the standard's collar, the hip
  socket below its buttock): its standard offset turned by the world rotation of the source segment ending there
  (the clavicle, the pelvis) -- the offset follows the source's rotation from its rest pose, so the standard's own
  collar and hip geometry stays (the CMU clavicle starts mid-chest and rises 25 degrees; the standard's starts at the
  neck base and falls 12);
- points without a source (buttocks, collars, eyes, fingers, end sites): rigid on their parent's frame as in the
  standard rest pose. The frames: the hips turn with the source pelvis, the chest with the source's upper chest,
  the head with the source head; the hands continue the forearm (its world rotation, rest-aligned), as
  mocap/retarget.py does, because CMU's hand markers flip;
- a source bone of no length (the 3ds Max BVH's neck base sits on its chest) leaves its standard bone to the
  parent's frame;
- the root: the source's hip-socket midpoint scaled by standard leg length / source leg length (hip -> knee ->
  ankle), with the standard's hips placed from it by the pelvis frame, so the legs hang where the source's do.

Both source rest poses and the standard's stand upright facing +z, so the pelvis, chest and head frames need no rest
correction; the arms of the 3ds Max BVH hang down in its rest pose, so the forearm frame is rest-aligned. Positions
come back in metres, not yet on the floor (dance.py's floor rule does that). docs/data.md has the check against the
acLSTM clips of the same subjects.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..mocap import asf_amc, bvh
from ..mocap.humanoid import CANONICAL_JOINTS, map_humanoid
from ..mocap.rotations import rotation_between

# style, motion file, skeleton file (ASF) or None, relative to the corpus root; acLSTM's file numbers in the README.
EXTRA_FILES = (
    ("indian", "aclstm-extra/indian/94_01.bvh.gz", None),
    ("martial", "aclstm-extra/martial/135_02.amc.gz", "aclstm-extra/martial/135.asf"),
)
# The canonical points that tie a standard point to a source point. Not Hand_end (the hands follow the forearm),
# nor Head_end, Neck1 and ToeBase_end, which the standard skeleton does not have.
TIED = ("Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot",
        "RightToeBase", "Spine", "Spine1", "Neck", "Head", "LeftArm", "LeftForeArm", "LeftHand", "RightArm",
        "RightForeArm", "RightHand")
# A source bone shorter than this share of the source leg length has no direction.
NO_LENGTH = 1e-3


@dataclass
class SourceMotion:
    """A clip as world points and the world rotation of the segment ending at each point (any units, y up)."""
    name: str
    fps: float
    names: list[str]
    parents: list[int]
    positions: np.ndarray  # (frames, points, 3)
    segment: np.ndarray  # (frames, points, 3, 3): the rotation taking the rest segment into each point to now
    rest: np.ndarray  # (points, 3): the segment into each point in the rest pose (zero for the root)


def source_from_bvh(path: Path) -> SourceMotion:
    """A BVH clip (End Sites are points, named <joint>_end): a joint's rotation turns the bones to its children."""
    clip = bvh.load_bvh(path)
    rots, pos = bvh.global_transforms(clip)
    parents = [j.parent for j in clip.joints]
    seg = rots[:, [max(p, 0) for p in parents]]  # the root's own rotation for the root
    rest = np.array([j.offset if j.parent >= 0 else np.zeros(3) for j in clip.joints], dtype=np.float64)
    names = [f"{clip.joints[j.parent].name}_end" if j.end_site else j.name for j in clip.joints]
    return SourceMotion(Path(path).name, clip.fps, names, parents, pos, seg, rest)


def source_from_asf_amc(asf_path: Path, amc_path: Path, fps: float = 120.0) -> SourceMotion:
    """An ASF/AMC clip: the points are the root and each bone's end; a bone's rotation turns the bone itself."""
    skel = asf_amc.load_asf(asf_path)
    motion = asf_amc.load_amc(amc_path, skel)
    _, rots = asf_amc.global_rotations(skel, motion)
    names, pos = asf_amc.positions(skel, motion)
    parents = [-1] + [names.index(skel.parent[b]) for b in skel.order]
    seg = np.stack([rots[n] for n in names], axis=1)
    rest = np.array([np.zeros(3)] + [skel.rest_vector(b) * skel.metres_per_unit for b in skel.order])
    return SourceMotion(Path(amc_path).name, fps, names, parents, pos, seg, rest)


def read_source(mocap: Path, motion: str, skeleton: str | None) -> SourceMotion:
    return source_from_asf_amc(mocap / skeleton, mocap / motion) if skeleton else source_from_bvh(mocap / motion)


def rest_positions(parents: list[int], offsets: np.ndarray) -> np.ndarray:
    out = np.zeros_like(offsets, dtype=np.float64)
    for j, p in enumerate(parents):
        out[j] = offsets[j] + (out[p] if p >= 0 else 0.0)
    return out


def correspondence(src: SourceMotion, names: list[str], parents: list[int], offsets: np.ndarray) -> dict[str, tuple[int, int]]:
    """Per canonical point of TIED (and Head_end, Neck of the source): (standard joint, source point), -1 where absent."""
    std = map_humanoid(names, parents, rest_positions(parents, offsets)[None])
    mine = map_humanoid(src.names, src.parents, src.positions)
    return {c: (std.source[k], mine.source[k]) for k, c in enumerate(CANONICAL_JOINTS)}


def _leg(points: np.ndarray, up: int, knee: int, ankle: int) -> np.ndarray:
    return (np.linalg.norm(points[..., up, :] - points[..., knee, :], axis=-1)
            + np.linalg.norm(points[..., knee, :] - points[..., ankle, :], axis=-1))


def to_standard(src: SourceMotion, names: list[str], parents: list[int], offsets: np.ndarray,
                pairs: dict[str, tuple[int, int]] | None = None) -> np.ndarray:
    """The source clip on the standard skeleton (names, parents, offsets in metres from each parent, rest pose):
    world positions (frames, points, 3) in metres, one frame per source frame, not yet on the floor. `pairs`: the
    correspondence when given (a rest pose alone does not tell the mapper left from right), else found here."""
    pairs = pairs or correspondence(src, names, parents, offsets)
    tied = {pairs[c][0]: pairs[c][1] for c in TIED if pairs[c][0] >= 0 and pairs[c][1] >= 0}
    missing = [c for c in TIED if pairs[c][0] < 0 or pairs[c][1] < 0]
    if missing:
        raise ValueError(f"{src.name}: no {missing[0]} on {'the standard' if pairs[missing[0]][0] < 0 else 'the source'} skeleton")
    P, seg = src.positions, src.segment
    frames, J = len(P), len(names)
    rest = rest_positions(parents, offsets)
    sockets = [(pairs[f"{s}UpLeg"], pairs[f"{s}Leg"], pairs[f"{s}Foot"]) for s in ("Left", "Right")]
    std_leg = np.mean([_leg(rest, u[0], k[0], a[0]) for u, k, a in sockets])
    src_leg = float(np.median(np.mean([_leg(P, u[1], k[1], a[1]) for u, k, a in sockets], axis=0)))
    scale = std_leg / src_leg

    # Frames of the standard joints whose children ride on them (the others take their parent's).
    own_frame = {pairs["Hips"][0]: seg[:, pairs["Hips"][1]],
                 pairs["Spine1"][0]: seg[:, pairs["Neck"][1]],
                 pairs["Head"][0]: seg[:, pairs["Head_end"][1] if pairs["Head_end"][1] >= 0 else pairs["Head"][1]]}
    # Limb bones turn with their source segment from the rest pose, one rest correction per limb (its first bone's):
    # the first bone points exactly where the source's does, and the standard's rest bends (elbow 17 degrees, knee 8)
    # stay on top of the source's, as in the acLSTM clips (their elbows never straighten past 157 degrees).
    limb_rest: dict[int, np.ndarray] = {}
    for side in ("Left", "Right"):
        for chain in (("UpLeg", "Leg", "Foot", "ToeBase"), ("Arm", "ForeArm", "Hand")):
            first = pairs[f"{side}{chain[1]}"]
            align = rotation_between(offsets[first[0]], src.rest[first[1]])
            for upper, lower in zip(chain[:-1], chain[1:]):
                a, b = pairs[f"{side}{upper}"], pairs[f"{side}{lower}"]
                if parents[b[0]] != a[0] or src.parents[b[1]] != a[1]:
                    raise ValueError(f"{src.name}: {side}{upper} -> {side}{lower} is not one bone on both skeletons")
                limb_rest[b[0]] = align
        hand = pairs[f"{side}Hand"]
        own_frame[hand[0]] = seg[:, hand[1]] @ limb_rest[hand[0]]

    X = np.zeros((frames, J, 3))
    Q = np.zeros((frames, J, 3, 3))
    hips = pairs["Hips"][0]
    if hips != 0 or parents[0] != -1:
        raise ValueError("the standard skeleton's root must be its hips")
    Q[:, 0] = own_frame[0]
    mid_std = (rest[sockets[0][0][0]] + rest[sockets[1][0][0]]) / 2 - rest[0]
    mid_src = (P[:, sockets[0][0][1]] + P[:, sockets[1][0][1]]) / 2
    X[:, 0] = scale * mid_src - Q[:, 0] @ mid_std
    for j in range(1, J):
        p = parents[j]
        off = offsets[j]
        if j in limb_rest:
            X[:, j] = X[:, p] + seg[:, tied[j]] @ (limb_rest[j] @ off)
        elif j in tied and p in tied:
            bone = P[:, tied[j]] - P[:, tied[p]]
            length = np.linalg.norm(bone, axis=-1, keepdims=True)
            if np.median(length) > NO_LENGTH * src_leg:
                X[:, j] = X[:, p] + np.linalg.norm(off) * bone / np.maximum(length, 1e-12)
            else:
                X[:, j] = X[:, p] + Q[:, p] @ off
        elif j in tied:
            X[:, j] = X[:, p] + seg[:, tied[j]] @ off
        else:
            X[:, j] = X[:, p] + Q[:, p] @ off
        Q[:, j] = own_frame.get(j, Q[:, p])
    return X
