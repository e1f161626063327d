"""Measure dance-model training runs quickly (issue 18's pilots) and add them to docs/models/aclstm-pilots.{json,md}.

    python -m training.aclstm.pilot RUN [RUN ...] [--frames 3000] [--seeds 3] [--which best|last]
    python -m training.aclstm.pilot --feedback-noise 0.1 0.15 [--rho 0.9] [--pose-only] [--model aclstm] [--frames 20000]

Each RUN is a folder under runs/ (its best.pt, or last.pt with --which last). --feedback-noise measures an exported
model (public/models/) with noise on each fed-back frame instead, 5 seeds per style. What is measured:
training/aclstm/pilots.py.
"""
from __future__ import annotations

import argparse
import json

from ..paths import MODELS_DIR, REPORTS_DIR
from ..runs import RUNS_DIR
from .pilots import feedback_noise_runs, measure_run, pilot_markdown, summary_line

PILOTS = REPORTS_DIR / "aclstm-pilots.json"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="*")
    parser.add_argument("--frames", type=int, default=None, help="frames per seed (default 3000 for runs, 20000 for --feedback-noise)")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--which", choices=["best", "last"], default="best")
    parser.add_argument("--mocap", default=None)
    parser.add_argument("--feedback-noise", type=float, nargs="+", default=[], metavar="SIGMA")
    parser.add_argument("--rho", type=float, default=0.0, help="AR(1) coefficient of the feedback noise (0: white)")
    parser.add_argument("--pose-only", action="store_true", help="no feedback noise on the root's three channels")
    parser.add_argument("--model", default="aclstm", help="exported model id for --feedback-noise")
    parser.add_argument("--rollout-noise", type=float, default=0.0, help="white noise on each fed-back frame of a RUN's rollouts")
    parser.add_argument("--temperature", type=float, default=1.0, help="a Gaussian head's draws in the rollouts: its σ times this")
    parser.add_argument("--draw-rho", type=float, default=0.0, help="a Gaussian head's draws from AR(1) normals with this coefficient (0: white)")
    args = parser.parse_args(argv)
    if not args.runs and not args.feedback_noise:
        parser.error("give RUN names or --feedback-noise")
    saved = json.loads(PILOTS.read_text()) if PILOTS.exists() else {}
    if "pilots" not in saved:  # the first format: the pilot rows alone
        saved = {"pilots": saved, "feedback_noise": {}}
    table, sweeps = saved["pilots"], saved["feedback_noise"]
    mine, mine_sweeps = set(), set()  # what this call measured
    for sigma in args.feedback_noise:
        frames = args.frames or 20000
        w = feedback_noise_runs(MODELS_DIR, args.model, frames, sigma, args.rho, args.pose_only, mocap=args.mocap)
        key = f"{args.model} sigma {sigma:g} rho {args.rho:g} {'pose' if args.pose_only else 'all'} {frames}"
        sweeps[key] = w
        mine_sweeps.add(key)
        print(f"{args.model} feedback noise {sigma:g} (rho {args.rho:g}, {'pose' if args.pose_only else 'all'}): "
              f"{w['passes']}/{len(w['runs'])} pass, {w['diverged']} diverged")
    for name in args.runs:
        run_dir = RUNS_DIR / name
        m = measure_run(run_dir / f"{args.which}.pt", args.frames or 3000, args.seeds, args.mocap, args.rollout_noise, args.temperature, args.draw_rho)
        summary = json.loads((run_dir / "summary.json").read_text()) if (run_dir / "summary.json").exists() else {}
        m.pop("details")
        key = (f"{name}:{args.which}" + (f" +noise {args.rollout_noise:g}" if args.rollout_noise else "")
               + (f" temperature {args.temperature:g}" if args.temperature != 1 else "")
               + (f" draw rho {args.draw_rho:g}" if args.draw_rho else ""))
        table[key] = {**m, "summary": summary}
        mine.add(key)
        print(summary_line(key, m))
    # Another measurement may have written meanwhile (pilots run two at a time): merge into the file as it is now.
    latest = json.loads(PILOTS.read_text()) if PILOTS.exists() else {}
    if "pilots" in latest:
        table = {**latest["pilots"], **{k: table[k] for k in mine}}
        sweeps = {**latest["feedback_noise"], **{k: sweeps[k] for k in mine_sweeps}}
    PILOTS.write_text(json.dumps({"pilots": table, "feedback_noise": sweeps}, indent=1, default=str))
    PILOTS.with_suffix(".md").write_text(pilot_markdown(table, sweeps))
    print(f"wrote {PILOTS} and {PILOTS.with_suffix('.md')}")


if __name__ == "__main__":
    main()
