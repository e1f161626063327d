"""Changing a clip's frame rate: linear interpolation of the root, slerp of joint rotations."""
from __future__ import annotations

import numpy as np

from .retarget import CanonicalClip
from .rotations import quat_slerp
from .skeleton import Skeleton, canonical_skeleton, forward_kinematics


def resample_times(frames: int, src_fps: float, dst_fps: float) -> np.ndarray:
    """Source-frame positions (fractional) of the output frames, covering the clip's duration."""
    duration = (frames - 1) / src_fps
    count = int(np.floor(duration * dst_fps + 1e-6)) + 1
    return np.arange(count) * (src_fps / dst_fps)


def resample(clip: CanonicalClip, fps: float, skel: Skeleton | None = None) -> CanonicalClip:
    skel = skel or canonical_skeleton()
    if abs(clip.fps - fps) < 1e-3:
        return clip
    t = resample_times(clip.frames, clip.fps, fps)
    i0 = np.minimum(np.floor(t).astype(int), clip.frames - 1)
    i1 = np.minimum(i0 + 1, clip.frames - 1)
    w = (t - i0)[:, None]
    root = clip.root[i0] * (1 - w) + clip.root[i1] * w
    rotations = quat_slerp(clip.rotations[i0], clip.rotations[i1], w[:, None])
    return CanonicalClip(clip.name, fps, root, rotations, forward_kinematics(skel, root, rotations))
