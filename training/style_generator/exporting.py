"""Exporting a style-generator checkpoint (issue 39): the ONNX step with its style input (graph.py), the JSON with the
generator's fields plus its styles, licence and data, seed states per style, and a reference step for the page's parity
test. Exported into public/models (MODELS_DIR) it also gets its manifest entry, with the data and licence of
training/onnx/manifest.py's "cmu-and-bandai" (non-commercial), as every exporter registers its model there; exported
anywhere else, nothing else is written."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import onnx
import torch

from .. import metrics
from ..data.bandai import CONTENTS
from ..data.features import FIXED_JOINTS, FeatureCodec, feature_names
from ..data.locomotion import is_validation
from ..data.style_locomotion import CMU_STYLE, StyledClip
from ..generator.exporting import estimate_initial_state, pick_seeds, sampling_info
from ..mocap.rotations import matrix_to_quat
from ..mocap.skeleton import canonical_skeleton
from ..models.generator import MixtureLSTM, StyledGenerator
from ..onnx.compact import weight_format
from ..onnx.graph import OPSET
from ..onnx.manifest import register_model
from ..onnx.sessions import cpu_session
from ..paths import MODELS_DIR
from .graph import INPUTS, OUTPUTS, check_style_parity, export_style_onnx, model_from_style_onnx

LICENCE = "CC BY-NC 4.0 (non-commercial): trained on the Bandai Namco Research Motiondataset and CMU"
DATA = ("CMU motion capture (mocap.cs.cmu.edu): walking and running, as style 'cmu'; the Bandai Namco Research "
        "Motiondataset: walks, walking turns and runs performed in 7 styles")
STYLE_INPUT = ("style: float32 (batch, styles), weights over `styles` in this order; a one-hot picks a style. The step "
               "computes the style's embedding as style @ E (E: one learned row of style_dim values per style) and "
               "concatenates it to x before fc1, so a convex combination of one-hots (weights >= 0 summing to 1) blends "
               "the styles' embeddings: the page blends from one style to the next over about a second when the style "
               "is switched.")
SEED_FRAMES = 6


def _rounded(values) -> list[float]:
    return [round(float(v), 6) for v in np.asarray(values).reshape(-1)]


def style_seed_frames(clips: list[StyledClip], styles: list[str], valid_files: set[str], codec: FeatureCodec,
                      mean: np.ndarray, std: np.ndarray) -> list[dict]:
    """Real frames to estimate each style's seed states from, all from held-out clips: for CMU the generator's rule
    (generator/exporting.py pick_seeds: 6 walks of a spread of speeds, 2 runs), for a Bandai style the middle held-out
    clip by name of each content (walk, turn left, turn right, run). Names start with the gait (walk, run), as the
    page's gait seeds need."""
    out = []
    for style in styles:
        held = [c for c in clips if c.style == style and c.clip.file in valid_files]
        if not held:
            raise ValueError(f"no held-out clips of style {style!r}")
        if style == CMU_STYLE:
            for s in pick_seeds([c.clip for c in held], codec, mean, std):
                out.append({**s, "name": f"{s['category']} {style} {s['name'].split(' ', 1)[1]}", "style": style})
            continue
        for content in CONTENTS:
            pool = sorted((c for c in held if c.content == content and c.clip.frames > 12), key=lambda c: c.clip.file)
            if not pool:
                continue
            c = pool[len(pool) // 2]
            x = codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts)
            start = len(x) // 3
            category = "run" if content == "run" else "walk"
            stem = c.clip.file.split("/")[-1].split(".")[0]
            out.append({"name": f"{category} {style} {content} {stem}", "file": c.clip.file, "category": category,
                        "style": style, "frames": ((x[start:start + SEED_FRAMES] - mean) / std).astype(np.float32)})
    return out


