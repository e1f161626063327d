"""Training the motion autoencoder on 4 s windows of CMU locomotion (data/windows.py), and reading its
checkpoints back.

Recipe (Yearsley §3.1.1): masked noise with p = 0.3 on the normalised input, mean squared error against the
clean window (the control channels weighted CONTROL_WEIGHT times), Adam with its default settings (lr 1e-3), here with
batches of 32 random windows and the learning rate halved twice late in the run; Holden's L1 penalty on the
latent is off (SPARSITY).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import torch

from ..data.locomotion import FPS, load_clips
from ..data.windows import CONTROL_SLICE, POSITION_DIM, ROW_DIM, WINDOW, WindowCorpus
from ..models.autoencoder import MotionAutoencoder, masked_noise
from ..runs import TrainingLoop

# Holden's Lasso term: an L1 penalty on the latent. With ReLU latents it kills channels: at 1e-3, 232 of the
# 256 channels never fired on the training windows (55 live without the control weighting, 24 with it), so it
# is off by default (--sparsity).
SPARSITY = 0.0
VALIDATE_EVERY = 250  # iterations
# The control channels are 3 of 80, but the page moves the root by the decoded control: with equal weights
# a pilot decoded the turn rate with 0.5-0.9 rad/s RMS error (and a bias of 0.4 rad/s on one held-out clip),
# so a perfect latent sequence still walked metres off its course. They count CONTROL_WEIGHT times.
CONTROL_WEIGHT = 10.0


def load_autoencoder(checkpoint: Path) -> tuple[MotionAutoencoder, dict]:
    """The model (eval mode) and its meta."""
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = MotionAutoencoder(meta["dim"], meta["hidden"], meta["latent"])
    model.load_state_dict(state["model"])
    return model.eval(), meta


def position_error_cm(model: MotionAutoencoder, corpus: WindowCorpus, windows: np.ndarray, mask_p: float = 0.0,
                      seed: int = 0) -> float:
    """Mean distance (cm) per joint and frame between the clean windows' joint positions (root facing frame)
    and the reconstruction from the windows, corrupted by masked noise with probability `mask_p`."""
    torch.manual_seed(seed)
    x = torch.from_numpy(windows)
    with torch.no_grad():
        y = model(masked_noise(x, mask_p) if mask_p > 0 else x)[0].numpy()
    std, mean = corpus.std[:POSITION_DIM], corpus.mean[:POSITION_DIM]
    real = (windows[..., :POSITION_DIM] * std + mean).reshape(*windows.shape[:2], -1, 3)
    made = (y[..., :POSITION_DIM] * std + mean).reshape(*windows.shape[:2], -1, 3)
    return float(np.linalg.norm(real - made, axis=-1).mean() * 100)


def control_rmse(model: MotionAutoencoder, corpus: WindowCorpus, windows: np.ndarray) -> np.ndarray:
    """RMS error of the reconstructed control (forward m/s, sideways m/s, turn rad/s) from clean windows."""
    with torch.no_grad():
        y = model(torch.from_numpy(windows))[0].numpy()
    std = corpus.std[CONTROL_SLICE]
    return np.sqrt((((y - windows)[..., CONTROL_SLICE] * std) ** 2).mean(axis=(0, 1)))


def live_channels(model: MotionAutoencoder, corpus: WindowCorpus) -> int:
    """Latent channels that ever fire on the training clips (ReLU channels can die in training)."""
    with torch.no_grad():
        z = np.concatenate([model.encode(torch.from_numpy(s[None, :len(s) // 4 * 4])).numpy()[0] for s in corpus.train])
    return int((z.std(axis=0) > 1e-3).sum())


def train_autoencoder(args: argparse.Namespace) -> tuple[float, Path]:
    """One run with the options of python -m training.autoencoder.train; returns the best held-out
    reconstruction error (cm, clean input) and the run directory."""
    loop = TrainingLoop(args)
    run = loop.run
    corpus = WindowCorpus(load_clips(args.mocap))
    valid = corpus.valid_windows()
    model = MotionAutoencoder(ROW_DIM, args.hidden, args.latent)
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    milestones = [int(args.iterations * 0.7), int(args.iterations * 0.9)]
    scheduler = torch.optim.lr_scheduler.MultiStepLR(optimiser, milestones, gamma=0.5)
    rng = loop.seed()
    meta = {"dim": ROW_DIM, "hidden": args.hidden, "latent": args.latent, "fps": FPS, "window": WINDOW,
            "mean": corpus.mean.tolist(), "std": corpus.std.tolist(), "valid_files": corpus.valid_files,
            "train_frames": corpus.train_frames, "args": vars(args)}
    start = loop.start(meta, model=model, optimiser=optimiser, scheduler=scheduler)
    run.log.info("start: %d parameters, %d training frames (augmented), %d held-out windows", loop.parameters,
                 corpus.train_frames, len(valid))
    weights = torch.ones(ROW_DIM)
    weights[CONTROL_SLICE] = args.control_weight
    weights /= weights.mean()
    bar = loop.progress_bar("autoencoder", args.iterations, start)
    losses, it = [], start
    for it in range(start, args.iterations):
        x = corpus.batch(rng, args.batch)
        y, z = model(masked_noise(x, args.mask))
        loss = (((y - x) ** 2) * weights).mean() + args.sparsity * z.abs().mean()
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        scheduler.step()
        losses.append(float(loss))
        bar.update(1)
        bar.set_postfix(loss=f"{np.mean(losses[-50:]):.4f}")
        if (it + 1) % VALIDATE_EVERY == 0 or it + 1 == args.iterations:
            model.eval()
            clean, noisy = position_error_cm(model, corpus, valid), position_error_cm(model, corpus, valid, args.mask)
            turn = control_rmse(model, corpus, valid)
            model.train()
            if clean < loop.best:
                loop.best = clean
                run.save({"model": model.state_dict(), "iteration": it + 1, "valid_cm": clean, "meta": meta}, run.best_path)
            run.log.info("iteration %d loss %.4f held-out error %.2f cm clean, %.2f cm masked (p=%.1f) best %.2f; control RMS "
                         "error %s minutes %.1f", it + 1, np.mean(losses[-VALIDATE_EVERY:]), clean, noisy, args.mask, loop.best,
                         np.round(turn, 3).tolist(), loop.elapsed() / 60)
        if loop.step_done(it + 1):
            break
    loop.finish(it + 1, {"best_valid_cm": loop.best, "iterations": it + 1})
    return loop.best, run.dir
