"""Measure the shipped VAE-LSTM and write docs/models/vae-lstm.{md,json}.

    python -m training.vae_lstm.evaluate
    python -m training.vae_lstm.evaluate --map-windows     # cache/vae-lstm-map-windows.json for npm run evaluate:vae-lstm
    python -m training.vae_lstm.evaluate --models DIR --out DIR2   # another export (e.g. its float32 files), report in DIR2
    python -m training.vae_lstm.evaluate --from-json     # vae-lstm.md again from vae-lstm.json, measuring nothing

Run npm run evaluate:vae-lstm first for the page's numbers on the benchmark paths; the measures are described in
training/vae_lstm/measures.py, the prose around them is docs/models/vae-lstm-notes.json.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..paths import DEFAULT_CACHE, MODELS_DIR, REPORTS_DIR, add_mocap_argument
from ..runs import add_from_json_argument, rewrote_from_json
from .measures import map_follow_windows
from .report import rewrite_vae_lstm_markdown, write_report

MAP_WINDOWS = DEFAULT_CACHE / "vae-lstm-map-windows.json"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--map-windows", action="store_true",
                        help=f"write only {MAP_WINDOWS}: the prediction windows' root paths for the MAP follower in the page")
    parser.add_argument("--models", type=Path, default=MODELS_DIR, help="the folder holding vae-lstm.json and its graphs")
    parser.add_argument("--out", type=Path, default=REPORTS_DIR, help="where to write vae-lstm.{md,json}")
    add_from_json_argument(parser, "vae-lstm")
    args = parser.parse_args(argv)
    if rewrote_from_json(args, "vae-lstm", rewrite_vae_lstm_markdown):
        return
    if args.map_windows:
        MAP_WINDOWS.parent.mkdir(parents=True, exist_ok=True)
        MAP_WINDOWS.write_text(json.dumps(map_follow_windows(WindowCorpus(load_clips(args.mocap)))))
        print(f"wrote {MAP_WINDOWS}")
        return
    if not (args.models / "vae-lstm.json").exists():
        raise SystemExit(f"error: no vae-lstm.json in {args.models}")
    report = write_report(args.mocap, args.models, args.out)
    rows = report["prediction"]["rows"]
    print(f"wrote {args.out / 'vae-lstm.md'}: at 120 frames (relative) " +
          ", ".join(f"{k} {v['relative_cm'][120]}" for k, v in rows.items()))


if __name__ == "__main__":
    main()
