"""Exporting the dance models (acLSTM and its vanilla baseline): ONNX step plus JSON, parity checked.

public/models/<id>.onnx runs K steps in one call: x, style, h, c, steps -> ys (steps frames), h_out, c_out (the batch
dimension is dynamic; training/aclstm/graph.py); its large weights are stored as int8 by default (or float16/float32: --weights; training/onnx/compact.py).
<id>.json holds the skeleton, feature layout, normalisation, per-style seed motions (10 real frames each,
from held-out clips), the real per-second pose change per style, training and parity numbers.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch

from ..data.dance import STYLES, DanceClip, decode, encode, load_clips, real_pose_change, resample_positions
from ..models.aclstm import DanceLSTM
from ..onnx.compact import compact_weights, weight_format
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR, REPO_ROOT
from .calibration import input_moments
from .graph import (MDN_OUTPUTS, OUTPUTS, check_parity, dance_graph, dance_model_from_onnx, graph_inputs, graph_outputs,
                    mdn_torch_steps)

SEED_FRAMES = 10  # the paper's seed length (about 170 ms at 60 fps)
SEEDS_PER_STYLE = 8
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "aclstm_reference.json"
MDN_FIXTURE = REPO_ROOT / "tests" / "fixtures" / "aclstm_mdn_reference.json"


def load_dance_model(checkpoint: Path) -> tuple[DanceLSTM, dict, dict]:
    state = torch.load(checkpoint, weights_only=False)
    meta = state["meta"]
    model = DanceLSTM(meta["dim"], len(meta["styles"]), meta["hidden"], meta["layers"], meta.get("head", "mean"),
                       meta.get("components", 10))
    model.load_state_dict(state["model"])
    return model.eval(), meta, state


def export_onnx(model: DanceLSTM, path: Path, weights: str = "float32", hessians: dict | None = None) -> DanceLSTM:
    """Writes the step graph with its large weights stored as `weights` (int4: rounded by `hessians`, the input
    moments of calibration.input_moments, when given); returns the network the file computes (the weights as
    stored), the reference for the parity check."""
    onnx.save(compact_weights(dance_graph(model), weights, hessians=hessians), str(path))
    return dance_model_from_onnx(path, model.dim, model.styles, model.hidden, model.layers)


def pick_seeds(clips: list[DanceClip], styles: tuple[str, ...] | list[str] = STYLES) -> list[dict]:
    """SEEDS_PER_STYLE windows of SEED_FRAMES real feature frames per style, spread over the held-out clips."""
    seeds = []
    for style in styles:
        held = [c for c in clips if c.style == style and c.held_out]
        for k in range(SEEDS_PER_STYLE):
            c = held[k % len(held)]
            secs = c.seconds + c.lead_in_s  # in the file's time, as the seeds' names and start_seconds say
            start = (k // len(held) + 1) / (SEEDS_PER_STYLE // len(held) + 2) * secs
            pos = resample_positions(c.positions, c.fps, start - c.lead_in_s, SEED_FRAMES + 1)
            pos[..., [0, 2]] -= pos[-1:, :1, [0, 2]]  # the seed ends with the root over the origin
            seeds.append({"style": style, "name": f"{style} {Path(c.file).name.split('.')[0]} @{start:.1f}s",
                          "file": c.file, "start_seconds": round(start, 2),
                          "frames": [[round(float(v), 5) for v in f] for f in encode(pos)]})
    return seeds


FIXTURE_STEPS = 24


def write_reference_fixture(onnx_path: Path, info: dict) -> None:
    """ONNX calls at batch 2 for onnxruntime-web parity, one step and FIXTURE_STEPS steps from the same inputs, and a
    decoded seed (TypeScript decoder parity)."""
    session = cpu_session(onnx_path)
    mean, std = np.array(info["normalisation"]["mean"]), np.array(info["normalisation"]["std"])
    seeds = [info["seeds"][0], info["seeds"][-1]]
    x = np.array([(np.array(s["frames"][-1]) - mean) / std for s in seeds], np.float32)
    style = np.eye(len(STYLES), dtype=np.float32)[[STYLES.index(s["style"]) for s in seeds]]
    rng = np.random.default_rng(3)
    shape = (info["onnx"]["layers"], 2, info["onnx"]["hidden"])
    h, c = (rng.normal(scale=0.3, size=shape).astype(np.float32) for _ in range(2))
    inputs = {"x": x.ravel().tolist(), "style": style.ravel().tolist(), "h": h.ravel().tolist(), "c": c.ravel().tolist(), "batch": 2}
    gauss = "noise" in info["onnx"]["inputs"]
    noise = rng.normal(size=(FIXTURE_STEPS, 2, x.shape[1])).astype(np.float32)
    temperature = np.array([info.get("temperature", 1.0)], np.float32)

    def case(steps: int) -> dict:
        drawn = {"noise": noise[:steps], "temperature": temperature} if gauss else {}
        outs = session.run(OUTPUTS, {"x": x, "style": style, "h": h, "c": c, "steps": np.array([steps], np.int64), **drawn})
        listed = {"noise": noise[:steps].ravel().tolist(), "temperature": float(temperature[0])} if gauss else {}
        return {"inputs": {**inputs, "steps": steps, **listed}, "outputs": {n: np.asarray(o).ravel().tolist() for n, o in zip(OUTPUTS, outs)}}

    feats = np.array(seeds[0]["frames"])
    decoded = {"features": feats.ravel().tolist(), "frames": len(feats), "positions": decode(feats).ravel().tolist()}
    FIXTURE.write_text(json.dumps({"model": info["file"], "step": case(1), "steps": case(FIXTURE_STEPS), "decode": decoded}) + "\n")
    print(f"wrote {FIXTURE}")


def training_history(checkpoint: Path, iteration: int | None) -> dict:
    """The run's last history entry up to `iteration` (its minutes and validation), from its latest checkpoint."""
    latest = checkpoint.parent / "checkpoint.pt"
    if not latest.exists() or iteration is None:
        return {}
    upto = [h for h in torch.load(latest, weights_only=False).get("history", []) if h["iteration"] <= iteration]
    return upto[-1] if upto else {}


