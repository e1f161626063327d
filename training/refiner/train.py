"""Train the adversarial refiner R against a discriminator D (Wang, Chai, Xia §4.2, §4.3).

    python -m training.train_refiner [--minutes 50] [--hidden 96] [--resume]

R is trained on motion sampled from the generator (runs/generator/best.pt, the weights of the shipped
public/models/generator.onnx) at temperature 0.5, against real windows of the generator's own training
split (train_generator.Corpus: mirrored and speed-changed copies of the training clips; the held-out
validation clips are not used here). Generated streams start from a short teacher-forced warm-up on a
random real training window, so they cover many states; they are cached in cache/refiner_generated_*.npz.

Losses: D minimises eq. (10), -log(1 - D(R(x))) - log D(x_real); R minimises eq. (13),
-log D(R(x)) + lambda * |root(x) - root(R(x))|^2 with lambda = 20, where root() is the root trajectory
integrated over the window (metres). D gives one logit per frame; losses are means over frames.
Recipe (§4.2.2): 75 initial updates of R (root term only: D is untrained) and 75 of D, then k = 5 R updates
per D update, k doubled when the D loss is below 0.01 and halved when it is above 1; a history buffer of
B = 320 refined windows, each D update sees b/2 = 16 from the current R and 16 from the buffer (then 16
buffer entries are replaced); RMSProp (decay 0.9), learning rates 0.002 (R) and 0.005 (D), b = 32.

R sees windows of --window frames (90) from a zero state, so it learns to start cold as the browser does;
D judges --crop-frame crops (30, one second: the running clips are barely longer) of them.

One deviation from the paper, and one variant that was tried (measured in docs/models/refiner.md):
- --pose-weight (default 1, the shipped run): eq. 13 regularises the root only. Trained that way
  (--pose-weight 0, runs/refiner-faithful) R changed the frames by 0.86 standard deviations on average and
  flipped a third of the contact bits within 1,000 updates while D won (D(refined) 0.05): the joints D cannot
  see drift freely. The extra term is the mean squared change of all other features (tilt, joint rotations,
  contacts; normalised units), the "self-regularisation" of the paper's Fig. 2 applied to the whole frame.
- --d-pose 1 (default 0 = the paper): D also sees the rest of the frame (root motion, tilt, joint rotations).
  Tried with --pose-weight 0.5 (runs/refiner-dpose): D won faster and validation skating stayed higher
  (0.95 against 0.71 m/s at 1,500 updates), so the shipped R is trained against the paper's D.

Writes runs/refiner/{train.log, checkpoint.pt, best.pt, last.pt}; best.pt is the checkpoint with the lowest
validation skating (contact share within 0.1 of the generator's). Longer training lowers that measure but makes
the motion easier to tell from real motion (docs/models/refiner.md), so the shipped model is an early best.pt,
kept as runs/refiner/shipped.pt. Export with python -m training.export_refiner --checkpoint <file>.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from ..data.cmu import DEFAULT_CACHE
from ..generator.export import load_generator
from ..models.generator import MixtureLSTM
from ..models.refiner import Discriminator, Refiner, discriminator_input, discriminator_inputs
from ..paths import add_mocap_argument
from ..runs import RUNS_DIR, Run
from ..generator.train import Corpus, load_clips

TEMPERATURE = 0.5
TOE_NAMES = ("LeftToeBase", "RightToeBase")


# ---- generated motion ---------------------------------------------------------------------------

def sample_torch(logits, mu, log_sigma, temperature: float, gen: torch.Generator) -> torch.Tensor:
    """generate.sample_mixture in torch: weights sharpened by 1/temperature, sigmas scaled by temperature."""
    p = torch.softmax(torch.log_softmax(logits, -1) / temperature, -1)
    k = torch.multinomial(p, 1, generator=gen)[:, 0]
    rows = torch.arange(len(k))
    noise = torch.randn(mu.shape[0], mu.shape[-1], generator=gen)
    return mu[rows, k] + torch.exp(log_sigma[rows, k]) * temperature * noise


@torch.no_grad()
def generate_streams(model: MixtureLSTM, corpus: Corpus, streams: int, frames: int, warmup: int,
                     temperature: float, seed: int, batch: int = 512) -> np.ndarray:
    """(streams, frames + 1, D) normalised: frame 0 is the last real warm-up frame, then `frames` sampled ones.
    Each stream is teacher-forced on `warmup` real frames of a random training window, then runs free with
    the contact bits snapped to clean 0/1 as generate.ShippedGenerator does."""
    rng = np.random.default_rng(seed)
    gen = torch.Generator().manual_seed(seed)
    mean, std = torch.tensor(corpus.mean, dtype=torch.float32), torch.tensor(corpus.std, dtype=torch.float32)
    lo, hi = (0 - mean[-2:]) / std[-2:], (1 - mean[-2:]) / std[-2:]
    out = np.zeros((streams, frames + 1, len(mean)), np.float32)
    long_enough = [k for k, s in enumerate(corpus.train) if len(s) > warmup]
    p = corpus.weights[long_enough] / corpus.weights[long_enough].sum()
    for a in tqdm(range(0, streams, batch), desc="generating", unit="batch"):
        b = min(batch, streams - a)
        real = np.zeros((b, warmup, len(mean)), np.float32)
        for i, k in enumerate(rng.choice(long_enough, size=b, p=p)):
            s = rng.integers(0, len(corpus.train[k]) - warmup + 1)
            real[i] = corpus.train[k][s:s + warmup]
        x = torch.from_numpy(real)
        logits, mu, log_sigma, state = model(x)
        out[a:a + b, 0] = real[:, -1]
        logits, mu, log_sigma = logits[:, -1], mu[:, -1], log_sigma[:, -1]
        for t in range(frames):
            x = sample_torch(logits, mu, log_sigma, temperature, gen)
            x[:, -2:] = torch.where(x[:, -2:] * std[-2:] + mean[-2:] > 0.5, hi, lo)
            out[a:a + b, t + 1] = x.numpy()
            logits, mu, log_sigma, state = model(x.unsqueeze(1), state)
            logits, mu, log_sigma = logits[:, 0], mu[:, 0], log_sigma[:, 0]
    return out


def generated_cache(model, corpus, args, kind: str) -> np.ndarray:
    """Cached generated streams: 'train' (many short streams plus some long ones) or 'valid' (own seed)."""
    if kind == "train":
        specs = [(args.streams, args.window + 30, 1), (args.long_streams, 1200, 2)]
    else:
        specs = [(256, args.window, 101)]
    arrays = []
    for streams, frames, seed in specs:
        path = DEFAULT_CACHE / f"refiner_generated_t{TEMPERATURE}_{streams}x{frames}_w{args.warmup}_s{seed}.npz"
        if path.exists():
            arrays.append(np.load(path)["x"])
            continue
        x = generate_streams(model, corpus, streams, frames, args.warmup, TEMPERATURE, seed)
        DEFAULT_CACHE.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(path, x=x)
        arrays.append(x)
    return arrays


class WindowSampler:
    """Windows of window + 1 frames (x_prev and the window) from a list of (streams, frames, D) arrays or
    from a list of sequences (frames, D) with weights."""

    def __init__(self, seqs: list[np.ndarray], window: int, weights: np.ndarray | None = None):
        self.seqs = [s for s in seqs if len(s) >= window + 1]
        w = np.array([len(s) - window for s in self.seqs], np.float64) if weights is None else \
            np.array([wt for s, wt in zip(seqs, weights) if len(s) >= window + 1], np.float64)
        self.p = w / w.sum()
        self.window = window

    def __call__(self, rng: np.random.Generator, size: int) -> tuple[torch.Tensor, torch.Tensor]:
        out = np.zeros((size, self.window + 1, self.seqs[0].shape[-1]), np.float32)
        for i, k in enumerate(rng.choice(len(self.seqs), size=size, p=self.p)):
            s = rng.integers(0, len(self.seqs[k]) - self.window)
            out[i] = self.seqs[k][s:s + self.window + 1]
        t = torch.from_numpy(out)
        return t[:, 1:], t[:, 0]


def streams_to_seqs(arrays: list[np.ndarray]) -> list[np.ndarray]:
    return [s for a in arrays for s in a]


# ---- losses and measures ------------------------------------------------------------------------

def crops(d: torch.Tensor, length: int) -> torch.Tensor:
    """(B, T, F) -> (B * T // length, length, F): non-overlapping crops."""
    b, t, f = d.shape
    n = t // length
    return d[:, :n * length].reshape(b * n, length, f)


def root_loss(refiner: Refiner, x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """Mean squared distance (m^2) between the root trajectories of input and refined windows (eq. 13)."""
    geo = refiner.geometry
    a, b = geo.root_trajectory(refiner.physical(x)), geo.root_trajectory(refiner.physical(y))
    return ((a - b) ** 2).sum(-1).mean()


@torch.no_grad()
def skating(refiner: Refiner, x: torch.Tensor, x_prev: torch.Tensor) -> tuple[float, float]:
    """Mean horizontal toe speed (m/s) while planted in this frame and the one before (as metrics.foot_skating,
    using the windows' own contact bits), and the share of planted frames."""
    geo = refiner.geometry
    f, fp = refiner.physical(x), refiner.physical(x_prev)
    _, v = geo.end_effectors(f, fp)
    bits = torch.cat([fp.unsqueeze(1), f], 1)[..., -2:] > 0.5
    planted = bits[:, 1:] & bits[:, :-1]
    speeds = []
    for side, name in enumerate(TOE_NAMES):
        k = geo.end_names.index(name)
        speed = torch.linalg.norm(v[..., k, [0, 2]], dim=-1)
        speeds.append(speed[planted[..., side]])
    s = torch.cat(speeds)
    return float(s.mean()) if len(s) else float("nan"), float(bits[:, 1:].float().mean())


def end_statistics(refiner: Refiner, sampler: WindowSampler, rng, n: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of the physical [p_end, v_end] over real windows."""
    x, xp = sampler(rng, n)
    with torch.no_grad():
        f = refiner.physical(x)
        p, v = refiner.geometry.end_effectors(f, refiner.physical(xp))
        e = torch.cat([p.flatten(-2), v.flatten(-2)], -1).reshape(-1, 6 * refiner.ends).numpy()
    return e.mean(0), np.maximum(e.std(0), 1e-2)


# ---- training -----------------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_mocap_argument(parser)
    parser.add_argument("--generator", type=Path, default=RUNS_DIR / "generator" / "best.pt")
    parser.add_argument("--hidden", type=int, default=96, help="refiner width (FC1 and LSTM)")
    parser.add_argument("--d-hidden", type=int, default=64, help="discriminator width (FC1 and each LSTM direction)")
    parser.add_argument("--window", type=int, default=90, help="frames per refiner window (from a zero state)")
    parser.add_argument("--crop", type=int, default=30, help="frames per discriminator window")
    parser.add_argument("--batch", type=int, default=32, help="b: refiner windows per update, D windows per update")
    parser.add_argument("--buffer", type=int, default=320, help="B: history buffer of refined D windows")
    parser.add_argument("--lam", type=float, default=20.0, help="lambda of the root regularisation (eq. 13)")
    parser.add_argument("--pose-weight", type=float, default=1.0,
                        help="extra self-regularisation (eq. 13 has the root only): weight of the mean squared change of "
                             "the other features (tilt, joint rotation vectors, contacts; normalised units). 0 = the paper")
    parser.add_argument("--d-pose", type=int, default=0,
                        help="1: D also sees the rest of x (root motion, tilt, joint rotations), not only the end "
                             "effectors and contacts of eq. 12; 0 = the paper")
    parser.add_argument("--lr-r", type=float, default=0.002)
    parser.add_argument("--lr-d", type=float, default=0.005)
    parser.add_argument("--initial", type=int, default=75, help="initial updates of each network")
    parser.add_argument("--ratio", type=int, default=5, help="refiner updates per discriminator update (start)")
    parser.add_argument("--iterations", type=int, default=20000, help="refiner updates in all")
    parser.add_argument("--streams", type=int, default=2048, help="short generated streams for training")
    parser.add_argument("--long-streams", type=int, default=96, help="long (1200-frame) generated streams")
    parser.add_argument("--warmup", type=int, default=10, help="teacher-forced real frames before sampling")
    parser.add_argument("--minutes", type=float, default=50.0, help="stop cleanly after this much training time")
    parser.add_argument("--checkpoint-minutes", type=float, default=3.0)
    parser.add_argument("--eval-every", type=int, default=250, help="refiner updates between validation checks")
    parser.add_argument("--run", default="refiner")
    parser.add_argument("--resume", action="store_true", help="continue from runs/<run>/checkpoint.pt")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args(argv)

    torch.set_num_threads(args.threads)
    run = Run(args.run, args.checkpoint_minutes)
    generator, gmeta, _ = load_generator(args.generator)
    corpus = Corpus(load_clips(args.mocap))
    if np.abs(corpus.mean - np.array(gmeta["mean"])).max() > 1e-5:
        raise SystemExit("error: the corpus's normalisation differs from the generator's; was the cache rebuilt?")
    mean, std, refs = np.array(gmeta["mean"]), np.array(gmeta["std"]), np.array(gmeta["references"])
    corpus.mean, corpus.std = mean, std

    rng = np.random.default_rng(args.seed)
    torch.manual_seed(args.seed)
    real = WindowSampler(corpus.train, args.window, corpus.weights)
    real_crop = WindowSampler(corpus.train, args.crop, corpus.weights)
    fake = WindowSampler(streams_to_seqs(generated_cache(generator, corpus, args, "train")), args.window)
    valid_fake = generated_cache(generator, corpus, args, "valid")[0]
    valid_real = WindowSampler(corpus.valid, args.crop)
    vx, vxp = torch.from_numpy(valid_fake[:, 1:]), torch.from_numpy(valid_fake[:, 0])
    vr = valid_real(np.random.default_rng(7), 256)

    probe = Refiner(mean, std, refs, args.hidden)
    end_mean, end_std = end_statistics(probe, real, np.random.default_rng(3))
    refiner = Refiner(mean, std, refs, args.hidden, end_mean, end_std, fps=gmeta["fps"])
    disc = Discriminator(discriminator_inputs(refiner, bool(args.d_pose)), args.d_hidden)
    opt_r = torch.optim.RMSprop(refiner.parameters(), lr=args.lr_r, alpha=0.9)
    opt_d = torch.optim.RMSprop(disc.parameters(), lr=args.lr_d, alpha=0.9)
    meta = {"dim": refiner.dim, "hidden": args.hidden, "d_hidden": args.d_hidden, "fps": gmeta["fps"],
            "mean": mean.tolist(), "std": std.tolist(), "references": refs.tolist(),
            "end_effectors": refiner.geometry.end_names, "end_mean": end_mean.tolist(), "end_std": end_std.tolist(),
            "temperature": TEMPERATURE, "generator": str(args.generator), "valid_files": corpus.valid_files,
            "args": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}}

    half = args.batch // 2

    def refine_batch():
        x, xp = fake(rng, args.batch)
        y, _ = refiner(x, xp)
        return x, xp, y

    def d_fake_input(y, xp):
        return crops(discriminator_input(refiner, y, xp, bool(args.d_pose)), args.crop)

    def d_real_input():
        x, xp = real_crop(rng, args.batch)
        return discriminator_input(refiner, x, xp, bool(args.d_pose))

    with torch.no_grad():
        _, xp0, y0 = refine_batch()
        buf = d_fake_input(y0, xp0)
        while len(buf) < args.buffer:
            _, xpi, yi = refine_batch()
            buf = torch.cat([buf, d_fake_input(yi, xpi)])
        buffer = buf[:args.buffer].clone()

    state = {"r_updates": 0, "d_updates": 0, "k": args.ratio, "best": float("inf"), "elapsed": 0.0, "history": []}
    if args.resume:
        ck = run.resume(rng, refiner=refiner, discriminator=disc, opt_r=opt_r, opt_d=opt_d)
        buffer = ck["buffer"]
        state = ck["state"]
        run.log.info("resumed at %d refiner / %d discriminator updates", state["r_updates"], state["d_updates"])
    else:
        params_r = sum(p.numel() for p in refiner.parameters())
        params_d = sum(p.numel() for p in disc.parameters())
        run.log.info("start: refiner %d parameters (hidden %d), discriminator %d (hidden %d), %d generated streams, "
                     "%d real training sequences, args %s", params_r, args.hidden, params_d, args.d_hidden,
                     len(fake.seqs), len(real.seqs), json.dumps(meta["args"]))
    with torch.no_grad():
        raw_skate, raw_share = skating(refiner, vx, vxp) if state["r_updates"] == 0 else (None, None)
        real_skate, real_share = skating(refiner, *vr)
    if raw_skate is not None:
        state["raw_valid"] = {"skating": raw_skate, "contact_share": raw_share}
        run.log.info("validation before training: generated skating %.3f m/s (contact share %.2f), "
                     "real held-out %.3f m/s (%.2f)", raw_skate, raw_share, real_skate, real_share)

    t0 = time.monotonic()
    elapsed = lambda: state["elapsed"] + time.monotonic() - t0

    def checkpoint() -> dict:
        return {"refiner": refiner.state_dict(), "discriminator": disc.state_dict(), "opt_r": opt_r.state_dict(),
                "opt_d": opt_d.state_dict(), "buffer": buffer, "rng": rng.bit_generator.state,
                "torch_rng": torch.get_rng_state(), "state": dict(state, elapsed=elapsed()), "meta": meta}

    def r_update(adversarial: bool) -> dict:
        x, xp, y = refine_batch()
        reg = root_loss(refiner, x, y)
        loss = args.lam * reg
        if args.pose_weight > 0:
            loss = loss + args.pose_weight * ((y - x)[..., 4:] ** 2).mean()
        adv = torch.zeros(())
        if adversarial:
            logits = disc(d_fake_input(y, xp))
            adv = F.binary_cross_entropy_with_logits(logits, torch.ones_like(logits))  # -log D(R(x)), eq. 9
            loss = loss + adv
        opt_r.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(refiner.parameters(), 10.0)
        opt_r.step()
        state["r_updates"] += 1
        return {"adv": float(adv.detach()), "root": float(reg.detach()), "y": y.detach(), "xp": xp}

    def d_update(last: dict | None) -> float:
        nonlocal buffer
        if last is None:
            with torch.no_grad():
                _, xp, y = refine_batch()
        else:
            xp, y = last["xp"], last["y"]
        with torch.no_grad():
            current = d_fake_input(y, xp)
            current = current[torch.from_numpy(rng.choice(len(current), half, replace=False))]
        old = buffer[torch.from_numpy(rng.choice(len(buffer), half, replace=False))]
        fake_in = torch.cat([current, old])
        real_in = d_real_input()
        lf, lr = disc(fake_in), disc(real_in)
        # eq. 10 as the mean cross-entropy over the batch of refined and real windows (a chance-level D scores
        # ln 2 = 0.69, so the thresholds 0.01 and 1 of the adaptive multiplier mean "too strong" and "lost")
        loss = 0.5 * (F.binary_cross_entropy_with_logits(lf, torch.zeros_like(lf))
                      + F.binary_cross_entropy_with_logits(lr, torch.ones_like(lr)))
        opt_d.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(disc.parameters(), 10.0)
        opt_d.step()
        buffer[torch.from_numpy(rng.choice(len(buffer), half, replace=False))] = current
        state["d_updates"] += 1
        return float(loss)

    @torch.no_grad()
    def validate() -> dict:
        refiner.eval()
        y, _ = refiner(vx, vxp)
        skate, share = skating(refiner, y, vxp)
        root = float(root_loss(refiner, vx, y))
        change = float((y - vx)[..., :-2].abs().mean())
        flips = float(((refiner.physical(y)[..., -2:] > 0.5) != (refiner.physical(vx)[..., -2:] > 0.5)).float().mean())
        pf = torch.sigmoid(disc(d_fake_input(y, vxp))).mean()
        pr = torch.sigmoid(disc(discriminator_input(refiner, *vr, bool(args.d_pose)))).mean()
        refiner.train()
        return {"skating": skate, "contact_share": share, "root_mse": root, "feature_change": change,
                "contact_flips": flips, "d_real": float(pr), "d_refined": float(pf)}

    bar = tqdm(total=args.iterations, initial=state["r_updates"], desc="refiner", unit="R-update")
    adv_hist, root_hist, d_hist = [], [], []
    last = None
    next_eval = (state["r_updates"] // args.eval_every + 1) * args.eval_every
    while state["r_updates"] < args.iterations:
        if state["r_updates"] < args.initial:
            last = r_update(adversarial=False)
            root_hist.append(last["root"])
            bar.update(1)
        elif state["d_updates"] < args.initial:
            d_hist.append(d_update(None))
        else:
            for _ in range(state["k"]):
                last = r_update(adversarial=True)
                adv_hist.append(last["adv"])
                root_hist.append(last["root"])
                bar.update(1)
            ld = d_update(last)
            d_hist.append(ld)
            # The multiplier follows a running mean of the D loss (single updates are noisy) and changes at
            # most once per 10 D updates.
            state["d_ema"] = ld if state.get("d_ema") is None else 0.8 * state["d_ema"] + 0.2 * ld
            state["since_change"] = state.get("since_change", 0) + 1
            if state["since_change"] >= 10 and (state["d_ema"] < 0.01 or state["d_ema"] > 1.0):
                state["k"] = min(state["k"] * 2, 80) if state["d_ema"] < 0.01 else max(state["k"] // 2, 1)
                state["since_change"] = 0
        bar.set_postfix(k=state["k"], adv=f"{np.mean(adv_hist[-50:]) if adv_hist else 0:.2f}",
                        d=f"{np.mean(d_hist[-20:]) if d_hist else 0:.2f}", root=f"{np.mean(root_hist[-50:]):.4f}")
        if state["r_updates"] >= next_eval:
            next_eval += args.eval_every
            v = validate()
            v.update(r_updates=state["r_updates"], d_updates=state["d_updates"], k=state["k"], minutes=elapsed() / 60,
                     adv=float(np.mean(adv_hist[-args.eval_every:])) if adv_hist else None,
                     d_loss=float(np.mean(d_hist[-50:])) if d_hist else None,
                     root=float(np.mean(root_hist[-args.eval_every:])))
            state["history"].append(v)
            run.log.info("R %d D %d k %d | adv %.3f d_loss %.3f root %.5f | valid skating %.3f (raw %.3f) share %.2f "
                         "root_mse %.4f change %.3f flips %.3f D(real) %.2f D(refined) %.2f | %.1f min",
                         v["r_updates"], v["d_updates"], v["k"], v["adv"] or 0, v["d_loss"] or 0, v["root"],
                         v["skating"], state.get("raw_valid", {}).get("skating", float("nan")), v["contact_share"],
                         v["root_mse"], v["feature_change"], v["contact_flips"], v["d_real"], v["d_refined"], v["minutes"])
            # Best: lowest validation skating, once adversarial training has started, as long as the contact
            # share stays near the generator's (turning contacts off would lower the measure trivially).
            raw_share = state.get("raw_valid", {}).get("contact_share", v["contact_share"])
            if state["d_updates"] >= args.initial and abs(v["contact_share"] - raw_share) < 0.1 and v["skating"] < state["best"]:
                state["best"] = v["skating"]
                run.save({"refiner": refiner.state_dict(), "state": dict(state, elapsed=elapsed()), "meta": meta,
                          "valid": v}, run.best_path)
        if run.due():
            run.save(checkpoint())
        if elapsed() > args.minutes * 60:
            run.log.info("stopped: time budget of %.0f minutes used", args.minutes)
            break
    bar.close()
    run.save(checkpoint())
    run.save({"refiner": refiner.state_dict(), "state": dict(state, elapsed=elapsed()), "meta": meta},
             run.dir / "last.pt")
    (run.dir / "summary.json").write_text(json.dumps(
        {"r_updates": state["r_updates"], "d_updates": state["d_updates"], "best_valid_skating": state["best"],
         "raw_valid": state.get("raw_valid"), "minutes": elapsed() / 60,
         "last_valid": state["history"][-1] if state["history"] else None}, indent=1))
    print(f"done: {state['r_updates']} refiner updates, best validation skating {state['best']:.3f} m/s; {run.dir}")


if __name__ == "__main__":
    main()
