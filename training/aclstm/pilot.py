"""Measure dance-model training runs quickly (issue 18's pilots) and add them to docs/models/aclstm-pilots.{json,md}.

    python -m training.aclstm.pilot RUN [RUN ...] [--frames 3000] [--seeds 3] [--which best|last]
    python -m training.aclstm.pilot --feedback-noise 0.1 0.15 [--rho 0.9] [--pose-only] [--model aclstm] [--frames 20000]
    python -m training.aclstm.pilot RUN --phrase-tune     # an mdn head: phrase sampling, chosen per style on held-out windows
    python -m training.aclstm.pilot RUN --which last --sweep indian --temperatures 0.7 1.0 1.4   # one style, hotter than the export's grid

An mdn head's rollouts use the phrase sampler (training/aclstm/phrase_sampling.py): --temperature, --max-hold, --draw-rho
and --threshold for every style, or --phrase-tune: each style's setting chosen from a grid on held-out seed windows
that the judged runs do not start from (pilots.tune_phrase), written to docs/models/aclstm-phrase-tuning.json.

Each RUN is a folder under runs/ (its best.pt, or last.pt with --which last). --feedback-noise measures an exported
model (public/models/) with noise on each fed-back frame instead, 5 seeds per style. What is measured:
training/aclstm/pilots.py.
"""
from __future__ import annotations

import argparse
import json

from ..data.dance import STYLES
from ..paths import MODELS_DIR, REPORTS_DIR
from ..runs import RUNS_DIR
from .phrase_sampling import PhraseParams
from .pilots import (feedback_noise_runs, measure_run, pilot_markdown, summary_line, temperature_sweep, tune_phrase, tuning_grid,
                     tuning_row_text)

PILOTS = REPORTS_DIR / "aclstm-pilots.json"
SWEEPS = REPORTS_DIR / "aclstm-temperature-sweeps.json"
TUNING = REPORTS_DIR / "aclstm-phrase-tuning.json"


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
    parser.add_argument("--max-hold", type=int, default=30, help="an mdn head's phrase: redraw the component at least every this many frames")
    parser.add_argument("--threshold", type=float, default=0.05, help="an mdn head's phrase: redraw when the held component's weight falls below this")
    parser.add_argument("--phrase-tune", action="store_true", help="an mdn head: choose temperature, max hold and rho per style on held-out windows")
    parser.add_argument("--tune-frames", type=int, default=1200)
    parser.add_argument("--sweep", choices=STYLES, default=None,
                        help="an mdn head: this style's tuning runs at --temperatures (3,000 frames), into "
                             "docs/models/aclstm-temperature-sweeps.json; nothing else is measured")
    parser.add_argument("--temperatures", type=float, nargs="+", default=[0.7, 1.0, 1.4])
    args = parser.parse_args(argv)
    if args.sweep:
        if not args.runs:
            parser.error("--sweep needs a RUN")
        for name in args.runs:
            swept = temperature_sweep(RUNS_DIR / name / f"{args.which}.pt", args.sweep, tuple(args.temperatures), mocap=args.mocap)
            # Read just before writing: another sweep may have written meanwhile (sweeps run two at a time).
            sweeps = json.loads(SWEEPS.read_text()) if SWEEPS.exists() else {}
            sweeps[f"{name}:{args.which} {args.sweep}"] = swept
            SWEEPS.write_text(json.dumps(sweeps, indent=1))
            for share, rows in swept["rows"].items():
                for r in rows:
                    p = r["params"]
                    print(f"{name} {args.sweep} cutoff share {share} τ {p['temperature']:g} hold {p['max_hold']} ρ {p['rho']:g}: "
                          + tuning_row_text(r))
        print(f"wrote {SWEEPS}")
        return
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
        checkpoint = run_dir / f"{args.which}.pt"
        phrase, tag = None, ""
        if args.phrase_tune:
            tuned = tune_phrase(checkpoint, tuning_grid(args.threshold), args.tune_frames, mocap=args.mocap)
            TUNING.write_text(json.dumps({**(json.loads(TUNING.read_text()) if TUNING.exists() else {}),
                                          f"{name}:{args.which}": tuned}, indent=1))
            phrase = {s: PhraseParams(**v["best"]) for s, v in tuned["styles"].items()}
            tag = " phrase tuned"
            for s, v in tuned["styles"].items():
                print(f"{s}: chosen {v['best']} (tuning: {v['table'][0]['passes']}/{v['table'][0]['runs']} pass, "
                      f"median {v['table'][0]['median_ratio']:.0%}, jitter {v['table'][0]['jitter_vs_real']:.1f}x)")
        elif args.temperature != 1 or args.draw_rho or args.max_hold != 30:
            phrase = {s: PhraseParams(args.temperature, args.max_hold, args.draw_rho, args.threshold) for s in STYLES}
            tag = f" phrase t {args.temperature:g} hold {args.max_hold} rho {args.draw_rho:g}"
        m = measure_run(checkpoint, args.frames or 3000, args.seeds, args.mocap, args.rollout_noise, args.temperature, args.draw_rho, phrase)
        summary = json.loads((run_dir / "summary.json").read_text()) if (run_dir / "summary.json").exists() else {}
        m.pop("details")
        if m["args"].get("head") == "mdn":
            key = f"{name}:{args.which}" + (tag or " phrase default")
        else:
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
