"""Lighter model files (training/onnx/compact.py): weights stored as float16, int8 or int4 come back as the float32
values the graph computes with, and a dance model reads back from its file whatever the format."""
import numpy as np
import onnx
import pytest
import torch
from onnx import TensorProto, helper, numpy_helper

from training.aclstm.exporting import export_onnx
from training.aclstm.graph import check_parity, dance_model_from_onnx
from training.models.aclstm import DanceLSTM, DanceStep
from training.onnx.compact import (INT4_BLOCK, compact_weights, dequantise_int4, quantise_int4, quantise_int8,
                                   stored_float_weights, weight_format)
from training.onnx.sessions import cpu_session


def matmul_model(w: np.ndarray) -> onnx.ModelProto:
    graph = helper.make_graph([helper.make_node("MatMul", ["x", "w"], ["y"])], "g",
                              [helper.make_tensor_value_info("x", TensorProto.FLOAT, ["b", w.shape[0]])],
                              [helper.make_tensor_value_info("y", TensorProto.FLOAT, ["b", w.shape[1]])],
                              [numpy_helper.from_array(w, "w")])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    return model


@pytest.mark.parametrize("fmt, bytes_per_weight, tolerance", [("float16", 2, 1e-3), ("int8", 1, 1e-2)])
def test_stored_weights_compute_as_their_float_values(tmp_path, fmt, bytes_per_weight, tolerance):
    rng = np.random.default_rng(0)
    w = rng.normal(size=(128, 64)).astype(np.float32)
    w[:, 3] *= 50  # one loud output channel must not cost the others their precision (int8: a scale per column)
    compact = compact_weights(matmul_model(w), fmt)
    assert weight_format(compact) == fmt
    path = tmp_path / "m.onnx"
    onnx.save(compact, path)
    assert path.stat().st_size < w.size * bytes_per_weight + 2000
    stored = stored_float_weights(compact)["w"]
    rel = np.abs(stored - w) / np.abs(w).max(axis=0)
    assert rel.max() < tolerance and rel.max() > 0  # lossy, but within the format's step
    x = rng.normal(size=(5, 128)).astype(np.float32)
    y = cpu_session(path).run(None, {"x": x})[0]
    assert np.abs(y - x @ stored).max() < 1e-4  # the graph computes with exactly the stored values


def test_small_weights_stay_float32_and_unknown_formats_are_refused():
    w = np.ones((8, 8), np.float32)
    assert weight_format(compact_weights(matmul_model(w), "int8")) == "float32"
    with pytest.raises(ValueError, match="unknown weight format 'bf16'"):
        compact_weights(matmul_model(w), "bf16")


def test_int8_scales_per_channel():
    w = np.array([[1.0, -100.0], [0.5, 50.0]], np.float32)
    q, scale = quantise_int8(w, axis=1)
    assert q.dtype == np.int8 and scale.shape == (1, 2)
    assert np.allclose(q * scale, w, atol=scale.max() / 2)
    assert q[0, 0] == 127 and q[0, 1] == -127