def estimated_style_seeds(model: MixtureLSTM, frames: list[dict], styles: list[str]) -> list[dict]:
    """The JSON's seeds: each seed's first frame and the (h, c) eq. 26 estimates for it under its own style."""
    seeds = []
    for s in frames:
        h, c, zero_nll, est_nll = estimate_initial_state(StyledGenerator(model, styles.index(s["style"])),
                                                         torch.from_numpy(s["frames"]))
        seeds.append({"name": s["name"], "file": s["file"], "category": s["category"], "style": s["style"],
                      "x": _rounded(s["frames"][0]), "h": _rounded(h), "c": _rounded(c),
                      "nll_zero_state": round(zero_nll, 3), "nll_estimated_state": round(est_nll, 3)})
        print(f"seed {s['name']}: NLL of the next frames {zero_nll:.1f} from a zero state, {est_nll:.1f} estimated")
    return seeds


def write_style_graph(model: MixtureLSTM, onnx_path: Path, weights: str) -> dict:
    """The step graph with its weights stored as `weights`, checked against torch holding the weights as stored (read
    back from the file), one-hot and blended; returns the JSON's parity field."""
    export_style_onnx(model, onnx_path, weights)
    stored = model_from_style_onnx(onnx_path, model.dim, model.hidden, model.mixtures, model.styles, model.style_dim)
    parity = {**check_style_parity(stored, onnx_path), "reference": f"torch with the weights as stored ({weights})"}
    print(f"parity ok: max |torch - onnxruntime| = {parity['max_abs_diff']:.2e} (one-hot {parity['one_hot']:.2e}, "
          f"blended {parity['blended']:.2e})")
    return parity


def style_info(model_id: str, model: MixtureLSTM, meta: dict, state: dict, onnx_path: Path, seeds: list[dict],
               parity: dict) -> dict:
    """The JSON: generator.json's fields (training/generator/exporting.py) plus styles, the style input, licence, data."""
    skel = canonical_skeleton()
    codec = FeatureCodec(skel, np.array(meta["references"]))
    styles = list(meta["styles"])
    return {
        "id": model_id, "kind": "lstm-gmm", "fps": meta["fps"], "file": onnx_path.name, "bytes": onnx_path.stat().st_size,
        "description": "Contact-aware LSTM with a 5-component Gaussian mixture over the next frame (Wang, Chai, Xia §4.1) "
                       "with a style input (one learned embedding per style), trained on CMU walking and running and the "
                       "Bandai Namco set's 7 styles.",
        "styles": styles,
        "licence": LICENCE,
        "data": DATA,
        "skeleton": skel.to_json(),
        "onnx": {"inputs": INPUTS, "outputs": OUTPUTS, "opset": OPSET, "layers": 2, "hidden": meta["hidden"],
                 "graph": "gate-level LSTM layers (Gemm + gate maths, no LSTM op), fc3 as three Gemms; "
                          "fc1 reads Concat(x, MatMul(style, style.weight))",
                 "mixtures": meta["mixtures"], "dim": meta["dim"], "styles": len(styles), "style_dim": meta["style_dim"],
                 "style_input": STYLE_INPUT},
        "features": {
            "names": feature_names(skel), "joints": codec.joints, "fixed_joints": [skel.index(n) for n in FIXED_JOINTS],
            "layout": "as generator.json's: x = [dtx, dtz, dry, ty, root tilt rotvec(3), joint rotvecs, contact L, contact R]",
            "references": [[round(float(v), 7) for v in q] for q in matrix_to_quat(codec.references)],
        },
        "normalisation": {"mean": [round(float(v), 7) for v in meta["mean"]],
                          "std": [round(float(v), 7) for v in meta["std"]]},
        "seeds": seeds,
        "seeds_rule": "per style, from held-out clips: cmu as the generator's seeds (6 walks, 2 runs), each Bandai style "
                      "the middle held-out clip of each content; each seed's `style` names the style its (h, c) was "
                      "estimated under (eq. 26)",
        "sampling": sampling_info(),
        "training": {"epochs": state.get("epoch"), "valid_nll_per_frame": state.get("valid_nll"),
                     "valid_nll_measure": "mean NLL per frame over each style's held-out clips, normalised units",
                     "valid_files": meta["valid_files"], "train_frames": meta["train_frames"],
                     "train_frames_per_style": meta.get("train_frames_per_style"), "args": meta["args"]},
        "parity": parity,
        "weights": weight_format(onnx.load(str(onnx_path))),
    }


