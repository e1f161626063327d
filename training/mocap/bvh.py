"""BVH reader with forward kinematics.

Local rotation of a joint is the product of its rotation channels in the listed order
(e.g. "Zrotation Yrotation Xrotation" gives Rz @ Ry @ Rx); G_j = G_parent @ R_j and
p_j = p_parent + G_parent @ OFFSET_j. Position channels move the root from its OFFSET; on any other joint they take
the OFFSET's place (the Bandai Namco files give every joint position channels equal to its OFFSET, the hips' carrying
the translation), as the page's reader does (web/motion/bvh.ts poseNodes). Positions stay in the file's units.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .files import MAX_FRAMES, MAX_VALUES, MotionFormatError, parse_floats, read_text
from .rotations import euler_matrix

CHANNELS = {"xposition", "yposition", "zposition", "xrotation", "yrotation", "zrotation"}


@dataclass
class BvhJoint:
    name: str
    parent: int
    offset: np.ndarray
    channels: list[str]  # lower-case channel names
    end_site: bool = False


@dataclass
class BvhClip:
    source: str
    joints: list[BvhJoint]
    frame_time: float
    motion: np.ndarray  # (frames, total channels)

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    def index(self, name: str) -> int:
        for i, j in enumerate(self.joints):
            if j.name == name:
                return i
        raise KeyError(name)


def parse_bvh(text: str, source: str = "<bvh>") -> BvhClip:
    lines = text.splitlines()
    tokens: list[tuple[int, str]] = []
    motion_line = None
    for n, raw in enumerate(lines, start=1):
        if raw.strip().upper().startswith("MOTION"):
            motion_line = n
            break
        tokens.extend((n, t) for t in raw.replace("{", " { ").replace("}", " } ").split())
    if not tokens or tokens[0][1].upper() != "HIERARCHY":
        raise MotionFormatError(source, "expected 'HIERARCHY' at the start of a BVH file", tokens[0][0] if tokens else 1)
    joints: list[BvhJoint] = []
    stack: list[int] = []
    pos = 1

    def take(what: str) -> tuple[int, str]:
        nonlocal pos
        if pos >= len(tokens):
            raise MotionFormatError(source, f"file is truncated inside HIERARCHY; expected {what}", len(lines))
        tok = tokens[pos]
        pos += 1
        return tok

    while pos < len(tokens):
        n, word = take("a joint")
        upper = word.upper()
        if upper in ("ROOT", "JOINT"):
            if (upper == "ROOT") != (not stack) :
                raise MotionFormatError(source, f"unexpected {word}", n)
            _, name = take("a joint name")
            joints.append(BvhJoint(name, stack[-1] if stack else -1, np.zeros(3), []))
            _expect(take("'{'"), "{", source)
            stack.append(len(joints) - 1)
        elif upper == "END":
            _expect(take("'Site'"), "SITE", source, upper=True)
            if not stack:
                raise MotionFormatError(source, "End Site outside a joint", n)
            joints.append(BvhJoint(joints[stack[-1]].name + "_end", stack[-1], np.zeros(3), [], end_site=True))
            _expect(take("'{'"), "{", source)
            stack.append(len(joints) - 1)
        elif upper == "OFFSET":
            if not stack:
                raise MotionFormatError(source, "OFFSET outside a joint", n)
            vals = [take("an OFFSET number") for _ in range(3)]
            joints[stack[-1]].offset = np.array(parse_floats([v for _, v in vals], source, n))
        elif upper == "CHANNELS":
            if not stack:
                raise MotionFormatError(source, "CHANNELS outside a joint", n)
            _, count = take("a channel count")
            if not count.isdigit() or int(count) > 6:
                raise MotionFormatError(source, f"expected a channel count of 0-6, found {count!r}", n)
            names = [take("a channel name")[1].lower() for _ in range(int(count))]
            bad = [c for c in names if c not in CHANNELS]
            if bad:
                raise MotionFormatError(source, f"unknown channel {bad[0]!r}", n)
            joints[stack[-1]].channels = names
        elif word == "}":
            if not stack:
                raise MotionFormatError(source, "unbalanced '}'", n)
            stack.pop()
            if not stack:
                break
        else:
            raise MotionFormatError(source, f"unexpected {word!r} in HIERARCHY", n)
    if stack or not joints:
        raise MotionFormatError(source, "HIERARCHY is truncated (unclosed joint braces)", len(lines))
    if motion_line is None:
        raise MotionFormatError(source, "no MOTION section", len(lines))
    frames, frame_time, data_start = _motion_header(lines, motion_line, source)
    n_channels = sum(len(j.channels) for j in joints)
    if frames * n_channels > MAX_VALUES or frames > MAX_FRAMES:
        raise MotionFormatError(source, f"declares {frames} frames, more than this loader accepts", data_start - 1)
    rows = []
    for n in range(data_start, len(lines) + 1):
        raw = lines[n - 1].strip()
        if not raw:
            continue
        if len(rows) == frames:
            raise MotionFormatError(source, f"more motion lines than the {frames} frames declared", n)
        vals = raw.split()
        if len(vals) != n_channels:
            raise MotionFormatError(source, f"expected {n_channels} numbers per frame, found {len(vals)}", n)
        rows.append(parse_floats(vals, source, n))
    if len(rows) != frames:
        raise MotionFormatError(source, f"declares {frames} frames but has {len(rows)} motion lines (truncated?)", len(lines))
    motion = np.array(rows, dtype=np.float64).reshape(frames, n_channels)
    return BvhClip(source, joints, frame_time, motion)


def _expect(tok: tuple[int, str], want: str, source: str, upper: bool = False) -> None:
    n, word = tok
    if (word.upper() if upper else word) != want:
        raise MotionFormatError(source, f"expected {want!r}, found {word!r}", n)


def _motion_header(lines: list[str], motion_line: int, source: str) -> tuple[int, float, int]:
    values = {}
    n = motion_line
    for key in ("frames", "frame time"):
        n += 1
        if n > len(lines):
            raise MotionFormatError(source, f"file ends before the '{key.title()}:' line", n - 1)
        head, _, rest = lines[n - 1].partition(":")
        if head.strip().lower() != key:
            raise MotionFormatError(source, f"expected '{key.title()}:', found {lines[n - 1].strip()[:40]!r}", n)
        try:
            values[key] = float(rest.strip())
        except ValueError:
            raise MotionFormatError(source, f"'{key.title()}:' needs a number", n) from None
    frames, frame_time = values["frames"], values["frame time"]
    if frames < 1 or frames != int(frames):
        raise MotionFormatError(source, f"frame count must be a positive integer, found {rest.strip()}", motion_line + 1)
    if not frame_time > 0 or frame_time > 10:
        raise MotionFormatError(source, f"frame time must be a positive number of seconds, found {frame_time}", motion_line + 2)
    return int(frames), frame_time, n + 1


def global_transforms(clip: BvhClip) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (frames, joints, 3, 3) and positions (frames, joints, 3) in file units."""
    frames, joints = clip.motion.shape[0], len(clip.joints)
    rots = np.zeros((frames, joints, 3, 3))
    pos = np.zeros((frames, joints, 3))
    col = 0
    for j, joint in enumerate(clip.joints):
        k = len(joint.channels)
        vals = clip.motion[:, col:col + k]
        col += k
        local_t = np.array(joint.offset, dtype=np.float64)[None].repeat(frames, 0)
        rot_axes = "".join(c[0] for c in joint.channels if c.endswith("rotation"))
        rot_vals = np.radians(vals[:, [i for i, c in enumerate(joint.channels) if c.endswith("rotation")]])
        local_r = euler_matrix(rot_vals, rot_axes, intrinsic=True) if rot_axes else np.broadcast_to(np.eye(3), (frames, 3, 3))
        moves = [(i, "xyz".index(c[0])) for i, c in enumerate(joint.channels) if c.endswith("position")]
        if moves and joint.parent >= 0:
            local_t[:] = 0.0  # a non-root joint's position channels replace its offset
        for i, axis in moves:
            local_t[:, axis] += vals[:, i]
        if joint.parent < 0:
            rots[:, j] = local_r
            pos[:, j] = local_t
        else:
            p = joint.parent
            rots[:, j] = rots[:, p] @ local_r
            pos[:, j] = pos[:, p] + np.einsum("fij,fj->fi", rots[:, p], local_t)
    return rots, pos


def load_bvh(path: str | Path) -> BvhClip:
    return parse_bvh(read_text(path), str(path))


def viewer_points(clip: BvhClip, positions: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Joints as the viewer lists them: zero-offset joints (other than the root) coincide with their parent and are left out."""
    keep = [i for i, j in enumerate(clip.joints) if j.parent < 0 or np.linalg.norm(j.offset) > 0]
    return [clip.joints[i].name for i in keep], positions[:, keep]
