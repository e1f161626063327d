"""Export the trained VAE-LSTM to public/models/vae-lstm*.onnx and vae-lstm.json (parity checked), and write
tests/fixtures/vae_lstm_reference.json.

    python -m training.vae_lstm.export [--checkpoint runs/vae-lstm/best.pt] [--out public/models] [--sampling steps --rho 0.9]

--sampling says how the page draws a seed's prior sample: "z1" (Algorithm 1: one latent, the cell on its own
state) or "steps" (a latent per step in teacher mode, AR(1) with lag-one correlation --rho); generation.py.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..paths import MODELS_DIR, REPO_ROOT
from .exporting import export_vae_lstm
from .training import load_vae_lstm


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", default=str(REPO_ROOT / "runs" / "vae-lstm" / "best.pt"))
    parser.add_argument("--out", default=str(MODELS_DIR))
    parser.add_argument("--sampling", choices=["z1", "steps"], default="z1")
    parser.add_argument("--rho", type=float, default=0.9, help="steps: lag-one correlation of the per-step latents")
    args = parser.parse_args(argv)
    checkpoint = Path(args.checkpoint)
    if not checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {checkpoint} (train first: python -m training.vae_lstm.train)")
    model, meta = load_vae_lstm(checkpoint)
    if not 0 <= args.rho < 1:
        raise SystemExit(f"error: --rho must be in [0, 1), got {args.rho}")
    sampling = {"mode": "z1"} if args.sampling == "z1" else {"mode": "steps", "rho": args.rho}
    export_vae_lstm(model, meta, {}, sampling, Path(args.out))


if __name__ == "__main__":
    main()