def reference_step(onnx_path: Path, info: dict) -> dict:
    """One onnxruntime step at batch 3 for the page's parity test: rows from the first seed, the last seed and the
    first seed again, with the style one-hot of the first seed's style, one-hot of the last seed's, and a blend
    (0.25 first style, 0.75 last style)."""
    styles = info["styles"]
    seeds = [info["seeds"][0], info["seeds"][-1], info["seeds"][0]]
    B, S, H = len(seeds), len(styles), info["onnx"]["hidden"]
    x = np.array([s["x"] for s in seeds], np.float32)
    h = np.stack([np.array(s["h"], np.float32).reshape(2, H) for s in seeds], axis=1)
    c = np.stack([np.array(s["c"], np.float32).reshape(2, H) for s in seeds], axis=1)
    style = np.zeros((B, S), np.float32)
    first, last = styles.index(seeds[0]["style"]), styles.index(seeds[1]["style"])
    style[0, first] = style[1, last] = 1.0
    style[2, first], style[2, last] = 0.25, 0.75
    outs = cpu_session(onnx_path).run(OUTPUTS, {"x": x, "h": h, "c": c, "style": style})
    return {"model": info["file"], "seeds": [0, len(info["seeds"]) - 1, 0],
            "inputs": {"batch": B, "x": x.ravel().tolist(), "h": h.ravel().tolist(), "c": c.ravel().tolist(),
                       "style": style.ravel().tolist()},
            "outputs": {name: np.asarray(o).ravel().tolist() for name, o in zip(OUTPUTS, outs)}}


def held_out_sliding(clips: list[StyledClip], styles: list[str], codec: FeatureCodec) -> dict[str, float]:
    """Per style, the foot sliding of its real held-out clips (m/s): the speed of the lowest foot point within 4 cm of
    the floor (metrics.low_foot_sliding_clips), each clip measured on its own: the page's readout reference."""
    skel = canonical_skeleton()
    out = {}
    for style in styles:
        positions = [codec.positions(codec.encode(c.clip.root, c.clip.rotations, c.clip.contacts))
                     for c in clips if c.style == style and is_validation(c.clip)]
        out[style] = round(metrics.low_foot_sliding_clips(positions, 30.0, skel), 4)
    return out


def export_style_generator(model: MixtureLSTM, meta: dict, state: dict, clips: list[StyledClip], out: Path,
                           model_id: str = "style-generator", weights: str = "int8") -> tuple[Path, dict]:
    """Writes out/<id>.onnx and out/<id>.json, and into MODELS_DIR the manifest entry; returns the ONNX path and the JSON."""
    out.mkdir(parents=True, exist_ok=True)
    onnx_path = out / f"{model_id}.onnx"
    parity = write_style_graph(model, onnx_path, weights)
    codec = FeatureCodec(canonical_skeleton(), np.array(meta["references"]))
    styles = list(meta["styles"])
    frames = style_seed_frames(clips, styles, set(meta["valid_files"]), codec, np.array(meta["mean"]), np.array(meta["std"]))
    info = style_info(model_id, model, meta, state, onnx_path, estimated_style_seeds(model, frames, styles), parity)
    info["held_out_sliding"] = held_out_sliding(clips, styles, codec)
    (out / f"{model_id}.json").write_text(json.dumps(info) + "\n")
    if out.resolve() == MODELS_DIR.resolve():  # shipping: the page lists it (non-commercial, labelled so in the pickers)
        register_model({"id": model_id, "kind": info["kind"], "skeleton": "cmu-canonical", "fps": info["fps"],
                        "styles": info["styles"], "bytes": info["bytes"], "file": info["file"]}, "cmu-and-bandai")
    return onnx_path, info
