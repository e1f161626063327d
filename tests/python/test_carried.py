"""Files that travel to and from a lent GPU (training/device/carried.py): the dance cache's positions come back within
5 µm with everything else exact, and a packed checkpoint comes back in parts under the size limit, loadable by the
export, with its weights as close as its format allows."""
from pathlib import Path

import numpy as np
import pytest
import torch

from training.device.carried import PART_BYTES, pack_checkpoint, pack_positions, unpack_checkpoint, unpack_positions
from training.aclstm.exporting import load_dance_model
from training.models.aclstm import DanceLSTM


def test_positions_round_trip_within_5_micrometres(tmp_path: Path):
    rng = np.random.default_rng(0)
    # Two clips whose positions wander (metres); the second starts far from where the first ends.
    positions = np.concatenate([np.cumsum(rng.normal(scale=0.01, size=(50, 4, 3)), axis=0),
                                5 + np.cumsum(rng.normal(scale=0.01, size=(30, 4, 3)), axis=0)]).astype(np.float32)
    cache = tmp_path / "cache.npz"
    np.savez(cache, positions=positions, start=[0, 50], frames=[50, 30], style=["salsa", "indian"], names=list("abcd"))
    pack_positions(cache, tmp_path / "packed.xz")
    unpack_positions(tmp_path / "packed.xz", tmp_path / "back.npz")
    back = np.load(tmp_path / "back.npz")
    # Half the 10 µm unit, plus the float32 rounding of the position it comes back as.
    assert np.abs(back["positions"] - positions).max() <= 5e-6 + float(np.spacing(np.abs(positions).max()))
    assert list(back["style"]) == ["salsa", "indian"] and list(back["frames"]) == [50, 30] and list(back["names"]) == list("abcd")


def _checkpoint(tmp_path: Path, hidden: int) -> tuple[Path, DanceLSTM]:
    torch.manual_seed(0)
    model = DanceLSTM(12, 3, hidden, 2, "mdn", 4)
    meta = {"dim": 12, "styles": ["salsa", "indian", "martial"], "hidden": hidden, "layers": 2, "head": "mdn", "components": 4}
    run = tmp_path / "run"
    run.mkdir()
    torch.save({"model": model.state_dict(), "iteration": 7, "meta": meta}, run / "last.pt")
    torch.save({"history": [{"iteration": 7, "minutes": 1.5}], "meta": meta}, run / "checkpoint.pt")
    return run / "last.pt", model


def test_checkpoint_round_trip_float16_and_int8(tmp_path: Path):
    last, model = _checkpoint(tmp_path, 32)
    for int8, tolerance in ((False, 1e-3), (True, 0.5 / 127 + 1e-6)):
        parts = pack_checkpoint(last, tmp_path / f"out{int8}" / "r-last", int8, last.parent / "checkpoint.pt")
        back = unpack_checkpoint(parts[0].parent / "r-last", tmp_path / f"back{int8}", "last.pt")
        loaded, meta, state = load_dance_model(back)
        assert state["iteration"] == 7 and meta["hidden"] == 32
        for name, w in model.state_dict().items():
            # float16: relative rounding; int8: half a step of each row's scale (its largest value / 127)
            bound = tolerance * (w.abs().amax(dim=1, keepdim=True) if int8 and w.dim() == 2 else w.abs().max())
            assert (loaded.state_dict()[name] - w).abs().le(bound + 1e-7).all(), (int8, name)
        assert torch.load(back.parent / "checkpoint.pt", weights_only=False)["history"][0]["minutes"] == 1.5


def test_checkpoint_larger_than_a_part_is_split_and_joined_in_order(tmp_path: Path, monkeypatch):
    import training.device.carried as carried
    last, model = _checkpoint(tmp_path, 32)
    # First a pack in more parts, then one in fewer (but more than ten) into the same place: the earlier pack's
    # last parts must not be joined in, and part10 comes after part9 (not after part1).
    monkeypatch.setattr(carried, "PART_BYTES", 1_000)
    carried.pack_checkpoint(last, tmp_path / "out" / "r-last")
    monkeypatch.setattr(carried, "PART_BYTES", 2_000)
    parts = carried.pack_checkpoint(last, tmp_path / "out" / "r-last")
    assert len(parts) > 10 and all(p.stat().st_size <= 2_000 for p in parts)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in parts)
    loaded, _, _ = load_dance_model(carried.unpack_checkpoint(tmp_path / "out" / "r-last", tmp_path / "back", "last.pt"))
    assert torch.allclose(loaded.decoder.weight, model.decoder.weight, atol=1e-3)
    assert PART_BYTES < 16 * 2 ** 20  # what comes back from the device: files of at most 16 MiB


def test_an_unpacked_run_is_refused_by_resume_with_a_message(tmp_path: Path, monkeypatch):
    import training.runs as runs
    last, _ = _checkpoint(tmp_path, 8)
    carried_parts = pack_checkpoint(last, tmp_path / "out" / "r-last", history_from=last.parent / "checkpoint.pt")
    monkeypatch.setattr(runs, "RUNS_DIR", tmp_path / "runs")
    unpack_checkpoint(carried_parts[0].parent / "r-last", tmp_path / "runs" / "r", "last.pt")
    run = runs.Run("r")
    model = DanceLSTM(12, 3, 8, 2, "mdn", 4)
    with pytest.raises(SystemExit, match="lacks model.*not resumable"):
        run.resume(np.random.default_rng(0), model=model)
