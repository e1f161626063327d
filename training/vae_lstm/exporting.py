"""Exporting the VAE-LSTM: four ONNX graphs, their JSON, parity checked, and
tests/fixtures/vae_lstm_reference.json for the browser's parity tests.

- vae-lstm.onnx, the cell (eqs. 7–9) over one chunk of CHUNK_STEPS steps: hc (batch, 30, 128), state (batch,
  latent), z (batch, 30, latent), mix (1,) -> canvas (batch, 30, latent), state_out. Step t's content is
  mix · z_t + (1 − mix) · the previous state: mix 0 is the free mode of Algorithm 1 (z unused), mix 1 the
  teacher mode with a latent per step (the paper's other way to sample). The state goes in and out, so a path
  of any length runs chunk after chunk (generation.py).
- vae-lstm-control.onnx, the control encoder: control (batch, frames, 3) normalised, frames a multiple of 4
  -> hc (batch, frames / 4, 128).
- vae-lstm-decoder.onnx: canvas (batch, steps, latent) -> rows (batch, 4 × steps, 80) normalised.
- vae-lstm-inference.onnx, the inference network: rows (batch, frames, 80) normalised -> mean and log_var
  (batch, frames / 4, latent) of the posterior of each step.

The batch dimension is dynamic in all four, and so are frames and steps in the convolutional three. Large
weights are stored as int8 with a float32 scale per output channel (or float16, or left float32: `weights`;
training/onnx/compact.py), turned back into float32 inside the graph when the session is created. The parity
check, the JSON's parity numbers and the fixture use torch holding the weights as stored: the network read back
from the written files (recovery.py), so the browser's tolerances hold whatever the format.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch
from torch import nn

from ..data.windows import CONTACT_SLICE, CONTROL_SLICE, JOINTS, POSITION_DIM, WindowCorpus
from ..mocap.skeleton import canonical_skeleton
from ..models.vae_lstm import KERNEL, POOLING, VaeLstm
from ..onnx.compact import compact_weights, files_weight_format
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR, REPO_ROOT
from .generation import CHUNK_STEPS, SEED_FRAMES, SEED_PAD, free_latents, prior_latents
from .prior_bank import posterior_prior
from .stride import fit_stride, phase_start, stride_sway
from .recovery import vae_lstm_from_onnx

PARITY_TOLERANCE = 1e-4
PRIOR_FIXTURE_SEED = 3
PRIOR_FIXTURE_RHO = 0.9
PRIOR_FIXTURE_SEEDS = (0, 4, 1234567)
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "vae_lstm_reference.json"
FILES = {"cell": "vae-lstm.onnx", "control": "vae-lstm-control.onnx", "decoder": "vae-lstm-decoder.onnx",
         "inference": "vae-lstm-inference.onnx"}
NAMES = {"cell": (["hc", "state", "z", "mix"], ["canvas", "state_out"]), "control": (["control"], ["hc"]),
         "decoder": (["canvas"], ["rows"]), "inference": (["rows"], ["mean", "log_var"])}


class CellChunk(nn.Module):
    def __init__(self, model: VaeLstm):
        super().__init__()
        self.cell = model.cell

    def forward(self, hc, state, z, mix):
        canvas = []
        for t in range(hc.shape[1]):
            state = self.cell(state, mix * z[:, t] + (1 - mix) * state, hc[:, t])
            canvas.append(state)
        return torch.stack(canvas, dim=1), state


class Wrap(nn.Module):
    def __init__(self, fn):
        super().__init__()
        self.fn = fn

    def forward(self, x):
        return self.fn(x)


def graphs(model: VaeLstm) -> dict[str, nn.Module]:
    return {"cell": CellChunk(model), "control": Wrap(model.control_encoder), "decoder": Wrap(model.decoder),
            "inference": Wrap(model.inference)}


def example_inputs(model: VaeLstm, batch: int = 1, frames: int = 40) -> dict[str, tuple[torch.Tensor, ...]]:
    hc_dim = model.cell.gates_control.in_features
    return {"cell": (torch.zeros(batch, CHUNK_STEPS, hc_dim), torch.zeros(batch, model.latent), torch.zeros(batch, CHUNK_STEPS, model.latent), torch.zeros(1)),
            "control": (torch.zeros(batch, frames, model.control),),
            "decoder": (torch.zeros(batch, frames // POOLING, model.latent),),
            "inference": (torch.zeros(batch, frames, model.dim),)}


def export_graphs(model: VaeLstm, out: Path, weights: str = "float32") -> VaeLstm:
    """Writes the four graphs into `out` with their large weights stored as `weights`; returns the network the files
    compute (the weights as stored, read back from them), the reference for the parity check and the fixture."""
    b = {0: "batch"}
    dynamic = {"cell": {"hc": b, "state": b, "z": b, "canvas": b, "state_out": b},
               "control": {"control": {0: "batch", 1: "frames"}, "hc": {0: "batch", 1: "steps"}},
               "decoder": {"canvas": {0: "batch", 1: "steps"}, "rows": {0: "batch", 1: "frames"}},
               "inference": {"rows": {0: "batch", 1: "frames"}, "mean": {0: "batch", 1: "steps"}, "log_var": {0: "batch", 1: "steps"}}}
    examples = example_inputs(model)
    for key, graph in graphs(model).items():
        inputs, outputs = NAMES[key]
        path = out / FILES[key]
        torch.onnx.export(graph.eval(), examples[key], str(path), input_names=inputs, output_names=outputs,
                          opset_version=17, dynamo=False, dynamic_axes=dynamic[key])
        if weights != "float32":
            onnx.save(compact_weights(onnx.load(str(path)), weights), str(path))
    return vae_lstm_from_onnx(out, FILES)


def random_inputs(model: VaeLstm, rng: np.random.Generator, batch: int, frames: int) -> dict[str, list[np.ndarray]]:
    hc_dim = model.cell.gates_control.in_features
    f32 = lambda *shape: rng.normal(size=shape).astype(np.float32)
    mix = np.array([rng.choice([0.0, 0.3, 1.0])], np.float32)
    return {"cell": [np.abs(f32(batch, CHUNK_STEPS, hc_dim)), f32(batch, model.latent), f32(batch, CHUNK_STEPS, model.latent), mix],
            "control": [f32(batch, frames, model.control)], "decoder": [f32(batch, frames // POOLING, model.latent)],
            "inference": [f32(batch, frames, model.dim)]}


def check_parity(model: VaeLstm, out: Path) -> dict[str, float]:
    """torch against onnxruntime for every graph at batch 1 and 3 and two lengths."""
    worst = dict.fromkeys(FILES, 0.0)
    rng = np.random.default_rng(1)
    modules = graphs(model)
    for key in FILES:
        session = cpu_session(out / FILES[key])
        for batch, frames in ((1, 40), (3, 200)):
            inputs = random_inputs(model, rng, batch, frames)[key]
            with torch.no_grad():
                ref = modules[key].eval()(*map(torch.from_numpy, inputs))
            ref = ref if isinstance(ref, tuple) else (ref,)
            got = session.run(NAMES[key][1], dict(zip(NAMES[key][0], inputs)))
            for r, g in zip(ref, got):
                worst[key] = max(worst[key], float(np.abs(r.numpy() - g).max()))
    for key, value in worst.items():
        if value > PARITY_TOLERANCE:
            raise SystemExit(f"error: {key} graph parity {value:.2e} exceeds {PARITY_TOLERANCE}")
    return worst


def vae_lstm_info(meta: dict, model: VaeLstm, report: dict, sampling: dict) -> dict:
    skel = canonical_skeleton()
    return {
        "id": "vae-lstm", "kind": "vae-lstm", "file": FILES["cell"], "files": FILES, "fps": meta["fps"],
        "window": meta["window"], "pooling": POOLING, "kernel": KERNEL, "chunk_steps": CHUNK_STEPS,
        "latent": model.latent, "control_features": model.cell.gates_control.in_features,
        "seed_frames": SEED_FRAMES, "seed_pad": SEED_PAD, "control_smoothing_frames": meta["control_sigma"],
        "sampling": sampling,
        "onnx": {key: {"inputs": NAMES[key][0], "outputs": NAMES[key][1]} for key in FILES},
        "skeleton": {"joints": skel.joints, "parents": skel.parents, "offsets": skel.offsets.round(6).ravel().tolist()},
        "rows": {"dim": model.dim, "positions": [0, POSITION_DIM], "control": [CONTROL_SLICE.start, CONTROL_SLICE.stop],
                 "contacts": [CONTACT_SLICE.start, CONTACT_SLICE.stop], "joints": JOINTS,
                 "positions_frame": "each frame's ground-projected root facing frame: x left, y up (height above the floor), z forward",
                 "control_channels": ["forward m/s", "sideways m/s (+ left)", "turn rad/s (+ from +z towards +x)"]},
        "normalisation": {"mean": [round(float(v), 6) for v in meta["row_mean"]], "std": [round(float(v), 6) for v in meta["row_std"]]},
        "report": report,
    }


def generate_rows(model: VaeLstm, control: np.ndarray, z1: np.ndarray, zs: np.ndarray | None = None, mix: float | None = None) -> np.ndarray:
    """Normalised rows (frames, dim) for a normalised control (frames, 3), frames a multiple of 4, from z1
    (latent,), the cell run chunk by chunk as the page runs it (the last chunk padded with its last step); with
    `zs` (steps, latent) each step's content is mix · z_t + (1 − mix) · the previous state (mix default 1: teacher
    mode)."""
    with torch.no_grad():
        hc = model.control_encoder(torch.from_numpy(control[None].astype(np.float32)))
        steps = hc.shape[1]
        chunks = -(-steps // CHUNK_STEPS)
        pad = lambda x: torch.cat([x, x[:, -1:].expand(-1, chunks * CHUNK_STEPS - steps, -1)], dim=1)
        padded = pad(hc)
        z = pad(torch.from_numpy(zs[None].astype(np.float32))) if zs is not None else torch.zeros(1, chunks * CHUNK_STEPS, model.latent)
        mix = torch.tensor([(1.0 if zs is not None else 0.0) if mix is None else mix])
        state, canvas, chunk = torch.from_numpy(z1[None].astype(np.float32)), [], CellChunk(model)
        for k in range(chunks):
            part, state = chunk(padded[:, k * CHUNK_STEPS:(k + 1) * CHUNK_STEPS], state, z[:, k * CHUNK_STEPS:(k + 1) * CHUNK_STEPS], mix)
            canvas.append(part)
        return model.decoder(torch.cat(canvas, dim=1)[:, :steps]).numpy()[0]


def write_fixture(model: VaeLstm, info: dict, path: Path = FIXTURE) -> None:
    """Inputs and torch outputs of each graph; one whole generation over two chunks (36 steps) in free mode from
    z1, and the same in teacher mode on given per-step latents; and the prior draws of one seed
    (generation.prior_latents, as the page draws them), for the browser's parity tests."""
    rng = np.random.default_rng(7)
    inputs = random_inputs(model, rng, 1, 16)
    modules = graphs(model)
    graphs_out = {}
    for key in FILES:
        with torch.no_grad():
            ref = modules[key].eval()(*map(torch.from_numpy, inputs[key]))
        ref = ref if isinstance(ref, tuple) else (ref,)
        graphs_out[key] = {"inputs": {n: {"dims": list(a.shape), "data": a.ravel().round(6).tolist()} for n, a in zip(NAMES[key][0], inputs[key])},
                           "outputs": {n: r.numpy().ravel().round(6).tolist() for n, r in zip(NAMES[key][1], ref)}}
    frames = 4 * (CHUNK_STEPS + 6)
    t = np.arange(frames) / info["fps"]
    physical = np.stack([1.2 + 0.2 * np.sin(t), np.zeros_like(t), 0.6 * np.sin(0.5 * t)], axis=1).round(6)
    mean, std = np.array(info["normalisation"]["mean"])[CONTROL_SLICE], np.array(info["normalisation"]["std"])[CONTROL_SLICE]
    z1 = rng.normal(size=model.latent).round(6).astype(np.float32)
    # The free mode as the page runs it for this model (with z1 in every step when it was trained so).
    rows = generate_rows(model, ((physical - mean) / std).astype(np.float32), z1, *free_latents(z1, frames // POOLING, info["sampling"]))
    prior, prior_steps = prior_latents(PRIOR_FIXTURE_SEED, model.latent, 5, PRIOR_FIXTURE_RHO)
    z1_prior = info["sampling"].get("z1_prior")
    # The shipped draw of z1 for a few seeds (generation.draw_z1 with the JSON's z1_prior, when it has one).
    shipped_draws = {str(seed): prior_latents(seed, model.latent, z1_prior=z1_prior)[0].tolist() for seed in PRIOR_FIXTURE_SEEDS}
    # The stride's sway added to a drawn control (stride.py), on a control whose speed crosses every band.
    stride = info.get("stride")
    sway_control = np.stack([np.linspace(0.0, 3.0, 150), np.zeros(150), np.full(150, 0.3)], axis=1).round(6)
    sway = {"control": sway_control.ravel().tolist(),
            "seeds": {str(seed): {"phase": phase_start(seed), "sway": stride_sway(sway_control, info["fps"], stride, phase_start(seed)).ravel().tolist()}
                      for seed in PRIOR_FIXTURE_SEEDS}} if stride else None
    steps = frames // POOLING
    zs = rng.normal(size=(steps, model.latent)).round(6).astype(np.float32)
    rows_steps = generate_rows(model, ((physical - mean) / std).astype(np.float32), z1, zs)
    fixture = {"model": info["id"], "tolerance": 2e-4, "graphs": graphs_out,
               "prior": {"seed": PRIOR_FIXTURE_SEED, "z1": prior.tolist(), "rho": PRIOR_FIXTURE_RHO, "steps": prior_steps.tolist()},
               "shipped_prior": {"z1_prior": z1_prior is not None, "z1": shipped_draws},
               "stride_sway": sway,
               "generate_steps": {"zs": zs.round(6).ravel().tolist(), "rows": rows_steps.round(6).ravel().tolist()},
               "generate": {"control": physical.round(6).ravel().tolist(), "frames": frames, "z1": z1.round(6).tolist(),
                            "rows": rows.round(6).ravel().tolist()}}
    path.write_text(json.dumps(fixture) + "\n")


def files_format(out: Path) -> str:
    """How the four files store their large weights ("int8", or e.g. "float32/int8" when they differ)."""
    return files_weight_format([out / f for f in FILES.values()])


def _write_checked(model: VaeLstm, out: Path, weights: str) -> tuple[VaeLstm, dict]:
    """The four graphs written and parity-checked against torch with the weights as stored; returns that network
    and the JSON's parity fields."""
    out.mkdir(parents=True, exist_ok=True)
    stored = export_graphs(model.eval(), out, weights)
    fields = {"parity_max_abs": check_parity(stored, out),
              "parity_reference": f"torch with the weights as stored ({files_format(out)})"}
    return stored, fields


def _publish(info: dict, stored: VaeLstm, out: Path) -> None:
    """vae-lstm.json beside the graphs; into MODELS_DIR also the manifest entry and the browser fixture (written
    from the network as stored)."""
    info["bytes"] = sum((out / f).stat().st_size for f in FILES.values())
    info["weights"] = files_format(out)
    (out / "vae-lstm.json").write_text(json.dumps(info) + "\n")
    if out.resolve() == MODELS_DIR.resolve():
        register_model({"id": "vae-lstm", "kind": "vae-lstm", "skeleton": "cmu-canonical", "fps": info["fps"],
                        "bytes": info["bytes"], "file": FILES["cell"], "files": FILES}, "cmu-locomotion")
        write_fixture(stored, info)
    print(f"wrote {', '.join(FILES.values())} in {out} ({info['bytes'] / 1e6:.2f} MB, {info['weights']}), "
          f"parity {info['parity_max_abs']}")


def export_vae_lstm(model: VaeLstm, meta: dict, report: dict, sampling: dict, out: Path = MODELS_DIR,
                    weights: str = "int8", corpus: WindowCorpus | None = None, z1_prior: bool = True) -> dict:
    """The four graphs and the JSON; with the training `corpus`, fit_sampling_fields: a drawn path gets the stride's
    sway (stride.py) and, with `z1_prior`, a "z1" sampling draws z1 from the posteriors of its training starts
    (prior_bank.py) instead of N(0, I)."""
    stored, parity = _write_checked(model, out, weights)
    info = vae_lstm_info(meta, model, report, sampling) | parity
    if corpus is not None:
        fit_sampling_fields(info, out, corpus, z1_prior)
    _publish(info, stored, out)
    return info


def rewrite_vae_lstm(source: Path, out: Path = MODELS_DIR, weights: str = "int8") -> dict:
    """The export in `source` (vae-lstm.json and its four graphs) written again into `out` with its weights stored
    as `weights`, without a checkpoint: the network is read back from the graphs (recovery.py), the JSON is kept
    but for its parity, bytes and weights fields. Rewriting int8 files as int8 stores the same values again (each
    channel's largest weight is already ±127 steps), but the float32 export is the one to start from."""
    info = json.loads((source / "vae-lstm.json").read_text())
    if info.get("files") != FILES:
        raise ValueError(f"{source / 'vae-lstm.json'} names the graphs {info.get('files')}, not {FILES}")
    model = vae_lstm_from_onnx(source, FILES)
    stored, parity = _write_checked(model, out, weights)
    info |= parity
    _publish(info, stored, out)
    return info


def fit_sampling_fields(info: dict, graphs: Path, corpus: WindowCorpus, z1_prior: bool = True) -> None:
    """Fits into `info` (a vae-lstm.json) what the page draws and reads besides the graphs in `graphs`: the stride a
    drawn path lacks (stride.py), and (`z1_prior`, for a "z1" sampling) the z1 prior, the posteriors of training
    starts (prior_bank.py, on the inference graph)."""
    if z1_prior and info["sampling"]["mode"] == "z1":
        info["sampling"] = info["sampling"] | {"z1_prior": posterior_prior(graphs / FILES["inference"], corpus)}
    info["stride"] = fit_stride(corpus, float(info["control_smoothing_frames"]), float(info["fps"]))


def refit_sampling_fields(corpus: WindowCorpus, models_dir: Path = MODELS_DIR) -> dict:
    """fit_sampling_fields on the shipped export's JSON, written back; and the browser fixture written again from the
    shipped graphs."""
    path = models_dir / "vae-lstm.json"
    info = json.loads(path.read_text())
    fit_sampling_fields(info, models_dir, corpus)
    path.write_text(json.dumps(info) + "\n")
    if models_dir.resolve() == MODELS_DIR.resolve():
        write_fixture(vae_lstm_from_onnx(models_dir, FILES), info)
    return info
