"""Fit again what the shipped VAE-LSTM draws and reads besides its graphs: the z1 prior, the posteriors of random
training starts (prior_bank.py; vae-lstm.json sampling.z1_prior), and the stride a drawn path lacks (stride.py;
vae-lstm.json stride); tests/fixtures/vae_lstm_reference.json is written again.

    python -m training.vae_lstm.fit_sampling [--mocap DIR]

A new export from a checkpoint (python -m training.vae_lstm.export) fits it too.
"""
from __future__ import annotations

import argparse

from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from .exporting import refit_sampling_fields


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mocap", default=None, help="the corpus (default ../shared/mocap or MOCAP_DIR)")
    args = parser.parse_args(argv)
    info = refit_sampling_fields(WindowCorpus(load_clips(args.mocap)))
    prior = info["sampling"].get("z1_prior")
    if prior:
        print(f"vae-lstm.json: z1 prior from {prior['starts']} training starts, sigma {sum(prior['sigma']) / len(prior['sigma']):.3f} on average")
    bands = info["stride"]["bands"]
    print("vae-lstm.json: stride " + ", ".join(f"{b['speed']:.2f} m/s every {b['period_s']:.2f} s ({b['strides']} strides)" for b in bands))


if __name__ == "__main__":
    main()
