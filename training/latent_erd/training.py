"""Training the control ERD (models/erd.py) in the autoencoder's latent space (the latent ERD) or on pose
rows (the pose-space baseline, Fragkiadaki-style), and reading checkpoints back.

Recipe: teacher forcing on random stretches of whole clips (sequences.py) with the next step's control,
mean squared error on the next step, Adam at 1e-3 halved at 60% and 85% of the run, gradients clipped
at norm 1. Gaussian input noise grows linearly from 0 to `noise` over the first half of the run
(Fragkiadaki et al.'s schedule, which keeps a free-running ERD from drifting off the data); dropout 0.2
before the decoder (Yearsley Ch. 6).
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from ..autoencoder.training import load_autoencoder
from ..data.locomotion import FPS, load_clips
from ..data.windows import WindowCorpus
from ..models.erd import ControlERD
from ..runs import Run
from .sequences import StepSequences, latent_sequences, pose_sequences

VALIDATE_EVERY = 250


def load_erd(checkpoint: Path) -> tuple[ControlERD, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = ControlERD(meta["dim"], meta["control_dim"], meta["hidden"], meta["layers"], meta["dropout"])
    model.load_state_dict(state["model"])
    return model.eval(), meta


def validation_loss(model: ControlERD, valid: StepSequences) -> float:
    """Mean squared next-step error over the held-out clips (teacher forcing, no noise)."""
    model.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for x, c in zip(valid.xs, valid.controls):
            xt = torch.from_numpy(x)[None]
            pred, _ = model(xt[:, :-1], torch.from_numpy(c)[None, 1:])
            total += float(((pred - xt[:, 1:]) ** 2).mean(-1).sum())
            count += len(x) - 1
    model.train()
    return total / max(count, 1)


def train_erd(args: argparse.Namespace) -> tuple[float, Path]:
    torch.set_num_threads(args.threads)
    run = Run(args.run, args.checkpoint_minutes)
    corpus = WindowCorpus(load_clips(args.mocap))
    meta = {"space": args.space, "fps": FPS, "hidden": args.hidden, "layers": args.layers, "dropout": args.dropout,
            "row_mean": corpus.mean.tolist(), "row_std": corpus.std.tolist(), "valid_files": corpus.valid_files,
            "args": vars(args)}
    if args.space == "latent":
        autoencoder, ae_meta = load_autoencoder(Path(args.autoencoder))
        train, valid, mean, std = latent_sequences(autoencoder, corpus)
        meta.update(latent_mean=mean.tolist(), latent_std=std.tolist(), autoencoder=str(args.autoencoder))
    else:
        train, valid = pose_sequences(corpus)
    meta.update(dim=train.dim, control_dim=train.control_dim)
    model = ControlERD(train.dim, train.control_dim, args.hidden, args.layers, args.dropout)
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    scheduler = torch.optim.lr_scheduler.MultiStepLR(optimiser, [int(args.iterations * 0.6), int(args.iterations * 0.85)], 0.5)
    rng = np.random.default_rng(args.seed)
    torch.manual_seed(args.seed)
    start, best, elapsed_before = 0, float("inf"), 0.0
    if args.resume:
        state = run.resume(rng, model=model, optimiser=optimiser, scheduler=scheduler)
        start, best, elapsed_before = state["iteration"], state["best"], state["elapsed"]
        run.log.info("resumed at iteration %d", start)
    params = sum(p.numel() for p in model.parameters())
    run.log.info("start: %s space, %d parameters, %d training sequences, %d held-out, steps of %d x %d",
                 args.space, params, len(train.xs), len(valid.xs), args.batch, args.steps)
    t0 = time.monotonic()
    elapsed = lambda: elapsed_before + time.monotonic() - t0

    def checkpoint(iteration: int) -> dict:
        return {"model": model.state_dict(), "optimiser": optimiser.state_dict(), "scheduler": scheduler.state_dict(),
                "rng": rng.bit_generator.state, "torch_rng": torch.get_rng_state(), "iteration": iteration,
                "best": best, "elapsed": elapsed(), "meta": meta}

    bar = tqdm(total=args.iterations, initial=start, desc=f"{args.space} ERD", unit="it")
    losses, it = [], start
    for it in range(start, args.iterations):
        x, c, y, mask = train.batch(rng, args.batch, args.steps)
        sigma = args.noise * min(1.0, it / max(1, args.iterations * 0.5))
        pred, _ = model(x + sigma * torch.randn_like(x), c)
        loss = (((pred - y) ** 2).mean(-1) * mask).sum() / mask.sum()
        optimiser.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        optimiser.step()
        scheduler.step()
        losses.append(float(loss))
        bar.update(1)
        bar.set_postfix(loss=f"{np.mean(losses[-50:]):.4f}", noise=f"{sigma:.2f}")
        if (it + 1) % VALIDATE_EVERY == 0 or it + 1 == args.iterations:
            val = validation_loss(model, valid)
            if val < best:
                best = val
                run.save({"model": model.state_dict(), "iteration": it + 1, "valid_loss": val, "meta": meta}, run.best_path)
            run.log.info("iteration %d train %.4f held-out %.4f best %.4f noise %.2f minutes %.1f", it + 1,
                         np.mean(losses[-VALIDATE_EVERY:]), val, best, sigma, elapsed() / 60)
        if run.due():
            run.save(checkpoint(it + 1))
        if elapsed() > args.minutes * 60:
            run.log.info("stopped: time budget of %.0f minutes used (iteration %d)", args.minutes, it + 1)
            break
    bar.close()
    run.save(checkpoint(it + 1))
    run.save({"model": model.state_dict(), "iteration": it + 1, "meta": meta}, run.dir / "last.pt")
    (run.dir / "summary.json").write_text(json.dumps({"best_valid_loss": best, "iterations": it + 1,
                                                       "minutes": elapsed() / 60, "parameters": params}, indent=1))
    return best, run.dir
