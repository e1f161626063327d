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
import json
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from ..data.locomotion import FPS, Corpus, load_clips
from ..models.generator import MixtureLSTM, mixture_nll
from ..runs import Run

NOISE_SIGMA = 0.05


def load_generator(checkpoint: Path) -> tuple[MixtureLSTM, dict, dict]:
    """The model (eval mode), its meta and the whole checkpoint dictionary."""
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = MixtureLSTM(meta["dim"], meta["hidden"], meta["mixtures"])
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
    torch.set_num_threads(args.threads)
    run = Run(args.run, args.checkpoint_minutes)
    corpus = Corpus(load_clips(args.mocap))
    dim = corpus.mean.shape[0]
    model = MixtureLSTM(dim, args.hidden, dropout=args.dropout)
    optimiser = torch.optim.RMSprop(model.parameters(), lr=args.lr, alpha=0.9)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimiser, gamma=0.95)
    rng = np.random.default_rng(args.seed)
    torch.manual_seed(args.seed)
    iters_per_epoch = args.iters_per_epoch
    start_epoch, start_iter, best, elapsed_before = 0, 0, float("inf"), 0.0
    if args.resume:
        state = run.resume(rng, model=model, optimiser=optimiser, scheduler=scheduler)
        start_epoch, start_iter, best = state["epoch"], state["iteration"], state["best"]
        elapsed_before = state["elapsed"]
        run.log.info("resumed at epoch %d iteration %d", start_epoch, start_iter)
    meta = {"dim": dim, "hidden": args.hidden, "mixtures": model.mixtures, "fps": FPS,
            "mean": corpus.mean.tolist(), "std": corpus.std.tolist(),
            "references": corpus.codec.references.tolist(), "valid_files": corpus.valid_files,
            "train_frames": corpus.train_frames, "args": vars(args)}
    params = sum(p.numel() for p in model.parameters())
    run.log.info("start: %d features, %d parameters, %d training frames (with mirroring), %d validation clips, "
                 "%d iterations per epoch", dim, params, corpus.train_frames, len(corpus.valid), iters_per_epoch)
    t0 = time.monotonic()

    def checkpoint(epoch: int, iteration: int) -> dict:
        return {"model": model.state_dict(), "optimiser": optimiser.state_dict(), "scheduler": scheduler.state_dict(),
                "rng": rng.bit_generator.state, "torch_rng": torch.get_rng_state(), "epoch": epoch,
                "iteration": iteration, "best": best, "elapsed": elapsed_before + time.monotonic() - t0, "meta": meta}

    total = args.epochs * iters_per_epoch
    bar = tqdm(total=total, initial=start_epoch * iters_per_epoch + start_iter, desc="generator", unit="it")
    out_of_time = False
    for epoch in range(start_epoch, args.epochs):
        losses = []
        for it in range(start_iter if epoch == start_epoch else 0, iters_per_epoch):
            x, mask = corpus.batch(rng, args.batch, args.window)
            inputs = x[:, :-1] + NOISE_SIGMA * torch.randn_like(x[:, :-1])
            logits, mu, log_sigma, _ = model(inputs)
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            loss = (nll * mask).sum() / mask.sum()
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_value_(model.parameters(), 5.0)
            optimiser.step()
            losses.append(float(loss))
            bar.update(1)
            bar.set_postfix(epoch=epoch + 1, nll=f"{np.mean(losses[-50:]):.2f}")
            if run.due():
                run.save(checkpoint(epoch, it + 1))
            if elapsed_before + time.monotonic() - t0 > args.minutes * 60:
                out_of_time = True
                run.save(checkpoint(epoch, it + 1))
                break
        if out_of_time:
            run.log.info("stopped: time budget of %.0f minutes used (epoch %d)", args.minutes, epoch + 1)
            break
        scheduler.step()
        val = validation_nll(model, corpus)
        if val < best:
            best = val
            run.save({"model": model.state_dict(), "epoch": epoch + 1, "valid_nll": val, "meta": meta}, run.best_path)
        run.save(checkpoint(epoch + 1, 0))
        run.log.info("epoch %d train_nll %.3f valid_nll %.3f best %.3f lr %.2e minutes %.1f", epoch + 1,
                     np.mean(losses), val, best, scheduler.get_last_lr()[0], (elapsed_before + time.monotonic() - t0) / 60)
    bar.close()
    (run.dir / "summary.json").write_text(json.dumps({"best_valid_nll": best, "epochs_done": epoch + 1 if not out_of_time else epoch,
                                                       "minutes": (elapsed_before + time.monotonic() - t0) / 60, "parameters": params}, indent=1))
    return best, run.dir
