"""Training the style-conditioned locomotion generator (issue 39) on CMU walking and running plus the Bandai Namco set,
and reading its checkpoints back.

The generator's recipe (training/generator/training.py, Wang, Chai, Xia §4.1.3: input noise sigma 0.05, RMSProp 1e-3
decayed by 0.95 per epoch of --iters-per-epoch, gradients clipped to [-5, 5], batches of 20 windows of 50 frames,
dropout 0.25) on data/style_locomotion.py's StyleCorpus, with one learned embedding per style (CMU is style 0, Bandai's
seven are 1-7) concatenated to the input frame at every step (models/generator.py MixtureLSTM(styles=8)). Windows are
drawn with each style equally often (StyleCorpus), or CMU's windows with --cmu-share. Validation: mean NLL per frame over the held-out clips of each
style (teacher forcing, no noise), and their mean over styles, which picks best.pt.

The rotation references are the shipped generator's (public/models/generator.json) unless --fit-references: the CMU
features then mean what they mean for the shipped model, so NLLs of the two models compare (normalisation aside,
which the pilot measures correct for) and the page's decoder needs no new references.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch

from ..data.locomotion import FPS
from ..data.style_locomotion import STYLES, StyleCorpus, load_styled_clips
from ..mocap.rotations import quat_to_matrix
from ..models.generator import MixtureLSTM, mixture_nll
from ..paths import MODELS_DIR
from ..runs import TrainingLoop
from .warm_start import warm_start

NOISE_SIGMA = 0.05
LICENCE = "CC BY-NC 4.0 (trained on the Bandai Namco set: non-commercial)"


def shipped_references(models_dir: Path = MODELS_DIR) -> np.ndarray:
    """The shipped generator's rotation references (joints, 3, 3)."""
    info = json.loads((models_dir / "generator.json").read_text())
    return quat_to_matrix(np.array(info["features"]["references"], np.float64))


def nll_per_clip(model, seqs: list[np.ndarray], styles: np.ndarray | None) -> list[tuple[float, int]]:
    """(summed NLL, frames) of each held-out sequence under `model` (teacher forcing, no noise); `styles` None for a
    model without a style input."""
    model.eval()
    out = []
    with torch.no_grad():
        for k, seq in enumerate(seqs):
            if len(seq) < 2:
                out.append((0.0, 0))
                continue
            x = torch.from_numpy(seq).unsqueeze(0)
            if styles is None:
                logits, mu, log_sigma, _ = model(x[:, :-1])
            else:
                logits, mu, log_sigma, _ = model(x[:, :-1], None, torch.tensor([int(styles[k])]))
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            out.append((float(nll.sum()), nll.numel()))
    return out


def validation_by_style(model: MixtureLSTM, corpus: StyleCorpus) -> dict[str, float]:
    """Mean NLL per frame over each style's held-out clips, and "mean": their mean over styles."""
    per_clip = nll_per_clip(model, corpus.valid, corpus.valid_styles)
    out = {}
    for i, name in enumerate(STYLES):
        total = sum(t for (t, n), s in zip(per_clip, corpus.valid_styles) if s == i)
        count = sum(n for (t, n), s in zip(per_clip, corpus.valid_styles) if s == i)
        if count:
            out[name] = total / count
    out["mean"] = float(np.mean([v for v in out.values()]))
    model.train()
    return out


