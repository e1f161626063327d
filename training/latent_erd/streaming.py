"""Online generation with the latent ERD, exactly as the page runs it (web/runtime/latentErd*.ts); the
fixture tests/fixtures/latent_erd_reference.json checks the two against each other.

The decoder needs latents on both sides of a frame (RADIUS = 9 steps, 1.2 s each way), so a stream cannot
wait for the real future. Each latent step (4 frames, 133 ms):

1. the ERD commits the next latent from the current one and the control for that step;
2. it looks ahead LOOKAHEAD more steps from a copy of its state, with the control it expects (the same
   control repeated, or the known future control when there is one): a guess at the future, thrown away
   afterwards;
3. the decoder turns the window [RADIUS committed steps, the new one, the guesses, the last guess repeated up
   to RADIUS] into the 4 frames of the new step (autoencoder/exporting.py ValidDecoder);
4. the root moves by the decoded frames' own control channels (training/control.py integrate_control), so
   the feet and the root agree.

So a change of control shows in the next emitted step: the added lag is one latent step (133 ms) at most,
with no wait for the decoder's future context. The cost is LOOKAHEAD extra ERD steps per 4 frames.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch

from ..autoencoder.exporting import RADIUS, ValidDecoder
from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, POSITION_DIM
from ..models.autoencoder import POOLING, MotionAutoencoder
from ..models.erd import ControlERD
from ..onnx.sessions import cpu_session

# Chosen by measurement (docs/models/latent-erd.md): across a step boundary the pose jumps 2.0 cm with 3 guesses
# against 1.3 cm inside a step (ratio 1.55; 6 guesses: ratio 1.08), but in Chromium 6 guesses brought the
# slowest benchmark path down to 20.5x real time (target 20x) and the worst 180-degree turn to 1.40 s, against
# 24-37x (two runs) and 1.30 s with 3.
LOOKAHEAD = 3


class TorchBackend:
    """The trained networks in torch (evaluation)."""

    def __init__(self, erd: ControlERD, autoencoder: MotionAutoencoder):
        self.erd, self.decoder = erd.eval(), ValidDecoder(autoencoder).eval()

    def step(self, z, control, h, c):
        with torch.no_grad():
            y, (h2, c2) = self.erd(torch.from_numpy(z)[:, None], torch.from_numpy(control)[:, None],
                                   (torch.from_numpy(h), torch.from_numpy(c)))
        return y[:, 0].numpy(), h2.numpy(), c2.numpy()

    def decode(self, window):
        with torch.no_grad():
            return self.decoder(torch.from_numpy(window)).numpy()


class OnnxBackend:
    """The exported graphs in onnxruntime (parity, and what the page runs)."""

    def __init__(self, erd_path, decoder_path):
        self.erd, self.decoder = cpu_session(erd_path), cpu_session(decoder_path)

    def step(self, z, control, h, c):
        return tuple(self.erd.run(["z_next", "h_out", "c_out"], {"z": z, "control": control, "h": h, "c": c}))

    def decode(self, window):
        return self.decoder.run(["rows"], {"latent": window})[0]


@dataclass
class Normalisation:
    latent_mean: np.ndarray
    latent_std: np.ndarray
    row_mean: np.ndarray
    row_std: np.ndarray

    @classmethod
    def from_meta(cls, meta: dict) -> "Normalisation":
        return cls(*(np.asarray(meta[k], np.float64) for k in ("latent_mean", "latent_std", "row_mean", "row_std")))

    def control(self, frames: np.ndarray) -> np.ndarray:
        """Physical control (4, 3) -> the ERD's normalised step control (12,)."""
        m, s = self.row_mean[CONTROL_SLICE], self.row_std[CONTROL_SLICE]
        return ((np.asarray(frames, np.float64) - m) / s).reshape(-1).astype(np.float32)


@dataclass
class Root:
    x: float = 0.0
    z: float = 0.0
    heading: float = 0.0


@dataclass
class StreamOutput:
    rows: np.ndarray       # (4, 80) physical rows
    positions: np.ndarray  # (4, joints, 3) world
    roots: np.ndarray      # (4, 3) x, z, heading of each frame
    contacts: np.ndarray   # (4, 2) 0/1


