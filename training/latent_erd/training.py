"""Training the control ERD (models/erd.py) in the autoencoder's latent space (the latent ERD) or on pose
rows (the pose-space baseline, Fragkiadaki-style), and reading checkpoints back.

Recipe: random stretches of whole clips (sequences.py) with the next step's control, mean squared error on
every next step, Adam at 1e-3 halved at 60% and 85% of the run, gradients clipped at norm 1, dropout 0.2
before the decoder (Yearsley Ch. 6), Gaussian input noise on the teacher-forced steps growing from 0 to
`noise` over the first half of the run (Fragkiadaki et al.'s schedule).

Self-fed stretches: the last part of each stretch is fed the ERD's own predictions instead of the real
steps, with gradients through them, growing from none to `self_fed` of the stretch (after SEED_STEPS real
ones) over the first 60% of the run (the ramp of Dance Revolution and MVAE). A purely teacher-forced pilot
(8 minutes) predicted the next step well (held-out MSE 0.014) but diverged when free-running: its decoded
forward speed reached -44 m/s within 20 s.

Motion energy (`energy`): mean squared error alone shrinks the motion. Once a self-fed stretch has lost the
real stride's phase, the prediction that costs least is the average over phases, a smaller step; the first
shipped ERD, trained without this term, moved its pose at about half the real clips' rate at 0.4-0.8 m/s (and
froze for whole seconds there in random control). The term asks each channel's mean squared step change over
the stretch to match the real one's (on the square roots, so it is in the units of a step), which does not
depend on the phase. Alone it added motion only where the control sways with the stride; with the control
smoothed (sequences.py) it ships (pilots: docs/models/latent-erd-notes.json).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import torch

from ..autoencoder.training import load_autoencoder
from ..data.locomotion import FPS, load_clips
from ..data.windows import WindowCorpus
from ..models.erd import ControlERD
from ..runs import TrainingLoop
from .sequences import StepSequences, latent_sequences, pose_sequences

VALIDATE_EVERY = 250
SEED_STEPS = 4


def load_erd(checkpoint: Path) -> tuple[ControlERD, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = ControlERD(meta["dim"], meta["control_dim"], meta["hidden"], meta["layers"], meta["dropout"])
    # Checkpoints from before the output clamp (the pose-space baseline's run) have no range: unclamped.
    result = model.load_state_dict(state["model"], strict=False)
    if result.unexpected_keys or set(result.missing_keys) - {"low", "high"}:
        raise SystemExit(f"error: {checkpoint} does not fit ControlERD: missing {result.missing_keys}, unexpected {result.unexpected_keys}")
    return model.eval(), meta


def rollout(model: ControlERD, x: torch.Tensor, c: torch.Tensor, teach: int) -> torch.Tensor:
    """Predictions for every step: the first `teach` from the real inputs, the rest fed the model's own."""
    pred, state = model(x[:, :teach], c[:, :teach])
    preds, cur = [pred], pred[:, -1:]
    for t in range(teach, x.shape[1]):
        cur, state = model(cur, c[:, t:t + 1], state)
        preds.append(cur)
    return torch.cat(preds, dim=1)


