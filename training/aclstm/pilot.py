"""Measure dance-model training runs quickly (issue 18's pilots) and add them to docs/models/aclstm-pilots.{json,md}.

    python -m training.aclstm.pilot RUN [RUN ...] [--frames 3000] [--seeds 3] [--which best|last]

Each RUN is a folder under runs/ (its best.pt, or last.pt with --which last). What is measured:
training/aclstm/pilots.py.
"""
from __future__ import annotations

import argparse
import json

from ..paths import REPORTS_DIR
from ..runs import RUNS_DIR
from .pilots import measure_run, pilot_markdown, summary_line

PILOTS = REPORTS_DIR / "aclstm-pilots.json"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--frames", type=int, default=3000)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--which", choices=["best", "last"], default="best")
    parser.add_argument("--mocap", default=None)
    args = parser.parse_args(argv)
    table = json.loads(PILOTS.read_text()) if PILOTS.exists() else {}
    for name in args.runs:
        run_dir = RUNS_DIR / name
        m = measure_run(run_dir / f"{args.which}.pt", args.frames, args.seeds, args.mocap)
        summary = json.loads((run_dir / "summary.json").read_text()) if (run_dir / "summary.json").exists() else {}
        m.pop("details")
        table[f"{name}:{args.which}"] = {**m, "summary": summary}
        print(summary_line(f"{name}:{args.which}", m))
    PILOTS.write_text(json.dumps(table, indent=1, default=str))
    PILOTS.with_suffix(".md").write_text(pilot_markdown(table))
    print(f"wrote {PILOTS} and {PILOTS.with_suffix('.md')}")


if __name__ == "__main__":
    main()