def training_minutes(checkpoint: Path, iteration: int | None) -> float | None:
    """Training time (minutes) up to `iteration`, from the run's latest checkpoint history."""
    minutes = training_history(checkpoint, iteration).get("minutes")
    return None if minutes is None else round(minutes, 1)


def write_dance_graph(model: DanceLSTM, onnx_path: Path, weights: str, calibration: dict | None = None) -> tuple[dict, dict]:
    """Writes and parity-checks the graph; returns the JSON's `onnx` and `parity` fields. int4 weights are rounded
    to keep the layers' outputs on the training clips: `calibration` holds calibration.input_moments' clips, mean,
    std and styles."""
    hessians = None
    if weights == "int4":
        if calibration is None:
            raise SystemExit("error: int4 weights need the training clips to round by (calibration.input_moments)")
        try:
            hessians = input_moments(model, **calibration)
        except ValueError as e:
            raise SystemExit(f"error: int4 weights: {e}")
    stored = export_onnx(model, onnx_path, weights, hessians)
    parity = {**check_parity(stored, onnx_path), "reference": f"torch with the weights as stored ({weights})"}
    print(f"parity ok: max |torch - onnxruntime| = {parity['max_abs_diff']:.2e}")
    fields = {"inputs": graph_inputs(model), "outputs": graph_outputs(model), "opset": 17, "layers": model.layers, "hidden": model.hidden,
              "dim": model.dim, "styles": model.styles, "head": model.head, "weights": weight_format(onnx.load(str(onnx_path))),
              **({"weights_rounding": "GPTQ on the inputs of the training clips, teacher-forced and free-running "
                                      "(training/aclstm/calibration.py)"} if hessians else {}),
              "style_input": "one-hot over `styles`; x and ys are normalised features",
              "steps_input": "int64 (1,): steps run in the call, each output frame fed back as the next input; "
                             "ys is (steps, batch, dim)"}
    if model.head == "gauss":
        fields["noise_input"] = ("float32 (>= steps, batch, dim) standard normals, one row per step: each frame is "
                                 "mu + temperature * sigma * noise[step], the network's Gaussian draw")
        fields["temperature_input"] = "float32 (1,): scales sigma (0: the mean)"
    if model.head == "mdn":
        fields["components"] = model.components
        fields["sampler_inputs"] = (
            "held, age (batch,) int64: the held component (-1: none yet) and the frames it has been held; wander "
            "(batch, dim): the AR(1) normals; temperature, rho, threshold (batch,) float32 and max_hold, min_hold "
            "(batch,) int64: each row's phrase parameters; uniforms (>= steps, batch) in [0, 1), one per step for a "
            "component draw by inverse CDF; normals (>= steps, batch, dim): the AR(1) innovations "
            "(training/aclstm/phrase_sampling.py)")
        fields["filter_inputs"] = ("filt (batch, 4, dim): x[t-1], x[t-2], y[t-1], y[t-2] of the output filter; filter_b "
                                   "(batch, 3), filter_a (batch, 2): b0, b1, b2 and a1, a2 (training/aclstm/jitter_filter.py)")
        fields["outputs_note"] = ("ys: the drawn frames, fed back; display: ys through the causal low-pass, what is shown; "
                                  "the sampler's and the filter's states after the call; weights (steps, batch, K)")
    return fields, parity


