"""Write tests/fixtures/fk_parity.json: a few frames of real clips as the Python loader sees them.

    python -m training.fixtures

The TypeScript tests check their FK and file readers against these numbers (within 1 mm).
Only derived numbers are stored; the raw clips stay in the corpus.
"""
from __future__ import annotations

import json

import numpy as np

from . import asf_amc, bvh
from .dataset import ClipInfo, load_clip
from .paths import REPO_ROOT, add_mocap_argument, resolve_mocap_dir
from .skeleton import canonical_skeleton

OUT = REPO_ROOT / "tests" / "fixtures" / "fk_parity.json"
CMU_UNIT = 0.0254 / 0.45  # the common CMU BVH conversion keeps ASF units (1/0.45 inch)


def _flat(a: np.ndarray) -> list[float]:
    return [round(float(v), 6) for v in np.asarray(a).reshape(-1)]


def bvh_points(clip: bvh.BvhClip, positions: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Joints as the viewer lists them: zero-offset joints (other than the root) coincide with their parent and are left out."""
    keep = [i for i, j in enumerate(clip.joints) if j.parent < 0 or np.linalg.norm(j.offset) > 0]
    return [clip.joints[i].name for i in keep], positions[:, keep]


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    mocap = resolve_mocap_dir(parser.parse_args().mocap)
    skel = canonical_skeleton()

    clip = load_clip(mocap, ClipInfo("cmu/amc/16_11.amc.gz", "16", "11", 120.0, "walk", "walk"), fps=30)
    frames = slice(10, 16)
    canonical = {"source": "cmu/amc/16_11.amc.gz at 30 fps, frames 10-15", "skeleton": skel.to_json(),
                 "frames": 6, "root_positions": _flat(clip.root[frames]),
                 "rotations": _flat(clip.rotations[frames]), "positions": _flat(clip.positions[frames])}

    asf = asf_amc.load_asf(mocap / "cmu/asf/16.asf")
    amc = asf_amc.load_amc(mocap / "cmu/amc/16_11.amc.gz", asf)
    names, pos = asf_amc.positions(asf, amc)
    amc_frames = [0, 100, 250, amc.frames - 1]
    amc_part = {"asf": "cmu/asf/16.asf", "amc": "cmu/amc/16_11.amc.gz", "frames": amc_frames,
                "joints": names, "positions": _flat(pos[amc_frames])}

    b = bvh.load_bvh(mocap / "cmu/bvh/07_04.bvh.gz")
    _, bpos = bvh.global_transforms(b)
    bnames, bpos = bvh_points(b, bpos * CMU_UNIT)
    bvh_frames = [0, 50, 200, len(bpos) - 1]
    bvh_part = {"file": "cmu/bvh/07_04.bvh.gz", "unit_metres": CMU_UNIT, "frames": bvh_frames,
                "joints": bnames, "positions": _flat(bpos[bvh_frames])}

    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps({"canonical": canonical, "amc": amc_part, "bvh": bvh_part}) + "\n")
    print(f"wrote {OUT} ({OUT.stat().st_size // 1024} KiB)")


if __name__ == "__main__":
    main()