def energy_loss(pred: torch.Tensor, y: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean over sequences and channels of (RMS step change of the prediction - of the real steps)^2, the RMS
    taken over each stretch's real targets (mask)."""
    both = (mask[:, 1:] * mask[:, :-1])[..., None]
    count = both.sum(1).clamp(min=1)
    rms = lambda x: torch.sqrt(((x[:, 1:] - x[:, :-1]) ** 2 * both).sum(1) / count + 1e-6)
    return ((rms(pred) - rms(y)) ** 2).mean()


def validation_loss(model: ControlERD, valid: StepSequences, steps: int = 40) -> float:
    """Mean squared error over held-out stretches free-running from SEED_STEPS real steps with the real
    control (up to `steps` steps): the measure that matters for a stream, unlike the next-step error."""
    model.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for x, c in zip(valid.xs, valid.controls):
            n = min(len(x), steps + 1)
            if n <= SEED_STEPS + 1:
                continue
            xt = torch.from_numpy(x[:n])[None]
            pred = rollout(model, xt[:, :-1], torch.from_numpy(c[1:n])[None], SEED_STEPS)
            total += float(((pred - xt[:, 1:]) ** 2).mean(-1)[:, SEED_STEPS - 1:].sum())
            count += n - SEED_STEPS
    model.train()
    return total / max(count, 1)


def train_erd(args: argparse.Namespace) -> tuple[float, Path]:
    loop = TrainingLoop(args)
    run = loop.run
    corpus = WindowCorpus(load_clips(args.mocap))
    meta = {"space": args.space, "fps": FPS, "hidden": args.hidden, "layers": args.layers, "dropout": args.dropout,
            "row_mean": corpus.mean.tolist(), "row_std": corpus.std.tolist(), "valid_files": corpus.valid_files,
            "args": vars(args)}
    if args.space == "latent":
        autoencoder, ae_meta = load_autoencoder(Path(args.autoencoder))
        train, valid, mean, std = latent_sequences(autoencoder, corpus, args.control_sigma)
        meta.update(latent_mean=mean.tolist(), latent_std=std.tolist(), autoencoder=str(args.autoencoder),
                    control_sigma=args.control_sigma)
    else:
        train, valid = pose_sequences(corpus)
    meta.update(dim=train.dim, control_dim=train.control_dim)
    model = ControlERD(train.dim, train.control_dim, args.hidden, args.layers, args.dropout)
    allx = np.concatenate(train.xs)
    model.set_range(allx.min(axis=0), allx.max(axis=0))
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    scheduler = torch.optim.lr_scheduler.MultiStepLR(optimiser, [int(args.iterations * 0.6), int(args.iterations * 0.85)], 0.5)
    rng = loop.seed()
    start = loop.start(meta, model=model, optimiser=optimiser, scheduler=scheduler)
    run.log.info("start: %s space, %d parameters, %d training sequences, %d held-out, steps of %d x %d",
                 args.space, loop.parameters, len(train.xs), len(valid.xs), args.batch, args.steps)
    bar = loop.progress_bar(f"{args.space} ERD", args.iterations, start)
    losses, it = [], start
    for it in range(start, args.iterations):
        x, c, y, mask = train.batch(rng, args.batch, args.steps)
        sigma = args.noise * min(1.0, it / max(1, args.iterations * 0.5))
        free = int(round(args.self_fed * min(1.0, it / max(1, args.iterations * 0.6)) * (args.steps - SEED_STEPS)))
        pred = rollout(model, x + sigma * torch.randn_like(x), c, args.steps - free)
        loss = (((pred - y) ** 2).mean(-1) * mask).sum() / mask.sum()
        if args.energy > 0:
            loss = loss + args.energy * energy_loss(pred, y, mask)
        optimiser.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        optimiser.step()
        scheduler.step()
        losses.append(float(loss))
        bar.update(1)
        bar.set_postfix(loss=f"{np.mean(losses[-50:]):.4f}", noise=f"{sigma:.2f}", self_fed=free)
        if (it + 1) % VALIDATE_EVERY == 0 or it + 1 == args.iterations:
            val = validation_loss(model, valid)
            if val < loop.best:
                loop.best = val
                run.save({"model": model.state_dict(), "iteration": it + 1, "valid_loss": val, "meta": meta}, run.best_path)
            run.log.info("iteration %d train %.4f held-out %.4f best %.4f noise %.2f self-fed %d of %d steps minutes %.1f", it + 1,
                         np.mean(losses[-VALIDATE_EVERY:]), val, loop.best, sigma, free, args.steps, loop.elapsed() / 60)
        if loop.step_done(it + 1):
            break
    loop.finish(it + 1, {"best_valid_loss": loop.best, "iterations": it + 1}, save_last=True)
    return loop.best, run.dir