def train_style_generator(args: argparse.Namespace) -> tuple[float, Path]:
    """One run with the options of python -m training.style_generator.train (kept in the checkpoint's meta); returns the
    best validation NLL (mean over styles) and the run directory."""
    loop = TrainingLoop(args)
    run = loop.run
    references = None if args.fit_references else shipped_references()
    corpus = StyleCorpus(load_styled_clips(args.mocap), references, cmu_share=args.cmu_share)
    dim = corpus.mean.shape[0]
    model = MixtureLSTM(dim, args.hidden, dropout=args.dropout, styles=len(STYLES), style_dim=args.style_dim)
    if getattr(args, "init_from_shipped", False) and not args.resume:
        warm_start(model, corpus.mean, corpus.std)
    optimiser = torch.optim.RMSprop(model.parameters(), lr=args.lr, alpha=0.9)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimiser, gamma=0.95)
    rng = loop.seed()
    iters_per_epoch = args.iters_per_epoch
    meta = {"dim": dim, "hidden": args.hidden, "mixtures": model.mixtures, "fps": FPS, "styles": list(STYLES),
            "style_dim": args.style_dim, "mean": corpus.mean.tolist(), "std": corpus.std.tolist(),
            "references": corpus.codec.references.tolist(), "valid_files": corpus.valid_files,
            "valid_styles": corpus.valid_styles.tolist(), "train_frames": corpus.train_frames,
            "train_frames_per_style": corpus.train_frames_per_style, "licence": LICENCE, "args": vars(args)}
    iteration = loop.start(meta, "epoch {epoch} iteration {iteration}", model=model, optimiser=optimiser, scheduler=scheduler)
    epoch = loop.resumed["epoch"] if loop.resumed else 0
    run.log.info("start: %d features, %d styles (%s), %d parameters, %d training frames (mirrored, speed copies), "
                 "%d validation clips, %d iterations per epoch", dim, len(STYLES), ", ".join(STYLES), loop.parameters,
                 corpus.train_frames, len(corpus.valid), iters_per_epoch)
    run.log.info("training frames per style: %s", corpus.train_frames_per_style)
    # CMU guard: best.pt is the best mean over styles among the epochs whose CMU held-out NLL is within --cmu-guard of
    # the first validation's (the shipped weights' when warm-started), so CMU never gets worse than that by more.
    cmu_limit = loop.resumed.get("cmu_limit") if loop.resumed else None
    if cmu_limit is None and args.cmu_guard is not None:
        first = validation_by_style(model, corpus)
        cmu_limit = first["cmu"] + args.cmu_guard
        run.log.info("before training: valid_nll mean %.3f | %s; CMU guard: best.pt needs cmu <= %.2f", first["mean"],
                     " ".join(f"{k} {v:.2f}" for k, v in first.items() if k != "mean"), cmu_limit)
    bar = loop.progress_bar("style generator", args.epochs * iters_per_epoch, epoch * iters_per_epoch + iteration)
    out_of_time = False
    while epoch < args.epochs:
        losses = []
        while iteration < iters_per_epoch:
            x, mask, style = corpus.batch(rng, args.batch, args.window)
            inputs = x[:, :-1] + NOISE_SIGMA * torch.randn_like(x[:, :-1])
            logits, mu, log_sigma, _ = model(inputs, None, style)
            nll = mixture_nll(logits, mu, log_sigma, x[:, 1:])
            loss = (nll * mask).sum() / mask.sum()
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_value_(model.parameters(), 5.0)
            optimiser.step()
            iteration += 1
            losses.append(loss.item())
            bar.update(1)
            bar.set_postfix(epoch=epoch + 1, nll=f"{np.mean(losses[-50:]):.2f}")
            out_of_time = loop.step_done(iteration, epoch=epoch, cmu_limit=cmu_limit)
            if out_of_time:
                break
        if out_of_time:
            break
        scheduler.step()
        val = validation_by_style(model, corpus)
        epoch, iteration = epoch + 1, 0
        if val["mean"] < loop.best and (cmu_limit is None or val["cmu"] <= cmu_limit):
            loop.best = val["mean"]
            run.save({"model": model.state_dict(), "epoch": epoch, "valid_nll": val, "meta": meta}, run.best_path)
        loop.save(iteration, epoch=epoch, cmu_limit=cmu_limit)
        run.log.info("epoch %d train_nll %.3f valid_nll mean %.3f best %.3f lr %.2e minutes %.1f | %s", epoch,
                     np.mean(losses), val["mean"], loop.best, scheduler.get_last_lr()[0], loop.elapsed() / 60,
                     " ".join(f"{k} {v:.2f}" for k, v in val.items() if k != "mean"))
    if not run.best_path.exists():  # no epoch met the guard (or none ended): the weights as they are
        run.save({"model": model.state_dict(), "epoch": epoch, "valid_nll": validation_by_style(model, corpus), "meta": meta},
                 run.best_path)
    loop.finish(iteration, {"best_valid_nll_mean_over_styles": loop.best, "epochs_done": epoch}, save_last=True,
                epoch=epoch, cmu_limit=cmu_limit)
    return loop.best, run.dir
