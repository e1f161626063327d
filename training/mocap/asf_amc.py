"""CMU ASF (skeleton) and AMC (motion) readers with forward kinematics.

FK follows the widely used AMC convention: for bone b with axis angles C_b and motion angles M_b
(both extrinsic Euler in the listed order), G_b = G_parent @ C_b @ M_b @ C_b^-1 and
end_b = end_parent + G_b @ (direction_b * length_b). ASF `length L` means one unit is 1/L inch.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .files import MAX_FRAMES, MotionFormatError, parse_floats, read_text
from .rotations import euler_matrix

INCH = 0.0254


@dataclass
class AsfBone:
    name: str
    direction: np.ndarray  # unit vector in the world-aligned rest frame
    length: float  # ASF units
    axis: np.ndarray  # radians
    axis_order: str  # e.g. "xyz"
    dofs: list[str]  # e.g. ["rx", "ry", "rz"]


@dataclass
class AsfSkeleton:
    source: str
    metres_per_unit: float
    degrees: bool
    root_order: list[str]
    root_axis_order: str
    root_position: np.ndarray
    root_orientation: np.ndarray  # radians
    bones: dict[str, AsfBone]
    parent: dict[str, str] = field(default_factory=dict)
    order: list[str] = field(default_factory=list)  # bones in depth-first hierarchy order

    def rest_vector(self, bone: str) -> np.ndarray:
        b = self.bones[bone]
        return b.direction * b.length


@dataclass
class AmcMotion:
    frames: int
    values: dict[str, np.ndarray]  # bone (and "root") -> (frames, n_dof) raw values as written


def _sections(text: str):
    """Yield (line_number, stripped_line) skipping blanks and comments."""
    for i, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if line:
            yield i, line


def parse_asf(text: str, source: str = "<asf>") -> AsfSkeleton:
    length_unit, degrees = 1.0, True
    root: dict = {"order": ["tx", "ty", "tz", "rx", "ry", "rz"], "axis": "xyz", "position": [0, 0, 0], "orientation": [0, 0, 0]}
    bones: dict[str, AsfBone] = {}
    hierarchy: list[tuple[int, list[str]]] = []
    section = None
    current: dict | None = None
    seen_bonedata = False
    for n, line in _sections(text):
        if line.startswith(":"):
            head = line.split()
            section = head[0][1:].lower()
            if section == "bonedata":
                seen_bonedata = True
            continue
        words = line.split()
        key = words[0].lower()
        if section == "units":
            if key == "length":
                length_unit = parse_floats(words[1:2], source, n)[0] if len(words) > 1 else 1.0
                if length_unit <= 0:
                    raise MotionFormatError(source, "units length must be positive", n)
            elif key == "angle":
                degrees = not (len(words) > 1 and words[1].lower().startswith("rad"))
        elif section == "root":
            if key == "order":
                root["order"] = [w.lower() for w in words[1:]]
            elif key == "axis":
                root["axis"] = words[1].lower() if len(words) > 1 else "xyz"
            elif key in ("position", "orientation"):
                if len(words) != 4:
                    raise MotionFormatError(source, f"root {key} needs 3 numbers, found {len(words) - 1}", n)
                root[key] = parse_floats(words[1:4], source, n)
        elif section == "bonedata":
            if key == "begin":
                current = {"line": n, "dofs": [], "axis": [0.0, 0.0, 0.0], "axis_order": "xyz"}
            elif key == "end":
                if current is None:
                    raise MotionFormatError(source, "'end' without 'begin' in :bonedata", n)
                for req in ("name", "direction", "length"):
                    if req not in current:
                        raise MotionFormatError(source, f"bone is missing '{req}'", current["line"])
                direction = np.array(current["direction"], dtype=np.float64)
                norm = np.linalg.norm(direction)
                direction = direction / norm if norm > 0 else direction
                ang = np.array(current["axis"])
                bones[current["name"]] = AsfBone(
                    current["name"], direction, current["length"], np.radians(ang) if degrees else ang,
                    current["axis_order"], current["dofs"])
                current = None
            elif current is not None:
                if key == "name" and len(words) > 1:
                    current["name"] = words[1]
                elif key == "direction":
                    if len(words) != 4:
                        raise MotionFormatError(source, f"direction needs 3 numbers, found {len(words) - 1}", n)
                    current["direction"] = parse_floats(words[1:4], source, n)
                elif key == "length":
                    current["length"] = parse_floats(words[1:2], source, n)[0]
                elif key == "axis":
                    if len(words) != 5:
                        raise MotionFormatError(source, "axis needs 3 angles and an order such as XYZ", n)
                    current["axis"] = parse_floats(words[1:4], source, n)
                    current["axis_order"] = words[4].lower()
                elif key == "dof":
                    current["dofs"] = [w.lower() for w in words[1:]]
                    bad = [d for d in current["dofs"] if d not in ("rx", "ry", "rz", "tx", "ty", "tz", "l")]
                    if bad:
                        raise MotionFormatError(source, f"unknown dof {bad[0]!r}", n)
        elif section == "hierarchy":
            if key not in ("begin", "end"):
                hierarchy.append((n, words))
    if not seen_bonedata or not bones:
        raise MotionFormatError(source, "no :bonedata section with bones; is this an ASF skeleton file?")
    if current is not None:
        raise MotionFormatError(source, "truncated :bonedata (a 'begin' without 'end')", current["line"])
    deg = np.radians if degrees else (lambda a: np.asarray(a, dtype=np.float64))
    skel = AsfSkeleton(source, INCH / length_unit, degrees, root["order"], root["axis"],
                       np.array(root["position"], dtype=np.float64), deg(np.array(root["orientation"], dtype=np.float64)), bones)
    children: dict[str, list[str]] = {}
    for n, words in hierarchy:
        parent = words[0]
        if parent != "root" and parent not in bones:
            raise MotionFormatError(source, f"hierarchy names unknown bone {parent!r}", n)
        for child in words[1:]:
            if child not in bones:
                raise MotionFormatError(source, f"hierarchy names unknown bone {child!r}", n)
            skel.parent[child] = parent
            children.setdefault(parent, []).append(child)
    stack = list(reversed(children.get("root", [])))
    while stack:
        b = stack.pop()
        skel.order.append(b)
        stack.extend(reversed(children.get(b, [])))
    missing = [b for b in bones if b not in skel.parent]
    if missing:
        raise MotionFormatError(source, f"bone {missing[0]!r} is not in :hierarchy")
    return skel


def parse_amc(text: str, skel: AsfSkeleton, source: str = "<amc>") -> AmcMotion:
    expected = {"root": len(skel.root_order)}
    for name, bone in skel.bones.items():
        expected[name] = len(bone.dofs)
    frames: list[dict[str, list[float]]] = []
    current: dict[str, list[float]] | None = None
    for n, line in _sections(text):
        if line.startswith(":"):
            continue
        words = line.split()
        if len(words) == 1 and words[0].isdigit():
            if len(frames) >= MAX_FRAMES:
                raise MotionFormatError(source, f"more than {MAX_FRAMES} frames", n)
            current = {}
            frames.append(current)
            continue
        if current is None:
            raise MotionFormatError(source, "expected a frame number before bone values", n)
        name = words[0]
        if name not in expected:
            raise MotionFormatError(source, f"unknown bone {name!r} (not in the ASF skeleton {skel.source})", n)
        values = parse_floats(words[1:], source, n)
        if len(values) != expected[name]:
            raise MotionFormatError(source, f"bone {name!r} needs {expected[name]} values, found {len(values)}", n)
        current[name] = values
    if not frames:
        raise MotionFormatError(source, "no frames found; is this an AMC motion file?")
    # A file cut mid-frame leaves the last frame incomplete: drop it rather than invent values.
    needed = [b for b, k in expected.items() if k > 0]
    if any(b not in frames[-1] for b in needed) and len(frames) > 1:
        frames.pop()
    for i, fr in enumerate(frames):
        missing = [b for b in needed if b not in fr]
        if missing:
            raise MotionFormatError(source, f"frame {i + 1} has no values for bone {missing[0]!r}")
    values = {b: np.array([fr.get(b, []) for fr in frames], dtype=np.float64).reshape(len(frames), expected[b]) for b in expected}
    return AmcMotion(len(frames), values)


def _axis_matrix(angles: np.ndarray, order: str) -> np.ndarray:
    # ASF axis angles are given as x, y, z values; the order string says how they compose.
    by_axis = dict(zip("xyz", angles))
    return euler_matrix(np.array([by_axis[a] for a in order]), order, intrinsic=False)


def _dof_matrix(values: np.ndarray, dofs: list[str], degrees: bool) -> np.ndarray:
    rot = [(d[1], i) for i, d in enumerate(dofs) if d in ("rx", "ry", "rz")]
    frames = values.shape[0]
    if not rot:
        return np.broadcast_to(np.eye(3), (frames, 3, 3))
    angles = values[:, [i for _, i in rot]]
    if degrees:
        angles = np.radians(angles)
    return euler_matrix(angles, "".join(a for a, _ in rot), intrinsic=False)


def global_rotations(skel: AsfSkeleton, motion: AmcMotion) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Root translation (frames, 3) in ASF units and each bone's world rotation (frames, 3, 3), incl. 'root'."""
    order = skel.root_order
    root_vals = motion.values["root"]
    trans = np.zeros((motion.frames, 3))
    for i, ch in enumerate(order):
        if ch in ("tx", "ty", "tz"):
            trans[:, "xyz".index(ch[1])] = root_vals[:, i]
    trans += skel.root_position
    c_root = _axis_matrix(skel.root_orientation, skel.root_axis_order)
    m_root = _dof_matrix(root_vals, order, skel.degrees)
    rots = {"root": c_root @ m_root @ c_root.T}
    for name in skel.order:
        bone = skel.bones[name]
        c = _axis_matrix(bone.axis, bone.axis_order)
        m = _dof_matrix(motion.values[name], bone.dofs, skel.degrees)
        rots[name] = rots[skel.parent[name]] @ (c @ m @ c.T)
    return trans, rots


def positions(skel: AsfSkeleton, motion: AmcMotion) -> tuple[list[str], np.ndarray]:
    """Joint names ['root', bones…] and world positions (frames, joints, 3) in metres; a bone's point is its end."""
    trans, rots = global_rotations(skel, motion)
    ends = {"root": trans}
    for name in skel.order:
        ends[name] = ends[skel.parent[name]] + rots[name] @ skel.rest_vector(name)
    names = ["root"] + skel.order
    return names, np.stack([ends[n] for n in names], axis=1) * skel.metres_per_unit


def load_asf(path: str | Path) -> AsfSkeleton:
    return parse_asf(read_text(path), str(path))


def load_amc(path: str | Path, skel: AsfSkeleton) -> AmcMotion:
    return parse_amc(read_text(path), skel, str(path))