def test_int4_packs_two_levels_a_byte_and_the_graph_unpacks_them(tmp_path):
    rng = np.random.default_rng(1)
    w = rng.normal(size=(171, 40)).astype(np.float32)  # 171 rows: the last block is padded
    w[:, 5] *= 30
    packed, scale = quantise_int4(w)
    blocks = -(-171 // INT4_BLOCK)
    assert packed.dtype == np.uint8 and packed.shape == (blocks * INT4_BLOCK // 2, 40)
    assert scale.dtype == np.float16 and scale.shape == (blocks, 1, 40)
    stored = dequantise_int4(packed, scale, 171)
    step = np.repeat(scale[:, 0].astype(np.float32), INT4_BLOCK, axis=0)[:171]
    assert np.all(np.abs(stored - w) <= step / 2 + 1e-6)  # each weight at its nearest level of its block
    # One scale per block and output channel, max |w| / 7 of that block's rows: the loud channel keeps its own.
    for b in range(blocks):
        rows = w[b * INT4_BLOCK:(b + 1) * INT4_BLOCK]
        assert np.allclose(scale[b, 0].astype(np.float32), np.abs(rows).max(axis=0) / 7, rtol=1e-3)
    assert scale[:, 0, 5].min() > 10 * np.delete(scale[:, 0], 5, axis=1).max()
    compact = compact_weights(matmul_model(w), "int4")
    assert weight_format(compact) == "int4" and np.array_equal(stored_float_weights(compact)["w"], stored)
    path = tmp_path / "m.onnx"
    onnx.save(compact, path)
    assert path.stat().st_size < w.size * 0.6 + 3000
    x = rng.normal(size=(5, 171)).astype(np.float32)
    assert np.abs(cpu_session(path).run(None, {"x": x})[0] - x @ stored).max() < 1e-4


def test_int4_gptq_keeps_the_output_on_the_given_inputs_closer_than_plain_rounding():
    rng = np.random.default_rng(2)
    w = rng.normal(size=(64, 32)).astype(np.float32)
    mix = np.eye(64) + 0.4 * rng.normal(size=(64, 64))  # correlated inputs, as hidden states are
    x = rng.normal(size=(4000, 64)) @ mix
    held = rng.normal(size=(1000, 64)) @ mix
    error = lambda stored: np.sqrt(np.mean((held @ stored - held @ w) ** 2))
    plain = dequantise_int4(*quantise_int4(w), 64)
    gptq = dequantise_int4(*quantise_int4(w, x.T @ x / len(x)), 64)
    assert error(gptq) < 0.85 * error(plain)
    # The Cholesky form equals GPTQ's textbook form: after each row, its rounding error spread by the inverse Hessian
    # and that row eliminated from the inverse (Schur complement).
    h = x.T @ x / len(x)
    inverse = np.linalg.inv(h + 0.01 * np.mean(np.diag(h)) * np.eye(64))
    work, reference = w.astype(np.float64), np.zeros_like(w, dtype=np.float64)
    for i in range(64):
        if i % INT4_BLOCK == 0:
            s = np.abs(work[i:i + INT4_BLOCK]).max(axis=0) / 7.0
            s = np.where(s > 0, s, 1.0).astype(np.float16).astype(np.float64)
        reference[i] = np.clip(np.rint(work[i] / s), -7, 7) * s
        work[i + 1:] -= np.outer(inverse[i + 1:, i], (work[i] - reference[i]) / inverse[i, i])
        inverse -= np.outer(inverse[:, i], inverse[i, :]) / inverse[i, i]
    assert np.abs(gptq - reference).max() < 1e-6
    with pytest.raises(ValueError, match="int4 stores 2-D weights"):
        compact_weights(matmul_model(np.ones((1, 64, 64), np.float32)), "int4")


@pytest.mark.parametrize("fmt", ["float32", "float16", "int8", "int4"])
def test_dance_graph_parity_and_read_back(tmp_path, fmt):
    torch.manual_seed(2)
    model = DanceLSTM(9, 3, hidden=64, layers=3).eval()
    path = tmp_path / "dance.onnx"
    stored = export_onnx(model, path, fmt)
    assert check_parity(stored, path)["max_abs_diff"] < 1e-4
    # The stored network is the trained one up to the format's rounding.
    x, style = torch.randn(2, 9), torch.eye(3)[:2]
    h, c = model.zero_state(2)
    with torch.no_grad():
        a, b = DanceStep(model)(x, style, h, c)[0], DanceStep(stored)(x, style, h, c)[0]
    assert (a - b).abs().max() < {"float32": 1e-6, "float16": 1e-2, "int8": 5e-2, "int4": 0.5}[fmt]


def test_gaussian_head_dance_graph_draws_from_the_given_normals(tmp_path):
    """The Gaussian head's Loop graph: parity with torch on the same normals, read back with its head, and a draw at
    temperature 0 is the mean while the normals move a draw at temperature 1."""
    torch.manual_seed(4)
    model = DanceLSTM(9, 3, hidden=32, layers=2, head="gauss").eval()
    path = tmp_path / "gauss.onnx"
    stored = export_onnx(model, path, "float32")
    assert check_parity(stored, path)["max_abs_diff"] < 1e-4
    assert dance_model_from_onnx(path, 9, 3, 32, 2).head == "gauss"
    session = cpu_session(path)
    x, style = np.zeros((1, 9), np.float32), np.eye(3, dtype=np.float32)[:1]
    h = np.zeros((2, 1, 32), np.float32)
    run = lambda noise, t: session.run(["ys"], {"x": x, "style": style, "h": h, "c": h, "steps": np.array([1], np.int64),
                                                "noise": noise, "temperature": np.array([t], np.float32)})[0][0]
    zeros, ones = np.zeros((1, 1, 9), np.float32), np.ones((1, 1, 9), np.float32)
    with torch.no_grad():
        mean = model.distribution(torch.from_numpy(x)[:, None], torch.from_numpy(style))[0][:, 0].numpy()
    assert np.abs(run(ones, 0.0) - mean).max() < 1e-5
    assert np.abs(run(zeros, 1.0) - mean).max() < 1e-5
    assert (run(ones, 1.0) > mean).all()


def test_dance_model_reads_back_from_the_earlier_one_step_export(tmp_path):
    """The torch export with ONNX LSTM nodes (the files shipped before the Loop graph) reads back exactly."""
    torch.manual_seed(3)
    model = DanceLSTM(9, 3, hidden=16, layers=3).eval()
    x, style = torch.zeros(1, 9), torch.zeros(1, 3)
    h, c = model.zero_state(1)
    path = tmp_path / "old.onnx"
    torch.onnx.export(DanceStep(model).eval(), (x, style, h, c), str(path), input_names=["x", "style", "h", "c"],
                      output_names=["y", "h_out", "c_out"], opset_version=17, dynamo=False)
    back = dance_model_from_onnx(path, 9, 3, 16, 3)
    xs = torch.randn(4, 9)
    with torch.no_grad():
        a = DanceStep(model)(xs, torch.eye(3)[[0, 1, 2, 0]], *model.zero_state(4))[0]
        b = DanceStep(back)(xs, torch.eye(3)[[0, 1, 2, 0]], *model.zero_state(4))[0]
    assert (a - b).abs().max() < 1e-6


def test_generator_int8_keeps_its_mixture_head_float16(tmp_path):
    """The generator's mixture head measurably needs more than int8 (held-out NLL -28.9 -> -14.5 per frame), so its
    int8 export keeps fc3 float16; the file still computes exactly what its stored weights give."""
    from training.generator.graph import HEAD_WEIGHTS, check_parity, export_onnx
    from training.generator.recovery import model_from_onnx
    from training.models.generator import MixtureLSTM

    torch.manual_seed(4)
    model = MixtureLSTM(40, 64, 3).eval()
    path = tmp_path / "generator.onnx"
    export_onnx(model, path, "int8")
    stored = onnx.load(str(path))
    names = {t.name for t in stored.graph.initializer}
    assert weight_format(stored) == "int8+float16"
    # (the 64 x 3 logits weight is under MIN_ELEMENTS and stays float32)
    assert {"fc3_mu.weight_t.f16", "fc3_log_sigma.weight_t.f16", "lstm0_ih.weight_t.i8"} <= names
    assert "fc3_logits.weight_t" in HEAD_WEIGHTS
    assert check_parity(model_from_onnx(path, 40, 64, 3), path)["max_abs_diff"] < 1e-4


def test_dance_input_moments_cover_every_large_weight_of_the_step_graph():
    """calibration.input_moments gives the second moment of what each large weight of the dance graph multiplies
    (training clips only), by the graph's names and with the weights' row counts."""
    from training.aclstm.calibration import input_moments
    from training.aclstm.graph import dance_graph
    from training.data.dance import DanceClip

    torch.manual_seed(3)
    model = DanceLSTM(171, 3, hidden=16, layers=3).eval()
    rng = np.random.default_rng(4)
    walk = lambda n: np.cumsum(rng.normal(scale=0.01, size=(n, 57, 3)), axis=0) + [0, 0.9, 0]
    clips = [DanceClip(style, f"{style}/{k}.bvh", 60.0, walk(700), held_out=(k == 1)) for style in ("salsa", "indian", "martial") for k in range(2)]
    moments = input_moments(model, clips, np.zeros(171), np.ones(171))
    inits = {t.name: t for t in dance_graph(model).graph.initializer}
    large = {n for n, t in inits.items() if np.prod(t.dims) >= 16 * 16 * 4 and n != "lstm0.w_style_t"}
    assert set(moments) == large
    for name, m in moments.items():
        assert m.shape == (inits[name].dims[0],) * 2, name
        assert np.allclose(m, m.T) and np.linalg.eigvalsh(m).min() > -1e-9, name
    # What each weight multiplies, teacher-forced: the top layer's h is nn.LSTM's output, and it is the top layer's
    # previous h one frame later.
    from training.aclstm.calibration import _layer_inputs
    x = rng.normal(size=(2, 7, 171)).astype(np.float32)
    style = np.eye(3, dtype=np.float32)[[0, 2]]
    seen = _layer_inputs(model, x, style, None)
    with torch.no_grad():
        top, _ = model.lstm(torch.cat([torch.from_numpy(x), torch.from_numpy(style)[:, None].expand(-1, 7, -1)], -1))
    assert np.allclose(np.stack(seen["decoder.weight_t"], 1), top.numpy(), atol=1e-5)
    assert np.allclose(np.stack(seen["lstm2.w_hh_t"][1:], 1), top.numpy()[:, :-1], atol=1e-5)
    assert np.allclose(np.stack(seen["lstm0.w_x_t"], 1), x)
