"""Fit the shipped VAE-LSTM's z1 prior again: the posteriors of random training starts (prior_bank.py), written into
public/models/vae-lstm.json's sampling.z1_prior, and tests/fixtures/vae_lstm_reference.json written again.

    python -m training.vae_lstm.fit_prior [--mocap DIR]

A new export from a checkpoint (python -m training.vae_lstm.export) fits it too.
"""
from __future__ import annotations

import argparse

from ..data.locomotion import load_clips
from ..data.windows import WindowCorpus
from .exporting import refit_z1_prior


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mocap", default=None, help="the corpus (default ../shared/mocap or MOCAP_DIR)")
    args = parser.parse_args(argv)
    try:
        info = refit_z1_prior(WindowCorpus(load_clips(args.mocap)))
    except ValueError as e:
        raise SystemExit(f"error: {e}")
    prior = info["sampling"]["z1_prior"]
    print(f"vae-lstm.json: z1 prior from {prior['starts']} training starts, sigma {sum(prior['sigma']) / len(prior['sigma']):.3f} on average")


if __name__ == "__main__":
    main()
