"""The measurements behind docs/models/vae-lstm.md (python -m training.vae_lstm.evaluate), on the shipped ONNX
graphs as the page runs them (chunked cell, root moved by the control asked for).

- Prediction (the paper's Tables 1 and 2): the latent ERD report's windows of the held-out clips (16 seed
  frames, then 212 predicted; latent_erd/measures.py), driven by the clip's own control, smoothed as the model read
  it in training (ShippedVae.clip_control), while the root follows the clip's own (raw) control. From 4 initial
  frames: z1 is the posterior mean of the last 4 seed frames (padded as in training); from the prior: z1 is
  a draw of N(0, I). The generation starts at the first of those 4 frames, so its frame 4 + k - 1 is the
  window's predicted frame k. The root starts where the clip's (smoothed) root is at that frame and moves by
  the clip's own control: the model is given the control, as in the paper.
- Long runs: random control (training/control.py) for 3,000 frames, prior samples, the cell chunk after
  chunk; the pose change per second against the real clips' median (the latent ERD's freeze line), and the
  seams at the chunk boundaries.
- Diversity: prior samples for one control signal, mean pairwise joint distance relative to the hips,
  beside the same for real held-out and training windows with similar control.
- Foot sliding: both measures (contact bits; lowest foot point near the floor), before and after the
  contact labels and lock (footlock.plant_feet, as the page), against the held-out real clips.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import metrics
from ..control import random_control
from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, JOINTS, POSITION_DIM, WindowCorpus, ground_frame, rows_to_world
from ..latent_erd.measures import FREEZE_FRACTION, HORIZONS, PREDICT_FRAMES, SEED_FRAMES, Window, prediction_errors
from ..latent_erd.measures import prediction_windows as erd_prediction_windows
from ..latent_erd.measures import sliding
from ..onnx.sessions import cpu_session
from .generation import SEED_FRAMES as INITIAL_FRAMES
from .generation import SEED_PAD, free_latents, prior_latents
from .stride import phase_start, stride_sway
from .training import smoothed_control

LONG_RUN_FRAMES = 3000
DIVERSITY_SAMPLES = 10
SIMILAR_SPEED = 0.15  # m/s: real windows whose mean forward speed is this close count as similar control
SIMILAR_TURN = 0.15  # rad/s, the same for the mean turn
# Drawn paths (forward m/s, turn rad/s): a drawn path's control is constant, with none of the stride's sway a real
# root's velocity has (the page adds it: ShippedVae.read_control). For diversity over 4 s, and held for long runs.
DRAWN_CONTROLS = ((0.9, 0.0), (1.2, 0.0), (1.5, 0.0), (1.2, 0.5))
DRAWN_LONG_RUNS = {"walk, straight, 1.2 m/s": (1.2, 0.0), "walk, turning 0.5 rad/s, 1.2 m/s": (1.2, 0.5), "run, straight, 2.8 m/s": (2.8, 0.0)}
TOES = (JOINTS.index("LeftToeBase"), JOINTS.index("RightToeBase"))


def drawn_control(forward: float, turn: float, frames: int) -> np.ndarray:
    return np.tile([forward, 0.0, turn], (frames, 1))


@dataclass
class ShippedVae:
    """The four exported graphs and the JSON, run the way the page runs them."""
    info: dict
    sessions: dict

    @classmethod
    def load(cls, models_dir: Path) -> "ShippedVae":
        info = json.loads((models_dir / "vae-lstm.json").read_text())
        return cls(info, {k: cpu_session(models_dir / f) for k, f in info["files"].items()})

    @property
    def fps(self) -> float:
        return float(self.info["fps"])

    @property
    def mean(self) -> np.ndarray:
        return np.array(self.info["normalisation"]["mean"])

    @property
    def std(self) -> np.ndarray:
        return np.array(self.info["normalisation"]["std"])

    def rows(self, control: np.ndarray, z1: np.ndarray, zs: np.ndarray | None = None, mix: float | None = None) -> np.ndarray:
        """Physical rows (frames, dim) for a physical control (frames, 3) from z1 (latent,), with the per-step
        latents `zs` (steps, latent) when given: step t's content is mix · z_t + (1 − mix) · the previous state
        (mix defaults to 1 with `zs`, teacher mode, and 0 without, Algorithm 1's free mode)."""
        frames = len(control)
        padded = np.concatenate([control, np.repeat(control[-1:], -frames % 4, 0)])
        c = ((padded - self.mean[CONTROL_SLICE]) / self.std[CONTROL_SLICE]).astype(np.float32)
        hc = self.sessions["control"].run(["hc"], {"control": c[None]})[0]
        steps, chunk = hc.shape[1], self.info["chunk_steps"]
        n = -(-steps // chunk)
        hc = np.concatenate([hc, np.repeat(hc[:, -1:], n * chunk - steps, 1)], axis=1)
        latent = self.info["latent"]
        z = np.zeros((1, n * chunk, latent), np.float32)
        if zs is not None:
            z[0, :steps] = zs[:steps]
            z[0, steps:] = zs[steps - 1]
        mix = np.array([(0.0 if zs is None else 1.0) if mix is None else mix], np.float32)
        state, canvas = z1[None].astype(np.float32), []
        for k in range(n):
            part, state = self.sessions["cell"].run(["canvas", "state_out"], {"hc": hc[:, k * chunk:(k + 1) * chunk], "state": state,
                                                                              "z": z[:, k * chunk:(k + 1) * chunk], "mix": mix})
            canvas.append(part)
        canvas = np.concatenate(canvas, axis=1)[:, :steps]
        rows = self.sessions["decoder"].run(["rows"], {"canvas": canvas})[0][0, :frames]
        return rows.astype(np.float64) * self.std + self.mean

    def posterior_mean(self, initial_rows: np.ndarray) -> np.ndarray:
        """Mean of q(z1 | 4 normalised initial rows), the rows padded to SEED_PAD frames by repeating the last."""
        x = np.concatenate([initial_rows, np.repeat(initial_rows[-1:], SEED_PAD - len(initial_rows), 0)]).astype(np.float32)
        return self.sessions["inference"].run(["mean"], {"rows": x[None]})[0][0, 0]

    def prior(self, seed: int, frames: int, sampling: dict | None = None) -> tuple[np.ndarray, np.ndarray | None, float]:
        """A seed's prior sample for `frames` frames, drawn as the page draws it: z1, the per-step latents and the
        share of each step's content they give (rows' `mix`): for "steps" a latent per step in teacher mode, for
        "z1" what the model's free mode reads (generation.free_latents)."""
        sampling = sampling or self.info["sampling"]
        if sampling["mode"] == "z1":
            z1, _ = prior_latents(seed, self.info["latent"], z1_prior=sampling.get("z1_prior"))
            return (z1, *free_latents(z1, -(-frames // 4), sampling))
        z1, zs = prior_latents(seed, self.info["latent"], -(-frames // 4), sampling["rho"], sampling.get("z1_prior"))
        return z1, zs, 1.0

    @property
    def control_sigma(self) -> float:
        """Frames of Gaussian smoothing on the control the model read in training (its JSON's control_smoothing_frames)."""
        return float(self.info.get("control_smoothing_frames", 0.0))

    def clip_control(self, clip_rows: np.ndarray) -> np.ndarray:
        """A whole clip's own control (frames, 3) as the model reads it: smoothed as in training (training.smoothed_control, the same function),
        as a drawn path's has no per-stride sway. The raw signal carries the stride (the hips sway and surge with each
        step), which pins the phase of the motion it drives to the clip's."""
        return smoothed_control(clip_rows, self.control_sigma)

    def read_control(self, control: np.ndarray, seed: int) -> np.ndarray:
        """What the model reads for a drawn control (frames, 3), as the page feeds it: with the JSON's "stride", the
        control plus the sway a real walk has at its speed, from the seed's gait phase (stride.py)."""
        stride = self.info.get("stride")
        return control + stride_sway(control, self.fps, stride, phase_start(seed)) if stride else control

    def world(self, control: np.ndarray, z1: np.ndarray, zs: np.ndarray | None = None, mix: float | None = None,
              start_xz=(0.0, 0.0), start_heading: float = 0.0, root_control: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """World positions (frames, joints, 3) with the root moved by `root_control` (default `control`, what the model
        reads, as the page moves it by the control it asks for), and the decoded contact bits."""
        return self.place(self.rows(control, z1, zs, mix), control if root_control is None else root_control, start_xz, start_heading)

    def place(self, rows: np.ndarray, root_control: np.ndarray, start_xz=(0.0, 0.0), start_heading: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """World positions of rows the model made (rows' own local poses, the root moved by `root_control`), and the
        decoded contact bits."""
        placed = rows.copy()
        placed[:, CONTROL_SLICE] = root_control
        return rows_to_world(placed, self.fps, start_xz, start_heading), (rows[:, CONTACT_SLICE] > 0.5).astype(np.uint8)


# ---- prediction ---------------------------------------------------------------------------------

def vae_prediction(vae: ShippedVae, corpus: WindowCorpus, w: Window, prior: tuple | None, sampling: dict | None = None) -> np.ndarray:
    """World positions of the window's predicted frames (PREDICT_FRAMES): from 4 initial frames (prior None:
    z1 the posterior mean, Algorithm 1) or from the given prior sample (ShippedVae.prior)."""
    c = corpus.valid_clips[w.clip]
    begin = w.start + SEED_FRAMES - INITIAL_FRAMES
    frames = INITIAL_FRAMES + PREDICT_FRAMES
    if prior is None:
        z1 = vae.posterior_mean(corpus.valid[w.clip][begin:begin + INITIAL_FRAMES])
        prior = (z1, *free_latents(z1, -(-frames // 4), vae.info["sampling"]))
    z1, zs, mix = prior
    xz, heading = ground_frame(c.positions)
    control = vae.clip_control(c.rows)[begin:begin + frames]
    positions, _ = vae.world(control, z1, zs, mix, xz[begin], float(heading[begin]), root_control=c.rows[begin:begin + frames, CONTROL_SLICE])
    return positions[INITIAL_FRAMES:]


def still_mean_pose(vae: ShippedVae, corpus: WindowCorpus, w: Window) -> np.ndarray:
    """World positions of the window's predicted frames for the training clips' mean pose held still, its root moved
    by the window's control like the VAE-LSTM's: the long-horizon baseline of motion prediction (once the stride's
    phase is lost, an average error scores a body that barely moves well)."""
    c = corpus.valid_clips[w.clip]
    begin = w.start + SEED_FRAMES - INITIAL_FRAMES
    frames = INITIAL_FRAMES + PREDICT_FRAMES
    rows = np.tile(corpus.mean, (frames, 1))
    rows[:, CONTROL_SLICE] = c.rows[begin:begin + frames, CONTROL_SLICE]
    xz, heading = ground_frame(c.positions)
    return rows_to_world(rows, vae.fps, xz[begin], float(heading[begin]))[INITIAL_FRAMES:]


def prediction_rows(vae: ShippedVae, corpus: WindowCorpus, windows: list[Window], samplings: dict[str, dict]) -> dict:
    """Rows of the tables: from 4 initial frames (Algorithm 1 from the posterior's z1), from prior samples drawn
    each way in `samplings` (name: sampling), and the still mean pose."""
    real = [corpus.valid_clips[w.clip].positions[w.start + SEED_FRAMES: w.start + SEED_FRAMES + PREDICT_FRAMES] for w in windows]
    frames = INITIAL_FRAMES + PREDICT_FRAMES
    out = {"VAE-LSTM, 4 initial frames": prediction_errors([vae_prediction(vae, corpus, w, None) for w in windows], real)}
    for name, sampling in samplings.items():
        made = [vae_prediction(vae, corpus, w, vae.prior(i, frames, sampling)) for i, w in enumerate(windows)]
        out[f"VAE-LSTM, prior sample ({name})"] = prediction_errors(made, real)
    out[STILL_MEAN_POSE] = prediction_errors([still_mean_pose(vae, corpus, w) for w in windows], real)
    return out


STILL_MEAN_POSE = "mean pose held still (root moved by the control)"


# ---- long runs and seams --------------------------------------------------------------------------

def pose_change(positions: np.ndarray, fps: float) -> np.ndarray:
    return metrics.pose_change_per_second(positions, fps)


def long_run(vae: ShippedVae, seed: int, frames: int = LONG_RUN_FRAMES, sampling: dict | None = None) -> dict:
    control = random_control(seed, frames, vae.fps)
    t0 = time.perf_counter()
    positions, bits = vae.world(vae.read_control(control, seed), *vae.prior(seed, frames, sampling), root_control=control)
    seconds = time.perf_counter() - t0
    return {"seed": seed, "positions": positions, "bits": bits, "control": control, "seconds": seconds}


def toe_swing(local: np.ndarray, fps: float) -> np.ndarray:
    """Per whole second, the toes' forward swing (m): the range of each toe's forward offset from the hips in the
    facing frame over the second, the two toes averaged. A stepping walk swings 0.5-0.9 m; a gliding body ~0."""
    n = int(fps)
    seconds = len(local) // n
    forward = local[:seconds * n, TOES, 2].reshape(seconds, n, len(TOES))
    return (forward.max(axis=1) - forward.min(axis=1)).mean(axis=1)


def drawn_long_run(vae: ShippedVae, forward: float, turn: float, seed: int, median: float, frames: int = LONG_RUN_FRAMES,
                   sampling: dict | None = None) -> dict:
    """A prior sample driven by a constant control for `frames` frames: the toes' swing in the first 2 s and the last
    10 s, and the pose change per second against the real median (freeze_stats)."""
    control = drawn_control(forward, turn, frames)
    prior = vae.prior(seed, frames, sampling)
    rows = vae.rows(vae.read_control(control, seed), *prior)
    swing = toe_swing(local_positions(rows), vae.fps)
    positions, _ = vae.place(rows, control)
    return {"seed": seed, "first_2s_swing_m": round(float(swing[:2].mean()), 3), "last_10s_swing_m": round(float(swing[-10:].mean()), 3),
            **freeze_stats(positions, vae.fps, median)}


def real_toe_swing(corpus: WindowCorpus, fps: float, least_speed: float = 0.8) -> dict:
    """The held-out clips' toe swing per second, over the seconds whose mean forward speed is at least `least_speed`."""
    swings = []
    n = int(fps)
    for c in corpus.valid_clips:
        swing = toe_swing(local_positions(c.rows), fps)
        speed = c.rows[:len(swing) * n, CONTROL_SLICE.start].reshape(len(swing), n).mean(axis=1)
        swings += swing[speed >= least_speed].tolist()
    return {"median_m": round(float(np.median(swings)), 3), "seconds": len(swings), "least_speed": least_speed}


def chunk_seams(positions: np.ndarray, chunk_frames: int) -> dict:
    """Mean joint displacement relative to the hips between consecutive frames (cm/frame): across a chunk
    boundary of the cell (every chunk_frames frames) and elsewhere."""
    local = positions - positions[:, :1]
    d = np.linalg.norm(np.diff(local, axis=0), axis=-1).mean(axis=1) * 100
    boundary = (np.arange(1, len(positions)) % chunk_frames) == 0
    return {"boundary_cm": round(float(d[boundary].mean()), 3), "elsewhere_cm": round(float(d[~boundary].mean()), 3),
            "ratio": round(float(d[boundary].mean() / d[~boundary].mean()), 3), "boundaries": int(boundary.sum())}


# ---- diversity --------------------------------------------------------------------------------------

def mean_pairwise(motions: list[np.ndarray]) -> float:
    """Mean over pairs of the mean joint distance (cm) between two motions of equal length, each relative to
    its hips (root aligned) in its own facing frame."""
    d = [np.linalg.norm(motions[i] - motions[j], axis=-1).mean() for i in range(len(motions)) for j in range(i + 1, len(motions))]
    return round(float(np.mean(d)) * 100, 2)


def local_positions(rows: np.ndarray) -> np.ndarray:
    local = rows[:, :POSITION_DIM].reshape(len(rows), -1, 3)
    return local - local[:, :1]


def drawn_path_diversity(vae: ShippedVae, window: int = 120, sampling: dict | None = None) -> list[dict]:
    """Prior samples for constant controls (DRAWN_CONTROLS): mean pairwise distance of all joints and of the toes
    alone, relative to the hips, over the window and over its last 2 s (do the samples converge?)."""
    out = []
    for forward, turn in DRAWN_CONTROLS:
        control = drawn_control(forward, turn, window)
        samples = [local_positions(vae.rows(vae.read_control(control, 1000 + k), *vae.prior(1000 + k, window, sampling)))
                   for k in range(DIVERSITY_SAMPLES)]
        late = [s[-2 * int(vae.fps):] for s in samples]
        out.append({"forward": forward, "turn": turn, "joints_cm": mean_pairwise(samples), "joints_last_2s_cm": mean_pairwise(late),
                    "toes_cm": mean_pairwise([s[:, TOES] for s in samples]), "toes_last_2s_cm": mean_pairwise([s[:, TOES] for s in late])})
    return out


def diversity(vae: ShippedVae, corpus: WindowCorpus, window: int = 120, sampling: dict | None = None) -> dict:
    """Prior samples for the control of each held-out window against the real windows of similar control."""
    out = []
    all_clips = corpus.valid_clips + corpus.train_clips[::6]  # the training clips unaugmented: every 6th copy
    real_windows = [(c.rows[a:a + window]) for c in all_clips for a in range(0, len(c.rows) - window + 1, window // 2)]
    stats = np.array([[r[:, CONTROL_SLICE.start].mean(), r[:, CONTROL_SLICE.start + 2].mean()] for r in real_windows])
    for c in corpus.valid_clips:
        clip_control = vae.clip_control(c.rows)
        for a in range(0, len(c.rows) - window + 1, window):
            control = clip_control[a:a + window]
            samples = [local_positions(vae.rows(control, *vae.prior(1000 + k, window, sampling))) for k in range(DIVERSITY_SAMPLES)]
            fwd, turn = control[:, 0].mean(), control[:, 2].mean()
            similar = [local_positions(real_windows[i]) for i in np.flatnonzero((np.abs(stats[:, 0] - fwd) < SIMILAR_SPEED) & (np.abs(stats[:, 1] - turn) < SIMILAR_TURN))]
            out.append({"clip": c.file, "start": a, "forward": round(float(fwd), 2), "turn": round(float(turn), 2),
                        "prior_samples_cm": mean_pairwise(samples), "real_similar_cm": mean_pairwise(similar[:20]) if len(similar) > 1 else None,
                        "prior_toes_cm": mean_pairwise([x[:, TOES] for x in samples]),
                        "real_similar_toes_cm": mean_pairwise([x[:, TOES] for x in similar[:20]]) if len(similar) > 1 else None,
                        "real_similar_windows": len(similar)})
    return {"windows": out, "samples": DIVERSITY_SAMPLES,
            "prior_samples_cm": round(float(np.mean([o["prior_samples_cm"] for o in out])), 2),
            "real_similar_cm": round(float(np.mean([o["real_similar_cm"] for o in out if o["real_similar_cm"] is not None])), 2),
            "prior_toes_cm": round(float(np.mean([o["prior_toes_cm"] for o in out])), 2),
            "real_similar_toes_cm": round(float(np.mean([o["real_similar_toes_cm"] for o in out if o["real_similar_toes_cm"] is not None])), 2),
            "drawn_paths": drawn_path_diversity(vae, window, sampling)}


# ---- held-out control ----------------------------------------------------------------------------------------

def held_out_control_runs(vae: ShippedVae, corpus: WindowCorpus, sampling: dict | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each held-out clip's own control, a prior sample per clip: positions and decoded bits."""
    return [vae.world(vae.clip_control(c.rows), *vae.prior(i, len(c.rows), sampling), root_control=c.rows[:, CONTROL_SLICE])
            for i, c in enumerate(corpus.valid_clips)]


def jitter_cm(motions: list[np.ndarray]) -> float:
    """RMS second difference (cm per frame²) of the joints relative to the hips, over all frames of all motions."""
    sq = [(np.diff(p - p[:, :1], n=2, axis=0) ** 2).sum(-1).ravel() for p in motions]
    return round(float(np.sqrt(np.concatenate(sq).mean()) * 100), 3)


def freeze_stats(positions: np.ndarray, fps: float, median: float) -> dict:
    changes = pose_change(positions, fps)
    return {"lowest_second": round(float(changes.min() / median), 3), "median_second": round(float(np.median(changes) / median), 3),
            "share_below": round(float((changes < FREEZE_FRACTION * median).mean()), 4)}


__all__ = ["HORIZONS", "ShippedVae", "chunk_seams", "diversity", "freeze_stats", "held_out_control_runs", "long_run",
           "prediction_rows", "sliding"]


# ---- the MAP follower on the clips' own root paths (run in the page: npm run evaluate:vae-lstm) ----------

def map_follow_windows(corpus: WindowCorpus) -> dict:
    """For each prediction window: the clip's (smoothed) root path over the predicted frames, as the ground path
    the generator's MAP follower walks in the page, and the real joint positions at each horizon, so the page
    measures its error the same way as the rows computed here."""
    out = []
    for w in erd_prediction_windows(corpus):
        c = corpus.valid_clips[w.clip]
        start = w.start + SEED_FRAMES
        xz, _ = ground_frame(c.positions)
        real = c.positions[start:start + PREDICT_FRAMES]
        out.append({"clip": c.file, "start": start, "points": xz[start - 1:start + PREDICT_FRAMES].round(4).tolist(),
                    "real": {str(k): real[k - 1].round(4).tolist() for k in HORIZONS}})
    return {"horizons": list(HORIZONS), "windows": out}
