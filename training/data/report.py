"""Measure the corpus on the canonical skeleton and write docs/data.md (training/data/statistics.py): every CMU clip,
then the combined locomotion corpus from the CMU and Bandai Namco caches (built first when missing), then the check of
the two extra dance trials' conversion (training/data/dance_extra_check.py, on cache/aclstm_positions_extra.npz).

    python -m training.data.report [--mocap DIR]
"""
from __future__ import annotations

import argparse

from ..paths import REPO_ROOT, add_mocap_argument, resolve_mocap_dir
from .bandai import load_clips as load_bandai_clips
from .dance_extra_check import extra_check, extra_report
from .locomotion import load_clips as load_cmu_clips
from .statistics import corpus_statistics, data_report, locomotion_report

OUT = REPO_ROOT / "docs" / "data.md"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    flag = parser.parse_args(argv).mocap
    mocap = resolve_mocap_dir(flag)
    combined = locomotion_report(load_cmu_clips(flag), load_bandai_clips(flag))
    extra = extra_report(extra_check(mocap, flag))
    OUT.write_text(data_report(corpus_statistics(mocap)) + "\n" + combined + "\n" + extra)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
