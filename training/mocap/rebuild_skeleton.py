"""Rebuild training/mocap/canonical_skeleton.json from the CMU ASF files (skeleton.build_canonical_from_asfs).

    python -m training.mocap.rebuild_skeleton [--mocap DIR]
"""
from __future__ import annotations

import argparse
import json

from ..paths import add_mocap_argument, resolve_mocap_dir
from .skeleton import SKELETON_JSON, build_canonical_from_asfs


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    root = resolve_mocap_dir(parser.parse_args(argv).mocap)
    data = build_canonical_from_asfs(sorted((root / "cmu" / "asf").glob("*.asf")))
    SKELETON_JSON.write_text(json.dumps(data, indent=1) + "\n")
    print(f"wrote {SKELETON_JSON} from {len(data['made_from'])} subjects")


if __name__ == "__main__":
    main()