@dataclass
class LatentStream:
    """One walker: the ERD state, the latest committed latents and the root. Starts from a seed: P real latent
    steps (normalised) and their controls; the ERD reads the seed teacher-forced, and the first emitted frames
    are those of the step after it."""
    backend: object
    norm: Normalisation
    seed_latents: np.ndarray   # (P, latent) normalised
    seed_controls: np.ndarray  # (P, 12) normalised
    state_shape: tuple         # (layers, hidden)
    fps: float = 30.0
    lookahead: int = LOOKAHEAD
    root: Root = field(default_factory=Root)

    def __post_init__(self):
        z = self.seed_latents.astype(np.float32)
        layers, hidden = self.state_shape
        self.h, self.c = np.zeros((layers, 1, hidden), np.float32), np.zeros((layers, 1, hidden), np.float32)
        for i in range(len(z) - 1):
            _, self.h, self.c = self.backend.step(z[i:i + 1], self.seed_controls[i + 1:i + 2].astype(np.float32), self.h, self.c)
        self.current = z[-1:].copy()
        self.history = list(z)

    def step(self, control: np.ndarray, future: list[np.ndarray] | None = None) -> StreamOutput:
        """Emit the next 4 frames for `control` (4, 3) physical; `future` optionally gives the expected controls
        (4, 3) of the steps after it, for the look-ahead (else `control` is repeated)."""
        c_now = self.norm.control(control)
        z, self.h, self.c = self.backend.step(self.current, c_now[None], self.h, self.c)
        self.current = z
        self.history.append(z[0])
        guesses, zz, h, c = [], z, self.h, self.c
        for k in range(self.lookahead):
            ck = self.norm.control(future[k]) if future is not None and k < len(future) else c_now
            zz, h, c = self.backend.step(zz, ck[None], h, c)
            guesses.append(zz[0])
        past = self.history[-(RADIUS + 1):]
        past = [past[0]] * (RADIUS + 1 - len(past)) + past
        ahead = guesses + [guesses[-1] if guesses else past[-1]] * (RADIUS - len(guesses))
        window = np.stack(past + ahead)[None] * self.norm.latent_std + self.norm.latent_mean
        rows = self.backend.decode(window.astype(np.float32))[0].astype(np.float64) * self.norm.row_std + self.norm.row_mean
        if len(self.history) > RADIUS + 1:
            self.history = self.history[-(RADIUS + 1):]
        return self._place(rows)

    def _place(self, rows: np.ndarray) -> StreamOutput:
        positions, roots = place_rows(rows, self.root, self.fps)
        return StreamOutput(rows, positions, roots, (rows[:, CONTACT_SLICE] > 0.5).astype(np.uint8))


def place_rows(rows: np.ndarray, root: Root, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """World positions (frames, joints, 3) and roots (frames, 3: x, z, heading) of physical rows, the root
    moved by the rows' own control channels from `root`, which is advanced past them (in place)."""
    local = rows[:, :POSITION_DIM].reshape(len(rows), -1, 3)
    positions = np.empty_like(local)
    roots = np.empty((len(rows), 3))
    for t in range(len(rows)):
        ch, sh = np.cos(root.heading), np.sin(root.heading)
        lx, lz = local[t, :, 0], local[t, :, 2]
        positions[t, :, 0] = ch * lx + sh * lz + root.x
        positions[t, :, 1] = local[t, :, 1]
        positions[t, :, 2] = -sh * lx + ch * lz + root.z
        roots[t] = root.x, root.z, root.heading
        fwd, side, turn = rows[t, CONTROL_SLICE] / fps
        root.x += ch * side + sh * fwd
        root.z += -sh * side + ch * fwd
        root.heading = float((root.heading + turn + np.pi) % (2 * np.pi) - np.pi)
    return positions, roots


def run_stream(stream: LatentStream, controls: np.ndarray, known_future: bool = True) -> StreamOutput:
    """Frames for a whole per-frame control (frames, 3), 4 at a time (frames cut to a multiple of 4)."""
    steps = len(controls) // POOLING
    per_step = controls[:steps * POOLING].reshape(steps, POOLING, 3)
    outs = []
    for s in range(steps):
        future = list(per_step[s + 1:s + 1 + stream.lookahead]) if known_future else None
        outs.append(stream.step(per_step[s], future))
    cat = lambda name: np.concatenate([getattr(o, name) for o in outs])
    return StreamOutput(cat("rows"), cat("positions"), cat("roots"), cat("contacts"))
