"""Training the VAE-LSTM (models/vae_lstm.py) on 4 s windows of CMU locomotion (data/windows.py), and reading
its checkpoints back.

Recipe (Habibie et al. §3.1, 4.2): the loss of eq. 5, a Gaussian likelihood of the window's 80 normalised
values per frame (fixed σ, so it is a mean squared error scaled by 1 / 2σ²) plus the KL divergence of every
step's posterior from N(0, I) (eq. 4); dropout on the positions and on the control; ℓ1 = 0.1 on the weights,
against the loss summed over the batch's values; Adam at 5e-4. Both sides are divided by 2σ² × values here,
so `beta` = 2σ² weighs the KL against the mean squared error (σ = 0.1: beta 0.02), and ℓ1 becomes
0.1 × Σ|w| / values. The KL weight ramps up from 0 over the first KL_RAMP of the run so the posterior is used
before it is pulled to the prior.

The paper trains the cell only in teacher mode (content z_t at every step) and generates in free mode (content
the previous state) from one sample z_1. `free` adds the free mode to training: each window is also
generated from z_1 alone, z_1 from the posterior of its first 4 frames (generation.py seed_window) or of the window
itself (`free_z1`, losses), and its reconstruction error (and that z_1's KL) counts `free` times. Pilots compare the two
(docs/models/vae-lstm.md).

Motion energy (`energy`): a free-mode window that has lost the stride's phase costs least under the squared
error as the average over phases, a body that glides: free-mode pilots moved their pose at a third of the
real clips' rate after 1,000 iterations, the paper's recipe at 4%. The term asks each channel's RMS change
between frames over the window to match the real window's (models/losses.py energy_loss), which does
not depend on the phase.

The control the cell reads is the rows' own signal smoothed over `control_sigma` frames: a drawn path or a
stick has no per-stride sway, and the latent ERD learnt to use that sway as its clock (latent-erd.md).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import torch

from ..data.locomotion import FPS, load_clips
from ..data.windows import CONTROL_SLICE, POSITION_DIM, ROW_DIM, WINDOW, WindowCorpus, smooth, window_at
from ..models.losses import energy_loss
from ..models.vae_lstm import VaeLstm
from ..runs import TrainingLoop
from .generation import SEED_FRAMES, seed_window

VALIDATE_EVERY = 250
KL_RAMP = 0.2
L1_PAPER = 0.1


def load_vae_lstm(checkpoint: Path) -> tuple[VaeLstm, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = VaeLstm(meta["dim"], meta["control"], meta["latent"], meta["control_features"], meta["inference_features"],
                    meta["decoder_hidden"], meta["dropout"])
    model.load_state_dict(state["model"])
    return model.eval(), meta


class ControlWindows:
    """Normalised rows with the control the cell reads (smoothed), sampled as windows of whole clips."""

    def __init__(self, seqs: list[np.ndarray], weights: np.ndarray, control_sigma: float):
        self.rows = seqs
        self.controls = [smoothed_control(s, control_sigma) for s in seqs]
        self.weights = weights / weights.sum()

    def batch(self, rng: np.random.Generator, size: int, length: int = WINDOW) -> tuple[torch.Tensor, torch.Tensor]:
        x = np.empty((size, length, ROW_DIM), np.float32)
        c = np.empty((size, length, 3), np.float32)
        for i, k in enumerate(rng.choice(len(self.rows), size=size, p=self.weights)):
            start = int(rng.integers(0, max(1, len(self.rows[k]) - length + 1)))
            x[i] = window_at(self.rows[k], start, length)
            c[i] = window_at(self.controls[k], start, length)
        return torch.from_numpy(x), torch.from_numpy(c)

    def windows(self, length: int = WINDOW, stride: int = WINDOW // 2) -> tuple[torch.Tensor, torch.Tensor]:
        """Every window of `length` frames at `stride` in whole clips (no clip joined to another)."""
        xs, cs = [], []
        for s, c in zip(self.rows, self.controls):
            for a in range(0, len(s) - length + 1, stride):
                xs.append(s[a:a + length])
                cs.append(c[a:a + length])
        return torch.from_numpy(np.stack(xs)), torch.from_numpy(np.stack(cs))


def smoothed_control(rows: np.ndarray, sigma: float) -> np.ndarray:
    control = rows[:, CONTROL_SLICE]
    return (smooth(control, sigma) if sigma > 0 else control).astype(np.float32)


def kl_per_step(mean: torch.Tensor, log_var: torch.Tensor) -> torch.Tensor:
    """KL(N(mean, exp(log_var)) || N(0, I)) summed over the latent, per step: (batch, steps)."""
    return 0.5 * (mean ** 2 + log_var.exp() - 1 - log_var).sum(-1)


def sample(mean: torch.Tensor, log_var: torch.Tensor) -> torch.Tensor:
    return mean + torch.randn_like(mean) * (0.5 * log_var).exp()


def losses(model: VaeLstm, x: torch.Tensor, control: torch.Tensor, free_z1: str = "seed", free_mix: float = 0.0) -> dict:
    """The teacher-mode and free-mode terms for windows x (batch, frames, dim) and their control. The free mode's
    z_1 comes from the posterior of the window's first 4 frames held (`free_z1` "seed", as a 4-frame start has
    it), of the window itself at its first step (“window”: it reads about 1.3 s of the real motion, its stride's
    phase and speed, as a prior sample is meant to stand for), or half the batch each ("both")."""
    hc = model.control_encoder(control)
    mean, log_var = model.inference(x)
    z = sample(mean, log_var)
    canvas, _ = model.cell.run(z[:, 0], hc, latents=z)
    teacher = ((model.decoder(canvas) - x) ** 2).mean()
    kl = kl_per_step(mean, log_var).mean()
    m1, v1 = model.posterior_first(seed_window(x[:, :SEED_FRAMES]))
    if free_z1 != "seed":
        own = torch.ones(x.shape[0], 1, dtype=torch.bool) if free_z1 == "window" else (torch.arange(x.shape[0]) % 2 == 1)[:, None]
        m1, v1 = torch.where(own, mean[:, 0], m1), torch.where(own, log_var[:, 0], v1)
    z1 = sample(m1, v1)
    free_rows = model.decoder(model.free_canvas(z1, hc, free_mix))
    free = ((free_rows - x) ** 2).mean()
    return {"teacher": teacher, "kl": kl, "free": free, "kl_first": kl_per_step(m1, v1).mean(),
            "energy": energy_loss(free_rows[..., :POSITION_DIM], x[..., :POSITION_DIM])}


def position_error_cm(model: VaeLstm, corpus: WindowCorpus, x: torch.Tensor, control: torch.Tensor, prior_seed: int | None, mix: float = 0.0) -> float:
    """Mean joint position error (cm, in the root's facing frame) of windows generated in free mode from z_1:
    the posterior mean of the first 4 frames, or with `prior_seed` a sample of N(0, I)."""
    with torch.no_grad():
        if prior_seed is None:
            z1 = model.posterior_first(seed_window(x[:, :SEED_FRAMES]))[0]
        else:
            z1 = torch.randn(x.shape[0], model.latent, generator=torch.Generator().manual_seed(prior_seed))
        y = model.generate(control, z1, mix).numpy()
    std, mean = corpus.std[:POSITION_DIM], corpus.mean[:POSITION_DIM]
    real = (x.numpy()[..., :POSITION_DIM] * std + mean).reshape(*x.shape[:2], -1, 3)
    made = (y[..., :POSITION_DIM] * std + mean).reshape(*x.shape[:2], -1, 3)
    return float(np.linalg.norm(real - made, axis=-1).mean() * 100)


def l1_penalty(model: VaeLstm) -> torch.Tensor:
    return sum(p.abs().sum() for name, p in model.named_parameters() if p.dim() > 1)


def train_vae_lstm(args: argparse.Namespace) -> tuple[float, Path]:
    loop = TrainingLoop(args)
    run = loop.run
    corpus = WindowCorpus(load_clips(args.mocap))
    train = ControlWindows(corpus.train, corpus.weights, args.control_sigma)
    valid = ControlWindows(corpus.valid, np.ones(len(corpus.valid)), args.control_sigma)
    vx, vc = valid.windows()
    model = VaeLstm(ROW_DIM, 3, args.latent, args.control_features, args.inference_features, args.decoder_hidden, args.dropout)
    meta = {"fps": FPS, "window": WINDOW, "dim": ROW_DIM, "control": 3, "latent": args.latent,
            "control_features": args.control_features, "inference_features": args.inference_features,
            "decoder_hidden": args.decoder_hidden, "dropout": args.dropout, "control_sigma": args.control_sigma,
            "row_mean": corpus.mean.tolist(), "row_std": corpus.std.tolist(), "valid_files": corpus.valid_files, "args": vars(args)}
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    scheduler = torch.optim.lr_scheduler.MultiStepLR(optimiser, [int(args.iterations * 0.7), int(args.iterations * 0.9)], 0.5)
    rng = loop.seed()
    start = loop.start(meta, model=model, optimiser=optimiser, scheduler=scheduler)
    values = args.batch * WINDOW * ROW_DIM
    run.log.info("start: %d parameters, %d training clips, %d held-out windows, batch %d, beta %g, free %g, energy %g, l1 %g",
                 loop.parameters, len(train.rows), len(vx), args.batch, args.beta, args.free, args.energy, args.l1)
    bar = loop.progress_bar("VAE-LSTM", args.iterations, start)
    history, it = [], start
    for it in range(start, args.iterations):
        x, c = train.batch(rng, args.batch)
        beta = args.beta * min(1.0, it / max(1, args.iterations * KL_RAMP))
        terms = losses(model, x, c, args.free_z1, args.free_mix)
        loss = (terms["teacher"] + beta * terms["kl"] / (4 * ROW_DIM)
                + args.free * (terms["free"] + beta * terms["kl_first"] / (4 * ROW_DIM) + args.energy * terms["energy"])
                + args.l1 * l1_penalty(model) / values)
        optimiser.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        optimiser.step()
        scheduler.step()
        history.append([float(terms[k]) for k in ("teacher", "free", "kl", "energy")])
        bar.update(1)
        recent = np.mean(history[-50:], axis=0)
        bar.set_postfix(teacher=f"{recent[0]:.3f}", free=f"{recent[1]:.3f}", kl=f"{recent[2]:.1f}")
        if (it + 1) % VALIDATE_EVERY == 0 or it + 1 == args.iterations:
            model.eval()
            posterior = position_error_cm(model, corpus, vx, vc, None, args.free_mix)
            prior = position_error_cm(model, corpus, vx, vc, 0, args.free_mix)
            model.train()
            if posterior < loop.best:
                loop.best = posterior
                run.save({"model": model.state_dict(), "iteration": it + 1, "valid_cm": posterior, "prior_cm": prior, "meta": meta},
                         run.best_path)
            recent = np.mean(history[-VALIDATE_EVERY:], axis=0)
            run.log.info("iteration %d teacher %.4f free %.4f kl %.1f energy %.4f held-out cm: from 4 frames %.2f, prior %.2f, best %.2f, minutes %.1f",
                         it + 1, recent[0], recent[1], recent[2], recent[3], posterior, prior, loop.best, loop.elapsed() / 60)
        if loop.step_done(it + 1):
            break
    loop.finish(it + 1, {"best_valid_cm": loop.best, "iterations": it + 1})
    return loop.best, run.dir