def _publish(info: dict, onnx_path: Path, model_id: str, out: Path) -> None:
    """The JSON beside the graph; into MODELS_DIR also the manifest entry and, for the auto-conditioned model, the
    browser fixture."""
    info["bytes"] = onnx_path.stat().st_size
    (out / f"{model_id}.json").write_text(json.dumps(info) + "\n")
    if info.get("head") == "mdn":  # the mdn fixture beside a development export, into tests/fixtures when shipped
        write_mdn_reference_fixture(onnx_path, info, MDN_FIXTURE if out == MODELS_DIR else out / MDN_FIXTURE.name)
    elif info["training_scheme"] == "auto-conditioned" and out == MODELS_DIR:
        write_reference_fixture(onnx_path, info)
    if out == MODELS_DIR:
        register_model({"id": model_id, "kind": "aclstm", "skeleton": "aclstm-standard", "fps": info["fps"],
                        "styles": info["styles"], "bytes": info["bytes"], "file": info["file"]}, "aclstm-dance")


def export_dance_model(checkpoint: Path, model_id: str, out: Path, mocap: str | None, weights: str = "int8",
                       temperature: float = 0.2, tune_frames: int = 1200) -> Path:
    """Writes out/<model_id>.onnx (parity checked) and out/<model_id>.json (see _publish). Returns the ONNX path.
    `temperature`: a Gaussian head's sampling temperature, kept in the JSON for the page and the evaluation. An mdn
    head's JSON gets `head`, `components` and `sampling` (mdn_sampling: the output filter per style from the training
    clips, the phrase parameters per style tuned on held-out windows over `tune_frames` frames)."""
    model, meta, state = load_dance_model(checkpoint)
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{model_id}.onnx"
    _, clips = load_clips(mocap)
    onnx_fields, parity = write_dance_graph(model, onnx_path, weights,
                                            {"clips": clips, "mean": meta["mean"], "std": meta["std"], "styles": meta["styles"]})
    vanilla = meta["args"]["condition"] == 0
    info = {
        "id": model_id, "kind": "aclstm", "fps": meta["fps"], "file": onnx_path.name,
        "description": ("Vanilla 3-layer LSTM trained with teacher forcing only (the acLSTM paper's baseline)" if vanilla else
                        "Auto-conditioned LSTM (Zhou et al.), u = v = 5")
                       + (f", Gaussian output head drawn at temperature {temperature:g} and fed back" if model.head == "gauss" else "")
                       + (f", mixture-density head (K = {model.components}) drawn by phrase-scale sampling and fed back, "
                          "shown through a causal low-pass" if model.head == "mdn" else "")
                       + ", one model for salsa, Indian and martial-arts dance.",
        "training_scheme": "teacher-forced" if vanilla else "auto-conditioned",
        **({"temperature": temperature} if model.head == "gauss" else {}),
        **({"head": "mdn", "components": model.components, "sampling": mdn_sampling(checkpoint, clips, mocap, tune_frames)}
           if model.head == "mdn" else {}),
        "styles": meta["styles"],
        "skeleton": meta["skeleton"],
        "features": {"dim": meta["dim"], "seed_frames": SEED_FRAMES,
                     "layout": "x = [root dx (m/frame), root height y (m), root dz (m/frame), then for each skeleton point "
                               "after the root: its position minus the root's (m, world axes)]; y up, " f"{meta['fps']:g} fps"},
        "onnx": onnx_fields,
        "normalisation": {"mean": [round(float(v), 7) for v in meta["mean"]], "std": [round(float(v), 7) for v in meta["std"]]},
        "real_pose_change": real_pose_change(clips),
        "seeds": pick_seeds(clips),
        "training": {"iterations": state.get("iteration"), "minutes": training_minutes(checkpoint, state.get("iteration")),
                     # last.pt keeps no validation: the last one measured before it (up to 250 iterations earlier)
                     "valid": state.get("valid") or training_history(checkpoint, state.get("iteration")).get("valid"),
                     "valid_files": meta["valid_files"], "args": meta["args"]},
        "parity": parity,
    }
    _publish(info, onnx_path, model_id, out)
    return onnx_path


