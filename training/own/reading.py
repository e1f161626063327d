"""Reading a user's folder of motion: every BVH and ASF/AMC pair under it (plain or gzipped), through the corpus
readers (training/mocap/canonical_points.py read_bvh, asf_amc.py), as joint names, parents and world positions (RawClip).
A file that cannot be read is set aside with its reader's message (file and line) and the others go on."""
from __future__ import annotations

from pathlib import Path

from ..mocap import asf_amc
from ..mocap.canonical_points import RawClip, read_bvh
from ..mocap.files import MotionFormatError

BVH_SUFFIXES = (".bvh", ".bvh.gz")
AMC_SUFFIXES = (".amc", ".amc.gz")
ASF_SUFFIXES = (".asf", ".asf.gz")
# AMC files carry no frame rate; CMU's (the format's main source) are captured at 120 fps.
AMC_FPS = 120.0


def _has_suffix(path: Path, suffixes: tuple[str, ...]) -> bool:
    return path.name.lower().endswith(suffixes)


def _stem(path: Path) -> str:
    name = path.name
    if name.lower().endswith(".gz"):
        name = name[:-3]
    return name.rsplit(".", 1)[0]


def motion_files(folder: Path) -> list[Path]:
    """BVH and AMC files under `folder`, at any depth, in name order."""
    return sorted(p for p in folder.rglob("*") if p.is_file() and _has_suffix(p, BVH_SUFFIXES + AMC_SUFFIXES))


def skeleton_for(amc: Path, folder: Path) -> Path | None:
    """The ASF skeleton of an AMC file: the .asf named as the AMC's subject (CMU's 02_01.amc → 02.asf) or as the AMC
    itself, anywhere under `folder`; else the only .asf beside it; else the only one in the folder."""
    asfs = sorted(p for p in folder.rglob("*") if p.is_file() and _has_suffix(p, ASF_SUFFIXES))
    stem = _stem(amc)
    for wanted in (stem.split("_")[0], stem):
        named = [p for p in asfs if _stem(p) == wanted]
        if named:
            return min(named, key=lambda p: (p.parent != amc.parent, str(p)))
    beside = [p for p in asfs if p.parent == amc.parent]
    if len(beside) == 1:
        return beside[0]
    return asfs[0] if len(asfs) == 1 else None


def read_amc(path: Path, asf: Path, name: str) -> RawClip:
    skel = asf_amc.load_asf(asf)
    joints, positions = asf_amc.positions(skel, asf_amc.load_amc(path, skel))
    parents = [-1] + [joints.index(skel.parent[b]) for b in joints[1:]]
    return RawClip(name, AMC_FPS, joints, parents, positions)


def read_folder(folder: Path) -> tuple[list[RawClip], list[str]]:
    """Every clip under `folder` that reads, and one message per file that does not (file and line)."""
    clips, problems = [], []
    for path in motion_files(folder):
        name = str(path.relative_to(folder))
        try:
            if _has_suffix(path, BVH_SUFFIXES):
                clips.append(read_bvh(path, name))
            else:
                asf = skeleton_for(path, folder)
                if asf is None:
                    problems.append(f"{name}: no .asf skeleton for this .amc (name it as the subject, e.g. 02.asf for 02_01.amc)")
                    continue
                clips.append(read_amc(path, asf, name))
        except MotionFormatError as err:
            problems.append(str(err).replace(str(path), name, 1))
        except (OSError, ValueError) as err:
            problems.append(f"{name}: {err}")
    return clips, problems
