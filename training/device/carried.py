"""Files made small enough to travel to and from a lent GPU machine, which gets the repository and at most 64 MiB
in all (no ../shared), and gives back at most 8 files of 16 MiB (python -m training.device.carry).

- The dance cache: each point's position rounded to 10 µm (at most 5 µm off, far below the millimetres a frame
  changes by), stored as frame-to-frame differences in integer units, compressed with xz: 62 MB of float32
  positions pack into 19 MB. Everything else in the cache travels as it is.
- A checkpoint's weights, for the way back: float16, or int8 with a scale per output row (the shipped ONNX files'
  own rounding, compact.quantise_int8, so an export of the unpacked weights stores the same numbers), in parts of
  at most PART_BYTES. The meta and validation history travel whole; the optimiser does not, so an unpacked run is
  for export and evaluation, not for --resume.
"""
from __future__ import annotations

import io
import lzma
from pathlib import Path

import numpy as np
import torch

from ..onnx.compact import quantise_int8

UNITS_PER_METRE = 100_000  # 10 µm
PART_BYTES = 15_000_000  # under the 16 MiB a file coming back may have


def pack_positions(cache: Path, out: Path) -> None:
    d = dict(np.load(cache))
    units = np.round(d.pop("positions").astype(np.float64) * UNITS_PER_METRE).astype(np.int64)
    deltas = units.copy()
    for start, frames in zip(d["start"], d["frames"]):  # differences within each clip, never across clips
        deltas[start + 1:start + frames] = units[start + 1:start + frames] - units[start:start + frames - 1]
    if np.abs(deltas).max() >= 2 ** 31:
        raise ValueError(f"{cache}: a position or step too large for 32-bit units")
    buffer = io.BytesIO()
    np.savez(buffer, deltas=deltas.astype(np.int32), **d)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(lzma.compress(buffer.getvalue()))


def unpack_positions(packed: Path, cache: Path) -> None:
    d = dict(np.load(io.BytesIO(lzma.decompress(packed.read_bytes()))))
    units = d.pop("deltas").astype(np.int64)
    for start, frames in zip(d["start"], d["frames"]):
        units[start:start + frames] = np.cumsum(units[start:start + frames], axis=0)
    cache.parent.mkdir(parents=True, exist_ok=True)
    np.savez(cache, positions=(units / UNITS_PER_METRE).astype(np.float32), **d)


def _packed_tensor(t: torch.Tensor, int8: bool) -> dict:
    t = t.detach().float().cpu()
    if int8 and t.dim() == 2:  # a scale per output row: the rows of PyTorch's (out, in) weights
        q, scale = quantise_int8(t.numpy(), axis=0)
        return {"int8": torch.from_numpy(q), "scale": torch.from_numpy(scale)}
    return {"float16": t.half()} if t.is_floating_point() else {"raw": t}


def _unpacked_tensor(p: dict) -> torch.Tensor:
    if "int8" in p:
        return p["int8"].float() * p["scale"]
    return p["float16"].float() if "float16" in p else p["raw"]


def _parts(stem: Path) -> list[Path]:
    """stem.part0, stem.part1 … in numeric order (part10 after part9)."""
    found = [(p, p.name[len(stem.name) + len(".part"):]) for p in stem.parent.glob(f"{stem.name}.part*")]
    return [p for p, k in sorted(((p, k) for p, k in found if k.isdigit()), key=lambda pk: int(pk[1]))]


def pack_checkpoint(checkpoint: Path, out_stem: Path, int8: bool = False, history_from: Path | None = None) -> list[Path]:
    """Writes out_stem.part0, .part1 … (each at most PART_BYTES); returns their paths. `history_from`: a checkpoint
    whose validation history to keep (the run's checkpoint.pt)."""
    state = torch.load(checkpoint, map_location="cpu", weights_only=False)
    history = torch.load(history_from, map_location="cpu", weights_only=False).get("history", []) if history_from else []
    buffer = io.BytesIO()
    torch.save({"model": {k: _packed_tensor(v, int8) for k, v in state["model"].items()}, "iteration": state.get("iteration"),
                "valid": state.get("valid"), "meta": state["meta"], "history": history}, buffer)
    data = buffer.getvalue()
    out_stem.parent.mkdir(parents=True, exist_ok=True)
    for stale in _parts(out_stem):  # an earlier pack's parts would be joined with these
        stale.unlink()
    parts = []
    for k, start in enumerate(range(0, len(data), PART_BYTES)):
        path = out_stem.with_name(f"{out_stem.name}.part{k}")
        path.write_bytes(data[start:start + PART_BYTES])
        parts.append(path)
    return parts


def unpack_checkpoint(stem: Path, run_dir: Path, name: str) -> Path:
    """Joins stem.part0, .part1 … into run_dir/name (the model, iteration, validation and meta, as training writes
    best.pt and last.pt) and, when the pack kept a history, run_dir/checkpoint.pt with it (the export reads training
    minutes there)."""
    parts = _parts(stem)
    if not parts:
        raise SystemExit(f"error: no {stem.name}.part0 in {stem.parent}")
    state = torch.load(io.BytesIO(b"".join(p.read_bytes() for p in parts)), weights_only=False)
    run_dir.mkdir(parents=True, exist_ok=True)
    out = run_dir / name
    torch.save({"model": {k: _unpacked_tensor(v) for k, v in state["model"].items()}, "iteration": state["iteration"],
                **({"valid": state["valid"]} if state.get("valid") else {}), "meta": state["meta"]}, out)
    if state["history"]:
        torch.save({"history": state["history"], "iteration": state["history"][-1]["iteration"], "meta": state["meta"],
                    "note": "unpacked from a lent GPU's run (training/device/carried.py): no optimiser, not resumable"},
                   run_dir / "checkpoint.pt")
    return out
