"""Measure the shipped VAE-LSTM and write docs/models/vae-lstm.{md,json}.

    python -m training.vae_lstm.evaluate

Run npm run evaluate:vae-lstm first for the page's numbers on the benchmark paths; the measures are described in
training/vae_lstm/measures.py, the prose around them is docs/models/vae-lstm-notes.json.
"""
from __future__ import annotations

import argparse

from ..paths import REPORTS_DIR, add_mocap_argument
from .report import write_report


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    args = parser.parse_args(argv)
    report = write_report(args.mocap)
    rows = report["prediction"]["rows"]
    print(f"wrote {REPORTS_DIR / 'vae-lstm.md'}: at 120 frames (relative) " +
          ", ".join(f"{k} {v['relative_cm'][120]}" for k, v in rows.items()))


if __name__ == "__main__":
    main()
