"""The latent ERD's training pieces: the motion-energy term, the smoothed control it reads, and the autoencoder
rebuilt from its shipped ONNX graphs (training/autoencoder/recovery.py)."""
import json

import numpy as np
import pytest
import torch

from training.autoencoder.exporting import export_graphs
from training.autoencoder.recovery import recover_checkpoint
from training.autoencoder.training import load_autoencoder
from training.data.windows import CONTROL_SLICE, ROW_DIM
from training.latent_erd.sequences import step_control
from training.latent_erd.training import energy_loss
from training.models.autoencoder import POOLING, MotionAutoencoder


def strides(amplitude: float, phase: float = 0.0, steps: int = 32) -> torch.Tensor:
    t = torch.arange(steps, dtype=torch.float32)
    return (amplitude * torch.sin(0.8 * t + phase))[None, :, None].repeat(2, 1, 3)


def test_energy_loss_is_blind_to_phase_and_sees_a_shrunken_stride():
    real, mask = strides(1.0), torch.ones(2, 32)
    assert float(energy_loss(strides(1.0, phase=2.0), real, mask)) < 1e-3  # the same stride out of phase
    assert float(energy_loss(strides(0.5), real, mask)) > 0.05
    # Its gradient asks a shrunken stride to grow.
    pred = strides(0.5).requires_grad_(True)
    energy_loss(pred, real, mask).backward()
    assert float((pred.grad * pred).sum()) < 0


def test_energy_loss_ignores_padding():
    real, pred = strides(1.0), strides(1.0)
    mask = torch.ones(2, 32)
    mask[:, 20:] = 0
    pred[:, 20:] = 0  # padding after a short clip: no targets there
    assert float(energy_loss(pred, real, mask)) < 1e-3


def test_step_control_smooths_the_stride_out_of_the_signal():
    frames = 120
    rows = np.zeros((frames, ROW_DIM), np.float32)
    rows[:, CONTROL_SLICE.start] = 1.0 + 0.3 * np.sin(2 * np.pi * np.arange(frames) / 30.0)  # 1 Hz sway in the speed
    raw, smoothed = step_control(rows, frames // POOLING), step_control(rows, frames // POOLING, sigma=10.0)
    assert raw.shape == smoothed.shape == (frames // POOLING, POOLING * 3)
    np.testing.assert_array_equal(raw.reshape(-1, 3), rows[:, CONTROL_SLICE])
    assert np.ptp(raw[10:-10, 0]) > 0.5 and np.ptp(smoothed[10:-10, 0]) < 0.1
    assert abs(float(smoothed[:, 0].mean()) - 1.0) < 0.02


def test_the_autoencoder_is_rebuilt_from_its_onnx_graphs(tmp_path):
    torch.manual_seed(2)
    model = MotionAutoencoder(ROW_DIM, hidden=8, latent=16).eval()
    export_graphs(model, tmp_path / "manifold-encoder.onnx", tmp_path / "manifold-decoder.onnx")
    info = {"fps": 30, "window": 120, "latent": 16, "hidden": 8, "rows": {"dim": ROW_DIM},
            "files": {"encoder": "manifold-encoder.onnx", "decoder": "manifold-decoder.onnx"},
            "normalisation": {"mean": [0.0] * ROW_DIM, "std": [1.0] * ROW_DIM}}
    (tmp_path / "manifold.json").write_text(json.dumps(info))
    _, worst = recover_checkpoint(tmp_path / "manifold.json", tmp_path / "best.pt")
    assert worst < 1e-4
    rebuilt, meta = load_autoencoder(tmp_path / "best.pt")
    assert (meta["hidden"], meta["latent"]) == (8, 16)
    for name, value in model.state_dict().items():
        torch.testing.assert_close(rebuilt.state_dict()[name], value)


def test_a_foreign_graph_is_refused(tmp_path):
    torch.manual_seed(2)
    model = MotionAutoencoder(ROW_DIM, hidden=8, latent=16).eval()
    export_graphs(model, tmp_path / "a.onnx", tmp_path / "b.onnx")
    info = {"fps": 30, "window": 120, "latent": 16, "hidden": 8, "rows": {"dim": ROW_DIM},
            "files": {"encoder": "b.onnx", "decoder": "a.onnx"}, "normalisation": {"mean": [], "std": []}}
    (tmp_path / "manifold.json").write_text(json.dumps(info))
    with pytest.raises(ValueError, match="no initializer"):
        recover_checkpoint(tmp_path / "manifold.json", tmp_path / "best.pt")
    assert not (tmp_path / "best.pt").exists()
