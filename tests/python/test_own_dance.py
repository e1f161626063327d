"""python -m training.own --kind dance: a folder of dance in, a dance model pack out (the acLSTM on the canonical
skeleton's points, one style). The test folder holds three acLSTM salsa files in a layout of its own (nested, one
unzipped); their headers say 120 fps where the set's readme says 60, so --source-fps 60 is given. The run is tiny: what
is checked is that the pack is complete and readable as the page reads it, not that the model dances well."""
import gzip
import json
import os
import re
import subprocess
import sys

import numpy as np
import onnxruntime
import pytest

from conftest import REPO
from training.data.dance import mirror_pairs
from training.mocap.humanoid import CANONICAL_JOINTS

SMALL = ["--hidden", "32", "--layers", "2", "--batch", "8", "--window", "40", "--iters-per-epoch", "15",
         "--iterations", "30", "--stability-frames", "600", "--source-fps", "60"]


def run_own(*args, env=None, timeout=150):
    return subprocess.run([sys.executable, "-m", "training.own", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout, env=env)


@pytest.fixture(scope="module")
def folder(tmp_path_factory, mocap):
    root = tmp_path_factory.mktemp("own-dance") / "Salsa Nights"
    (root / "night1" / "late").mkdir(parents=True)
    salsa = mocap / "aclstm" / "salsa"
    (root / "night1" / "take01.bvh.gz").write_bytes((salsa / "01.bvh.gz").read_bytes())
    (root / "night1" / "late" / "take02.bvh").write_bytes(gzip.decompress((salsa / "02.bvh.gz").read_bytes()))
    (root / "take03.bvh.gz").write_bytes((salsa / "03.bvh.gz").read_bytes())
    return root


@pytest.fixture(scope="module")
def pack(folder, tmp_path_factory):
    out = tmp_path_factory.mktemp("pack") / "my-salsa"
    run = tmp_path_factory.mktemp("run")
    done = run_own("--data", folder, "--kind", "dance", "--out", out, "--run", run, *SMALL, "--non-commercial",
                   "--licence", "CMU: free for research and commercial use (tested as if it were not)")
    assert done.returncode == 0, done.stderr[-3000:]
    return out, run, done


def test_a_dance_pack_is_written(pack):
    out, run, done = pack
    assert sorted(p.name for p in out.iterdir()) == ["card.md", "my-salsa.json", "my-salsa.onnx", "pose_change.png"]
    # --source-fps overrides the headers' 120 fps; every file of the nested layout is read.
    assert len(re.findall(r"^read \S+: [\d.]+ s at 60 fps", done.stdout, re.M)) == 3, done.stdout
    assert (run / "checkpoint.pt").exists() and (run / "best.pt").exists() and (run / "train.log").exists()


def test_the_json_holds_what_the_dance_page_checks(pack):
    """The fields web/runtime/aclstm/danceModel.ts parseDanceInfo requires, with their shapes, and one ONNX call."""
    out, _, _ = pack
    info = json.loads((out / "my-salsa.json").read_text())
    assert info["id"] == "my-salsa" and info["kind"] == "aclstm" and info["file"] == "my-salsa.onnx"
    assert info["styles"] == ["salsa-nights"]  # the data folder's name
    J = len(info["skeleton"]["joints"])
    assert info["skeleton"]["joints"] == CANONICAL_JOINTS and len(info["skeleton"]["offsets"]) == 3 * J
    o = info["onnx"]
    D = 3 * J
    assert o["inputs"] == ["x", "style", "h", "c", "steps"] and o["outputs"] == ["ys", "h_out", "c_out"]
    assert o["dim"] == info["features"]["dim"] == D and o["styles"] == 1 and o["layers"] == 2 and o["hidden"] == 32
    assert len(info["normalisation"]["mean"]) == D and min(info["normalisation"]["std"]) > 0
    assert info["seeds"] and all(s["style"] == "salsa-nights" and len(s["frames"]) == info["features"]["seed_frames"]
                                 and all(len(f) == D for f in s["frames"]) for s in info["seeds"])
    assert info["real_pose_change"]["salsa-nights"] > 0.2  # salsa moves: m/s of joint speed about the root
    session = onnxruntime.InferenceSession(str(out / info["file"]), providers=["CPUExecutionProvider"])
    x = (np.array(info["seeds"][0]["frames"][-1]) - info["normalisation"]["mean"]) / info["normalisation"]["std"]
    h = np.zeros((2, 3, 32), np.float32)
    ys, h_out, _ = session.run(None, {"x": np.tile(x, (3, 1)).astype(np.float32), "style": np.ones((3, 1), np.float32),
                                      "h": h, "c": h, "steps": np.array([4], np.int64)})
    assert ys.shape == (4, 3, D) and np.isfinite(ys).all() and h_out.shape == h.shape


def test_the_dance_card_is_written_from_measurements(pack):
    out, _, _ = pack
    card = (out / "card.md").read_text()
    info = json.loads((out / "my-salsa.json").read_text())
    m = info["pack"]["measures"]
    runs = m["stability"]["runs"]
    assert len(runs) == 3 and m["stability"]["frames"] == 600
    assert "30 iterations" in card and "Daz, 57 joints (3 files)" in card
    assert f"{m['real']['median_pose_change']:.3f} m/s" in card
    for r in runs:
        assert r["finite"] and f"| {r['seed']} | yes | {r['median_ratio']:.2f} |" in card
    passing = sum(r["passes"] for r in runs)
    assert f"{passing} of 3 runs pass the freeze rule" in card
    assert info["pack"]["commercial"] is False and info["pack"]["licence"].startswith("CMU: free")
    assert "- Licence: CMU: free for research and commercial use (tested as if it were not); non-commercial use only." in card
    assert f"{m['real']['sliding_low_foot']:.3f}" in card
    assert (out / "pose_change.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_canonical_points_mirror_left_to_right():
    pairs = mirror_pairs(CANONICAL_JOINTS)
    assert CANONICAL_JOINTS[pairs[CANONICAL_JOINTS.index("LeftUpLeg")]] == "RightUpLeg"
    assert CANONICAL_JOINTS[pairs[CANONICAL_JOINTS.index("RightHand_end")]] == "LeftHand_end"
    assert pairs[CANONICAL_JOINTS.index("Head")] == CANONICAL_JOINTS.index("Head")
    assert sorted(pairs) == list(range(len(CANONICAL_JOINTS)))


def test_dance_refusals(folder, tmp_path):
    # Dance trains on one process: under torchrun (WORLD_SIZE > 1) it says so before reading anything.
    done = run_own("--data", folder, "--kind", "dance", "--out", tmp_path / "p", env={**os.environ, "WORLD_SIZE": "2"})
    assert done.returncode != 0 and "--kind dance trains on one process" in done.stderr
    done = run_own("--data", folder, "--kind", "locomotion", "--out", tmp_path / "p", "--layers", "3")
    assert done.returncode != 0 and "--layers is for --kind dance" in done.stderr
    done = run_own("--data", folder, "--kind", "dance", "--out", tmp_path / "p", "--source-fps", "0")
    assert done.returncode != 0 and "argument --source-fps: must be a positive frame rate, got 0" in done.stderr