def rewrite_dance_model(source: Path, model_id: str, out: Path, weights: str, mocap: str | None = None) -> Path:
    """The exported model `source`/<model_id>.{json,onnx} written again with this graph and weight format, without
    its checkpoint: the network is read back from the ONNX file, everything else of the JSON is kept. (int4 reads
    the training clips, from `mocap`, to round by.)"""
    info = json.loads((source / f"{model_id}.json").read_text())
    o = info["onnx"]
    model = dance_model_from_onnx(source / info["file"], o["dim"], o["styles"], o["hidden"], o["layers"])
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{model_id}.onnx"
    calibration = None
    if weights == "int4":
        calibration = {"clips": load_clips(mocap)[1], "mean": info["normalisation"]["mean"],
                       "std": info["normalisation"]["std"], "styles": info["styles"]}
    info["onnx"], info["parity"] = write_dance_graph(model, onnx_path, weights, calibration)
    info["file"] = onnx_path.name
    _publish(info, onnx_path, model_id, out)
    return onnx_path


# The output filter's cutoffs tried per style at export: where this share of the style's training clips' velocity
# power lies below (jitter_filter.choose_cutoff). Each style takes the share whose best phrase setting scores best on
# the tuning windows (pilots.tuning_score: all passing within the jitter budget first); 0.99 alone until 2026-12-05.
CUTOFF_SHARES = (0.99, 0.98, 0.97, 0.95)


