"""python -m training.own on two processes under torchrun (DistributedDataParallel over gloo) trains the model one
process trains: the same loss at each iteration and the same weights, within float rounding, for the same seed and
whole batch; a run stopped and resumed under torchrun ends where the uninterrupted run does. Dropout is off: with it
each process draws its own masks (training/own/distributed.py)."""
import json
import subprocess
import sys

import numpy as np
import pytest
import torch
import torch.distributed

from conftest import REPO
from test_own import as_mixamo, cmu_text, every_nth_frame

if not (torch.distributed.is_available() and torch.distributed.is_gloo_available()):
    pytest.skip("this PyTorch has no torch.distributed with gloo", allow_module_level=True)

DRIVER = REPO / "tests" / "python" / "own_train_driver.py"
TINY = ["--kind", "locomotion", "--hidden", "32", "--iters-per-epoch", "10", "--batch", "8", "--window", "20",
        "--dropout", "0", "--seed", "3", "--checkpoint-minutes", "10"]
ITERATIONS = 24
TOLERANCE = dict(rtol=1e-4, atol=1e-4)


def torchrun(target: list[str], *args) -> list[str]:
    """Two processes on this machine running `target` (a script, or --module and a module) with `args`. The "--"
    keeps torchrun from reading the trainer's --run as an abbreviation of its own --run-path."""
    return [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node=2", *target, "--", *args]


def train(command: list[str]) -> subprocess.CompletedProcess:
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=80)
    assert done.returncode == 0, done.stdout[-1500:] + done.stderr[-3000:]
    return done


def final_weights(run) -> dict:
    """The model's weights at the end, and RMSProp's running mean of squared gradients: RMSProp's steps hardly change
    when every gradient is scaled alike, so the weights alone would not show gradients averaged with a wrong factor."""
    state = torch.load(run / "checkpoint.pt", weights_only=False)
    squares = {f"square_avg {i}": s["square_avg"] for i, s in state["optimiser"]["state"].items()}
    return {**state["model"], **squares}


def assert_same_weights(a, b):
    assert a.keys() == b.keys()
    for key in a:
        torch.testing.assert_close(a[key], b[key], **TOLERANCE, msg=lambda m: f"{key}: {m}")


@pytest.fixture(scope="module")
def folder(tmp_path_factory, mocap):
    root = tmp_path_factory.mktemp("ddp") / "two-walks"
    root.mkdir()
    for name in ("07_04", "07_05"):
        (root / f"{name}.bvh").write_text(every_nth_frame(as_mixamo(cmu_text(name)), 4))
    return root


@pytest.fixture(scope="module")
def one_process(folder, tmp_path_factory):
    run = tmp_path_factory.mktemp("one")
    train([sys.executable, str(DRIVER), "--data", str(folder), "--out", str(run / "pack"), "--run", str(run),
           "--iterations", str(ITERATIONS), *TINY])
    return run


def test_two_processes_train_the_model_of_one(folder, one_process, tmp_path):
    run = tmp_path / "two"
    train(torchrun([str(DRIVER)], "--data", str(folder), "--out", str(run / "pack"), "--run", str(run),
                   "--iterations", str(ITERATIONS), *TINY))
    one, two = (json.loads((r / "losses.json").read_text()) for r in (one_process, run))
    assert len(one) == len(two) == ITERATIONS
    np.testing.assert_allclose(two, one, rtol=TOLERANCE["rtol"])
    assert one[-1] < one[0] - 5, "the tiny run did not learn: nothing to compare"
    assert_same_weights(final_weights(one_process), final_weights(run))
    # Only process 0 writes: one log, with one start line.
    assert (run / "train.log").read_text().count("start:") == 1


def test_resumed_under_torchrun_ends_as_the_uninterrupted_run(folder, one_process, tmp_path):
    """Half the run, then the rest with --resume through the command itself, which exports the pack from process 0."""
    run, out = tmp_path / "resumed", tmp_path / "pack"
    train(torchrun([str(DRIVER)], "--data", str(folder), "--out", str(out), "--run", str(run),
                   "--iterations", str(ITERATIONS // 2), *TINY))
    first_half = json.loads((run / "losses.json").read_text())
    np.testing.assert_allclose(first_half, json.loads((one_process / "losses.json").read_text())[:ITERATIONS // 2],
                               rtol=TOLERANCE["rtol"])
    done = train(torchrun(["--module", "training.own"], "--data", str(folder), "--out", str(out), "--run", str(run),
                          "--resume", "--iterations", str(ITERATIONS), "--stability-frames", "200", *TINY))
    assert f"resumed at epoch 1 iteration {ITERATIONS // 2 - 10}" in (run / "train.log").read_text()
    assert_same_weights(final_weights(one_process), final_weights(run))
    assert done.stdout.count("wrote the pack") == 1 and (out / "card.md").exists()
