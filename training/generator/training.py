"""Training the locomotion generator (LSTM + Gaussian mixture) on CMU walking and running, and reading its
checkpoints back.

Recipe from Wang, Chai, Xia §4.1.3: 30 fps, Gaussian input noise sigma 0.05 (in normalised units),
RMSProp with learning rate 1e-3 multiplied by 0.95 each epoch, gradients clipped to [-5, 5],
batches of 20 windows of 50 frames. Clips are split into training and validation by clip
(data/locomotion.py, which also adds the mirrored and speed-changed copies). Dropout (0.25) keeps the
mixture from overfitting the small corpus: without it, validation NLL rises after about 10 epochs while
training NLL keeps falling.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import torch

from ..data.locomotion import FPS, Corpus, load_clips
from ..models.generator import MixtureLSTM, mixture_nll
from ..runs import TrainingLoop

NOISE_SIGMA = 0.05


def load_generator(checkpoint: Path) -> tuple[MixtureLSTM, dict, dict]:
    """The model (eval mode), its meta and the whole checkpoint dictionary; a style generator's checkpoint (issue 39,
    meta with `styles`) gives the model with its style input."""
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    styles = len(meta.get("styles", ()))
    model = MixtureLSTM(meta["dim"], meta["hidden"], meta["mixtures"], styles=styles, style_dim=meta.get("style_dim", 8))
    model.load_state_dict(state["model"])
    return model.eval(), meta, state


def validation_nll(model: MixtureLSTM, corpus: Corpus) -> float:
    """Mean NLL per frame over whole held-out clips (teacher forcing, no noise)."""
    model.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for seq in corpus.valid:
            if len(seq) < 2:
                continue
            x = torch.from_numpy(seq).unsqueeze(0)
            logits, mu, log_sigma, _ = model(x[:, :-1])
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            total += float(nll.sum())
            count += nll.numel()
    model.train()
    return total / max(count, 1)


def train_generator(args: argparse.Namespace) -> tuple[float, Path]:
    """One training run with the options of python -m training.generator.train (all kept in the checkpoint's
    meta); returns the best validation NLL and the run directory."""
    loop = TrainingLoop(args)
    run = loop.run
    corpus = Corpus(load_clips(args.mocap))
    dim = corpus.mean.shape[0]
    model = MixtureLSTM(dim, args.hidden, dropout=args.dropout)
    optimiser = torch.optim.RMSprop(model.parameters(), lr=args.lr, alpha=0.9)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimiser, gamma=0.95)
    rng = loop.seed()
    iters_per_epoch = args.iters_per_epoch
    meta = {"dim": dim, "hidden": args.hidden, "mixtures": model.mixtures, "fps": FPS,
            "mean": corpus.mean.tolist(), "std": corpus.std.tolist(),
            "references": corpus.codec.references.tolist(), "valid_files": corpus.valid_files,
            "train_frames": corpus.train_frames, "args": vars(args)}
    # The checkpoint's "iteration" counts within its "epoch" (0-based), the epoch the schedule is in.
    iteration = loop.start(meta, "epoch {epoch} iteration {iteration}", model=model, optimiser=optimiser, scheduler=scheduler)
    epoch = loop.resumed["epoch"] if loop.resumed else 0
    run.log.info("start: %d features, %d parameters, %d training frames (with mirroring), %d validation clips, "
                 "%d iterations per epoch", dim, loop.parameters, corpus.train_frames, len(corpus.valid), iters_per_epoch)
    bar = loop.progress_bar("generator", args.epochs * iters_per_epoch, epoch * iters_per_epoch + iteration)
    out_of_time = False
    while epoch < args.epochs:
        losses = []
        while iteration < iters_per_epoch:
            x, mask = corpus.batch(rng, args.batch, args.window)
            inputs = x[:, :-1] + NOISE_SIGMA * torch.randn_like(x[:, :-1])
            logits, mu, log_sigma, _ = model(inputs)
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            loss = (nll * mask).sum() / mask.sum()
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_value_(model.parameters(), 5.0)
            optimiser.step()
            iteration += 1
            losses.append(float(loss))
            bar.update(1)
            bar.set_postfix(epoch=epoch + 1, nll=f"{np.mean(losses[-50:]):.2f}")
            out_of_time = loop.step_done(iteration, epoch=epoch)
            if out_of_time:
                break
        if out_of_time:
            break
        scheduler.step()
        val = validation_nll(model, corpus)
        epoch, iteration = epoch + 1, 0
        if val < loop.best:
            loop.best = val
            run.save({"model": model.state_dict(), "epoch": epoch, "valid_nll": val, "meta": meta}, run.best_path)
        loop.save(iteration, epoch=epoch)
        run.log.info("epoch %d train_nll %.3f valid_nll %.3f best %.3f lr %.2e minutes %.1f", epoch,
                     np.mean(losses), val, loop.best, scheduler.get_last_lr()[0], loop.elapsed() / 60)
    # `epoch` is the number of whole epochs done: the one the time budget cut short does not count.
    loop.finish(iteration, {"best_valid_nll": loop.best, "epochs_done": epoch}, epoch=epoch)
    return loop.best, run.dir