def mdn_sampling(checkpoint: Path, clips: list[DanceClip], mocap: str | None, tune_frames: int = 1200,
                 shares: tuple[float, ...] = CUTOFF_SHARES) -> dict:
    """The JSON's `sampling` block of an mdn model: per style, the output filter (jitter_filter.style_filters: the
    cutoff below which a share of the style's training clips' velocity power lies, the share one of `shares`) and the
    phrase parameters, chosen together by pilots.tune_phrase_filtered (one set of rollouts) on held-out tuning windows (never the judged seeds) from
    tuning_grid with the AR(1) coefficients EXPORT_RHOS, the rollouts judged through the filter as the page shows them."""
    from .jitter_filter import coefficients, style_filters
    from .pilots import EXPORT_RHOS, EXPORT_TEMPERATURES, EXPORT_THRESHOLDS, tune_phrase_filtered, tuning_grid, tuning_row_text

    filters_by_share = [style_filters(clips, share=share) for share in shares]
    tunings = tune_phrase_filtered(checkpoint, tuning_grid(rhos=EXPORT_RHOS, thresholds=EXPORT_THRESHOLDS, temperatures=EXPORT_TEMPERATURES),
                                   [{s: coefficients(f) for s, f in filters.items()} for filters in filters_by_share],
                                   tune_frames, mocap=mocap)
    chosen = {}  # style -> (share, filter, tuned style block)
    for share, filters, tuned in zip(shares, filters_by_share, tunings):
        for style, v in tuned["styles"].items():
            if style not in chosen or tuple(v["table"][0]["score"]) < tuple(chosen[style][2]["table"][0]["score"]):
                chosen[style] = (share, filters[style], v)
    for style, (share, f, v) in chosen.items():
        row = v["table"][0]
        print(f"{style}: filter {f['cutoff_hz']:.2f} Hz ({share:.0%} of the power), phrase {v['best']} (tuning: {tuning_row_text(row)})")
    return {"rule": "phrase", "params": {s: v["best"] for s, (_, _, v) in chosen.items()},
            "filter": {s: {**f, "power_share": share} for s, (share, f, _) in chosen.items()},
            "tuning": {"frames": tuned["frames"], "seeds_per_style": tuned["seeds_per_style"], "fractions": list(tuned["fractions"]),
                       "power_shares": list(shares),
                       "chosen": {s: {k: v["table"][0][k] for k in ("passes", "runs", "diverged", "median_ratio", "jitter_vs_real",
                                                                   "jitter_raw_vs_real", "raised_foot_share", "raised_foot_real",
                                                                   "limb_worst_second")}
                                  for s, (_, _, v) in chosen.items()}},
            "notes": ("params: training/aclstm/phrase_sampling.py's rule per style; filter: a causal 2nd-order Butterworth "
                      "(b, a with a[0] = 1) per channel on the drawn frames, shown but never fed back "
                      "(training/aclstm/jitter_filter.py), its cutoff chosen per style with the params")}


MDN_FIXTURE_STEPS = 40


def mdn_case_feeds(info: dict, rows: list[dict], steps: int, rng: np.random.Generator) -> dict:
    """The mdn graph's feeds for a fixture case: each row {seed, held, age} starts from its seed's last frame with
    its style's phrase parameters and filter (at rest on that frame), h and c random; randoms rounded to 7 digits
    (so the fixture's numbers are the exact inputs)."""
    o, sampling = info["onnx"], info["sampling"]
    mean, std = np.array(info["normalisation"]["mean"]), np.array(info["normalisation"]["std"])
    q = lambda a, dtype=np.float32: np.array([float(f"{v:.7g}") for v in np.ravel(a)]).reshape(np.shape(a)).astype(dtype)
    b = len(rows)
    x = q([(np.array(r["seed"]["frames"][-1]) - mean) / std for r in rows])
    params = [sampling["params"][r["seed"]["style"]] for r in rows]
    filters = [sampling["filter"][r["seed"]["style"]] for r in rows]
    return {
        "x": x, "style": np.eye(len(info["styles"]), dtype=np.float32)[[info["styles"].index(r["seed"]["style"]) for r in rows]],
        "h": q(rng.normal(scale=0.3, size=(o["layers"], b, o["hidden"]))), "c": q(rng.normal(scale=0.3, size=(o["layers"], b, o["hidden"]))),
        "steps": np.array([steps], np.int64),
        "held": np.array([r["held"] for r in rows], np.int64), "age": np.array([r["age"] for r in rows], np.int64),
        "wander": q(rng.normal(size=(b, o["dim"]))),
        "temperature": q([p["temperature"] for p in params]), "rho": q([p["rho"] for p in params]),
        "threshold": q([p["threshold"] for p in params]),
        "max_hold": np.array([p["max_hold"] for p in params], np.int64), "min_hold": np.array([p["min_hold"] for p in params], np.int64),
        "uniforms": q(rng.random((steps, b))), "normals": q(rng.normal(size=(steps, b, o["dim"]))),
        "filt": np.repeat(x[:, None], 4, axis=1),
        "filter_b": q([f["b"] for f in filters]), "filter_a": q([f["a"][1:] for f in filters]),
    }


