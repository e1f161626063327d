"""training/generator/recovery.py: the torch checkpoint rebuilt from an ONNX export computes what the export computes."""
import json

import numpy as np
import pytest
import torch

from training.generator.graph import INPUTS, OUTPUTS, export_onnx
from training.generator.training import load_generator
from training.models.generator import GeneratorStep, MixtureLSTM
from training.generator.recovery import checkpoint_from_shipped, compare_with_onnx, model_from_onnx
from training.paths import MODELS_DIR
from training.mocap.rotations import matrix_to_quat


def export_with_lstm_nodes(model: MixtureLSTM, path) -> None:
    """The original export form: torch's legacy exporter writes nn.LSTM as ONNX LSTM nodes."""
    x, (h, c) = torch.zeros(1, model.dim), model.zero_state(1)
    b = {0: "batch"}
    torch.onnx.export(GeneratorStep(model).eval(), (x, h, c), str(path), input_names=INPUTS, output_names=OUTPUTS,
                      opset_version=17, dynamo=False,
                      dynamic_axes={"x": b, "h": {1: "batch"}, "c": {1: "batch"}, "weights": b, "mu": b, "sigma": b,
                                    "h_out": {1: "batch"}, "c_out": {1: "batch"}})


def random_model(dim=11, hidden=16, mixtures=5) -> MixtureLSTM:
    torch.manual_seed(3)
    model = MixtureLSTM(dim, hidden, mixtures).eval()
    with torch.no_grad():
        for p in model.parameters():  # distinct gate blocks, so a wrong gate order shows
            p.add_(torch.randn_like(p) * 0.3)
    return model


def test_recovers_the_lstm_node_export_exactly(tmp_path):
    model = random_model()
    path = tmp_path / "g.onnx"
    export_with_lstm_nodes(model, path)
    rebuilt = model_from_onnx(path, 11, 16, 5)
    for name, value in model.state_dict().items():
        assert torch.equal(rebuilt.state_dict()[name], value), name
    assert compare_with_onnx(rebuilt, path) < 1e-5


def test_recovers_the_gate_level_export(tmp_path):
    model = random_model()
    path = tmp_path / "g.onnx"
    export_onnx(model, path)
    rebuilt = model_from_onnx(path, 11, 16, 5)
    assert compare_with_onnx(rebuilt, path) < 1e-5
    assert compare_with_onnx(model, path) < 1e-5


def test_the_comparison_sees_a_wrong_weight(tmp_path):
    model = random_model()
    path = tmp_path / "g.onnx"
    export_with_lstm_nodes(model, path)
    rebuilt = model_from_onnx(path, 11, 16, 5)
    with torch.no_grad():
        rebuilt.lstm.weight_hh_l1[:16] *= 1.01  # input gate of the second layer, slightly off
    assert compare_with_onnx(rebuilt, path) > 1e-4


@pytest.mark.skipif(not (MODELS_DIR / "generator.json").exists(), reason="no generator shipped yet")
def test_shipped_generator_round_trips_through_a_checkpoint(tmp_path):
    info = json.loads((MODELS_DIR / "generator.json").read_text())
    state = checkpoint_from_shipped(MODELS_DIR / info["file"], info)
    torch.save(state, tmp_path / "best.pt")
    model, meta, loaded = load_generator(tmp_path / "best.pt")  # as python -m training.generator.export loads it
    assert compare_with_onnx(model, MODELS_DIR / info["file"], batches=(1, 7)) < 1e-5
    assert loaded["epoch"] == info["training"]["epochs"] and loaded["valid_nll"] == info["training"]["valid_nll_per_frame"]
    assert (meta["dim"], meta["hidden"], meta["mixtures"], meta["fps"]) == (
        info["onnx"]["dim"], info["onnx"]["hidden"], info["onnx"]["mixtures"], info["fps"])
    assert meta["mean"] == info["normalisation"]["mean"] and meta["std"] == info["normalisation"]["std"]
    assert meta["valid_files"] == info["training"]["valid_files"] and meta["args"] == info["training"]["args"]
    # References are stored as matrices and come back as the shipped quaternions.
    refs = np.array(meta["references"])
    assert refs.shape == (len(info["features"]["references"]), 3, 3)
    assert np.abs(matrix_to_quat(refs) - np.array(info["features"]["references"])).max() < 1e-6
