"""Training the dance model: acLSTM (auto-conditioned) or the vanilla teacher-forced baseline of the same size
(python -m training.aclstm.train).

Recipe from Zhou et al.: windows of 100 frames, u = v = 5 (5 real frames, then 5 of the network's own
output), Euclidean loss, Adam. Every window is rotated by a random angle about the vertical axis and
played at a random speed between 0.8x and 1.2x (the paper's multiple frame rates). Beyond the paper:
the model runs at 30 fps (see data/dance.MODEL_FPS), and half the windows are mirrored left to right,
which doubles the 2.5 minutes each of Indian and martial arts (the 60 fps model overfit them: training
loss 0.015 against 0.076 on held-out clips).
One model for all three styles (a one-hot style input): Indian and martial arts have 2.5 minutes each,
too little for a model of their own, and they share the body's kinematics with salsa's 15 minutes.
Styles are drawn equally often. Losses are in normalised units (per-feature mean and std).
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from ..data.dance import MODEL_FPS, STYLES, DanceClip, DanceSkeleton, encode, load_clips, mirror, mirror_pairs, resample_positions, rotate_y
from ..models.aclstm import DanceLSTM, mixture_nll
from ..models.losses import energy_loss
from ..runs import TrainingLoop

SPEEDS = (0.8, 1.2)


class DanceCorpus:
    """Training windows drawn on the fly (rotation and speed augmentation) and fixed validation windows."""

    def __init__(self, clips: list[DanceClip], window: int, rng: np.random.Generator, names: list[str], use_mirror: bool,
                 styles: tuple[str, ...] = STYLES):
        self.window = window
        self.styles = tuple(styles)
        self.pairs = mirror_pairs(names) if use_mirror else None
        self.train = {s: [c for c in clips if c.style == s and not c.held_out] for s in self.styles}
        # Clips of a style are drawn in proportion to their duration.
        self.clip_p = {}
        for s, mine in self.train.items():
            secs = np.array([c.seconds for c in mine])
            self.clip_p[s] = secs / secs.sum()
        self.valid_files = [c.file for c in clips if c.held_out]
        sample = np.concatenate([self._features(rng, s)[0] for s in self.styles for _ in range(200)])
        self.mean = sample.mean(axis=0)
        self.std = np.maximum(sample.std(axis=0), 1e-3)
        # Rotation makes x and z statistically alike: give them one spread, and zero mean.
        pts = self.std.reshape(-1, 3)
        pts[:, [0, 2]] = np.sqrt((pts[:, 0:1] ** 2 + pts[:, 2:3] ** 2) / 2)
        means = self.mean.reshape(-1, 3)
        means[:, [0, 2]] = 0.0
        self.valid = self._validation_windows(clips)

    def _features(self, rng, style, speed=None, angle=None):
        clips = self.train[style]
        c = clips[rng.choice(len(clips), p=self.clip_p[style])]
        speed = rng.uniform(*SPEEDS) if speed is None else speed
        span = (self.window + 2) * speed / MODEL_FPS
        start = rng.uniform(0, max(1e-6, c.seconds - span))
        pos = resample_positions(c.positions, c.fps, start, self.window + 2, speed)
        if self.pairs is not None and angle is None and rng.random() < 0.5:
            pos = mirror(pos, self.pairs)
        pos = rotate_y(pos, rng.uniform(0, 2 * np.pi) if angle is None else angle)
        return encode(pos), style

    def normalise(self, x):
        return ((x - self.mean) / self.std).astype(np.float32)

    def one_hot(self, styles, device: str | torch.device = "cpu"):
        return torch.eye(len(self.styles), device=device)[[self.styles.index(s) for s in styles]]

    def batch(self, rng, size, device: str | torch.device = "cpu"):
        styles = [self.styles[i] for i in rng.integers(0, len(self.styles), size)]
        x = np.stack([self.normalise(self._features(rng, s)[0]) for s in styles])
        return torch.from_numpy(x).to(device), self.one_hot(styles, device)

    def _validation_windows(self, clips, per_style=48):
        out = {}
        for s in self.styles:
            held = [c for c in clips if c.style == s and c.held_out]
            wins = []
            for k in range(per_style):
                c = held[k % len(held)]
                secs = c.seconds
                start = (k // len(held) + 0.5) / (per_style // len(held) + 1) * (secs - (self.window + 2) / MODEL_FPS)
                wins.append(self.normalise(encode(resample_positions(c.positions, c.fps, start, self.window + 2))))
            out[s] = torch.from_numpy(np.stack(wins))
        return out


def validation_losses(model: DanceLSTM, corpus: DanceCorpus, condition: int) -> dict:
    """Mean squared error per style on held-out windows: teacher-forced and auto-conditioned (u = v = 5)."""
    model.eval()
    out = {}
    device = next(model.parameters()).device
    with torch.no_grad():
        for s, x in corpus.valid.items():
            x = x.to(device)
            style = corpus.one_hot([s] * len(x), device)
            # Squared error of the mean, whatever the head (the Gaussian head's self-fed frames are draws).
            tf = ((model.auto_conditioned(x[:, :-1], style, 5, 0) - x[:, 1:]) ** 2).mean()
            # The same draws every validation, without resetting training's generators (the GPU's too).
            with torch.random.fork_rng(devices=[device] if device.type == "cuda" else []):
                torch.manual_seed(0)
                ac = ((model.auto_conditioned(x[:, :-1], style, 5, 5) - x[:, 1:]) ** 2).mean()
            out[s] = {"teacher_forced": float(tf), "auto_conditioned": float(ac)}
    model.train()
    key = "auto_conditioned" if condition else "teacher_forced"
    out["objective"] = float(np.mean([out[s][key] for s in corpus.styles]))
    return out


@dataclass
class DanceRun:
    stopped: str  # why the run stopped
    best: float  # the best validation objective
    run_dir: Path
    iterations: int
    minutes: float  # trained, over all sessions of the run
    interrupted: bool = False  # Ctrl-C: the checkpoint is saved


def train_dance_model(args: argparse.Namespace,
                      data: tuple[DanceSkeleton, list[DanceClip], tuple[str, ...]] | None = None) -> DanceRun:
    """One training run with the options of python -m training.aclstm.train (kept in the checkpoint's meta).
    `data`: the skeleton, clips and styles to train on (python -m training.own --kind dance); default the acLSTM
    corpus. Ctrl-C stops after the current step with the checkpoint saved."""
    loop = TrainingLoop(args)
    run = loop.run
    rng = loop.seed()
    skel, clips = load_clips(args.mocap, extra=getattr(args, "extra", False)) if data is None else data[:2]
    styles = STYLES if data is None else data[2]
    corpus = DanceCorpus(clips, args.window, np.random.default_rng(12345), skel.names, not args.no_mirror, styles)
    dim = corpus.mean.shape[0]
    components = getattr(args, "components", 10)
    device = torch.device(getattr(args, "device", "cpu"))
    model = DanceLSTM(dim, len(styles), args.hidden, args.layers, args.head, components).to(device)
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    scheduler = torch.optim.lr_scheduler.ExponentialLR(optimiser, gamma=args.decay)
    meta = {"dim": dim, "styles": list(styles), "hidden": args.hidden, "layers": args.layers, "head": args.head,
            **({"components": components} if args.head == "mdn" else {}), "fps": MODEL_FPS,
            "mean": corpus.mean.tolist(), "std": corpus.std.tolist(), "skeleton": skel.to_json(),
            "valid_files": corpus.valid_files, "args": vars(args)}
    iteration = loop.start(meta, model=model, optimiser=optimiser, scheduler=scheduler)
    if loop.resumed and (loop.resumed["meta"]["valid_files"] != meta["valid_files"] or loop.resumed["meta"]["dim"] != dim):
        raise SystemExit(f"error: --resume, but the checkpoint in {run.dir} was trained on other data: train without "
                         "--resume, or into another --run")
    history = loop.resumed["history"] if loop.resumed else []  # validation results, kept in every checkpoint
    run.log.info("start: %s, u=%d v=%d, %d features, %d parameters, batch %d x %d frames", args.run,
                 args.ground_truth, args.condition, dim, loop.parameters, args.batch, args.window)
    noise_rng = torch.Generator(device=device).manual_seed(args.seed + iteration)
    bar = loop.progress_bar(args.run, args.iterations, iteration)
    losses = []
    interrupted = False
    try:
        while iteration < args.iterations:
            x, style = corpus.batch(rng, args.batch, device)
            # Schedules over the time budget (so a resumed run continues them): the self-fed stretch grows from
            # v = condition to condition_max, and noise on the real input frames from noise[0] to noise[1]
            # (normalised units; the targets stay clean).
            progress = min(1.0, loop.elapsed() / (args.minutes * 60))
            condition = args.condition
            if args.condition and args.condition_max:
                condition = int(round(args.condition + (args.condition_max - args.condition) * progress))
            inputs = x[:, :-1]
            sigma = args.input_noise[0] + (args.input_noise[1] - args.input_noise[0]) * progress
            if sigma > 0:
                inputs = inputs + sigma * torch.randn(inputs.shape, generator=noise_rng, device=device)
            if args.head == "mdn":  # mixture likelihood; the self-fed frames are held-component draws (models/aclstm.py)
                logits, mus, log_sigmas = model.auto_conditioned_mixture(inputs, style, args.ground_truth, condition,
                                                                         getattr(args, "draw_temperature", 1.0), noise_rng)
                loss = mixture_nll(logits, mus, log_sigmas, x[:, 1:])
                pred = (torch.softmax(logits, -1).unsqueeze(-1) * mus).sum(-2)  # the mixture's mean, for the energy term
            else:
                pred, log_sigma = model.auto_conditioned_distribution(inputs, style, args.ground_truth, condition, args.feedback_noise)
                if log_sigma is None:
                    loss = ((pred - x[:, 1:]) ** 2).mean()
                else:  # Gaussian negative log-likelihood per channel (constant dropped)
                    loss = (0.5 * ((x[:, 1:] - pred) * torch.exp(-log_sigma)) ** 2 + log_sigma).mean()
            if args.energy:
                # Motion energy: each channel's RMS change between frames over the window should match the real
                # window's. A frozen pose is the mean regression's cheapest answer; this term prices it.
                loss = loss + args.energy * energy_loss(pred, x[:, 1:])
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            optimiser.step()
            iteration += 1
            losses.append(loss.item())
            bar.update(1)
            bar.set_postfix(loss=f"{np.mean(losses[-50:]):.4f}", v=condition, noise=f"{sigma:.2f}")
            if iteration % args.iters_per_epoch == 0:
                scheduler.step()
                val = validation_losses(model, corpus, args.condition)
                history.append({"iteration": iteration, "minutes": round(loop.elapsed() / 60, 2), "train": float(np.mean(losses)),
                                "valid": val})
                if val["objective"] < loop.best:
                    loop.best = val["objective"]
                    run.save({"model": model.state_dict(), "iteration": iteration, "valid": val, "meta": meta}, run.best_path)
                run.log.info("iteration %d train %.4f valid %.4f (tf %s, ac %s) best %.4f lr %.2e minutes %.1f", iteration,
                             np.mean(losses), val["objective"],
                             "/".join(f"{val[s]['teacher_forced']:.3f}" for s in styles),
                             "/".join(f"{val[s]['auto_conditioned']:.3f}" for s in styles),
                             loop.best, scheduler.get_last_lr()[0], loop.elapsed() / 60)
                losses = []
                loop.save(iteration, history=history)
            if loop.step_done(iteration, history=history):
                break
    except KeyboardInterrupt:
        loop.stopped, interrupted = "stopped by Ctrl-C", True
    if not run.best_path.exists():  # no validation yet (a short or interrupted run): the weights as they are
        val = validation_losses(model, corpus, args.condition)
        loop.best = val["objective"]
        run.save({"model": model.state_dict(), "iteration": iteration, "valid": val, "meta": meta}, run.best_path)
    # The last weights also count as a candidate: last.pt, for the evaluation to compare.
    loop.finish(iteration, {"best_valid": loop.best, "iterations": iteration, "stopped": loop.stopped},
                save_last=True, history=history)
    return DanceRun(loop.stopped, loop.best, run.dir, iteration, loop.elapsed() / 60, interrupted)