def write_mdn_reference_fixture(onnx_path: Path, info: dict, path: Path) -> None:
    """The mdn graph's parity fixture for the page: onnxruntime's outputs (every one of MDN_OUTPUTS, display and the
    sampler's and filter's states included) for MDN_FIXTURE_STEPS steps at batch 1 (a row holding a component 10
    frames short of its longest hold) and batch 2 (a fresh row, and a row 5 frames short of its longest hold), so a
    component is redrawn inside every call; checked against torch (graph.mdn_torch_steps); inputs and outputs
    flattened row-major, shapes beside them."""
    session = cpu_session(onnx_path)
    o = info["onnx"]
    model = dance_model_from_onnx(onnx_path, o["dim"], o["styles"], o["hidden"], o["layers"])
    rng = np.random.default_rng(5)
    by_style = {s: [x for x in info["seeds"] if x["style"] == s] for s in info["styles"]}
    first, second = info["styles"][0], info["styles"][-1]
    hold = lambda style, before: max(0, info["sampling"]["params"][style]["max_hold"] - before)
    cases = {"batch1": [{"seed": by_style[first][0], "held": 1, "age": hold(first, 10)}],
             "batch2": [{"seed": by_style[first][1], "held": -1, "age": 0},
                        {"seed": by_style[second][0], "held": 0, "age": hold(second, 5)}]}
    out = {"model": info["file"], "outputs_order": MDN_OUTPUTS, "cases": {}}
    for name, rows in cases.items():
        feeds = mdn_case_feeds(info, rows, MDN_FIXTURE_STEPS, rng)
        got = dict(zip(MDN_OUTPUTS, session.run(MDN_OUTPUTS, feeds)))
        ref = mdn_torch_steps(model, feeds)
        worst = max(float(np.abs(ref[n].astype(np.float64) - got[n]).max()) for n in MDN_OUTPUTS)
        redraws = (ref["redraws"] - (feeds["held"] < 0)).tolist()
        if worst > 1e-4 or redraws[-1] < 1:
            raise SystemExit(f"error: mdn fixture case {name}: torch - onnxruntime {worst:.2e}, redraws {redraws}")
        flat = lambda a: np.asarray(a).ravel().tolist()
        out["cases"][name] = {
            "batch": len(rows), "steps": MDN_FIXTURE_STEPS, "seeds": [r["seed"]["name"] for r in rows],
            "inputs": {k: flat(v) for k, v in feeds.items()}, "input_shapes": {k: list(np.shape(v)) for k, v in feeds.items()},
            "outputs": {k: [float(f"{x:.7g}") for x in flat(v)] if v.dtype.kind == "f" else flat(v) for k, v in got.items()},
            "output_shapes": {k: list(v.shape) for k, v in got.items()},
            "redraws_after_the_first": redraws, "torch_max_abs_diff": worst}
    path.write_text(json.dumps(out) + "\n")
    print(f"wrote {path} (torch against onnxruntime: " + ", ".join(f"{n} {c['torch_max_abs_diff']:.1e}" for n, c in out["cases"].items()) + ")")
