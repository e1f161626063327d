"""Export the trained VAE-LSTM to public/models/vae-lstm*.onnx and vae-lstm.json (parity checked), and write
tests/fixtures/vae_lstm_reference.json.

    python -m training.vae_lstm.export [--checkpoint runs/vae-lstm/best.pt] [--out public/models] [--sampling steps --rho 0.9]
    python -m training.vae_lstm.export --from-shipped [DIR] [--weights int8]   # no checkpoint: rewrite the shipped files

--sampling says how the page draws a seed's prior sample: "z1" (Algorithm 1: one latent, the cell on its own
state) or "steps" (a latent per step in teacher mode, AR(1) with lag-one correlation --rho); generation.py. For
"z1", --z1-prior posteriors (the default) draws z1 from the posteriors of training starts (prior_bank.py); every
export also fits the stride a drawn path lacks (stride.py), from the corpus.
--weights says how the files store their large weights (int8 with a scale per output channel, float16, float32;
training/onnx/compact.py); parity and the fixture are against torch with the weights as stored.
--from-shipped DIR reads the network back from DIR's four graphs (default the shipped ones; recovery.py) and keeps
DIR/vae-lstm.json but for its parity, bytes and weights fields: start from a float32 export when there is one.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from ..onnx.compact import FORMATS
from ..runs import add_export_arguments
from .exporting import export_vae_lstm, rewrite_vae_lstm
from .training import load_vae_lstm


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sampling", choices=["z1", "steps"], default="z1")
    parser.add_argument("--rho", type=float, default=0.9, help="steps: lag-one correlation of the per-step latents")
    parser.add_argument("--z1-prior", choices=["posteriors", "normal"], default="posteriors",
                        help="z1: draw it from the posteriors of training starts (prior_bank.py) or N(0, I)")
    parser.add_argument("--mocap", default=None, help="the training corpus, for the z1 prior and the stride (default ../shared/mocap or MOCAP_DIR)")
    add_export_arguments(parser, FORMATS, run="vae-lstm", weights_help="how the files store their large weights",
                         shipped_help="no checkpoint: read the network back from DIR's graphs (default the shipped ones) and keep its JSON")
    args = parser.parse_args(argv)
    if args.from_shipped is not None:
        if not (args.from_shipped / "vae-lstm.json").exists():
            raise SystemExit(f"error: no vae-lstm.json in {args.from_shipped}")
        try:
            rewrite_vae_lstm(args.from_shipped, args.out, args.weights)
        except ValueError as e:
            raise SystemExit(f"error: {e}")
        return
    checkpoint = Path(args.checkpoint)
    if not checkpoint.exists():
        raise SystemExit(f"error: no checkpoint at {checkpoint} (train first: python -m training.vae_lstm.train, "
                         "or rewrite the shipped files with --from-shipped)")
    model, meta = load_vae_lstm(checkpoint)
    if not 0 <= args.rho < 1:
        raise SystemExit(f"error: --rho must be in [0, 1), got {args.rho}")
    free_mix = float(meta["args"].get("free_mix", 0.0))
    # A model trained with z1 in every step of its free mode (--free-mix) is run that way (generation.free_latents).
    sampling = ({"mode": "z1", "mix": free_mix} if free_mix > 0 else {"mode": "z1"}) if args.sampling == "z1" else {"mode": "steps", "rho": args.rho}
    export_vae_lstm(model, meta, {}, sampling, args.out, args.weights, corpus=WindowCorpus(load_clips(args.mocap)),
                    z1_prior=args.z1_prior == "posteriors")


if __name__ == "__main__":
    main()
