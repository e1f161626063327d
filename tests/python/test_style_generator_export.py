"""The style generator's export (training/style_generator/graph.py, exporting.py): the ONNX step with its style input
against torch, one-hot and blended; a blend is the convex combination of the styles' embeddings; the shipped
generator's graph is unchanged (its file rewritten from its own weights is the same bytes); the fixture the page's
parity test reads (tests/fixtures/style_generator/) holds a step onnxruntime still reproduces."""
import json

import numpy as np
import onnx
import pytest
import torch

from training.generator.graph import OUTPUTS, export_onnx
from training.generator.recovery import model_from_onnx
from training.models.generator import MixtureLSTM, StyledGenerator
from training.onnx.sessions import cpu_session
from training.paths import MODELS_DIR, REPO_ROOT
from training.style_generator.graph import (INPUTS, StyleGeneratorStep, check_style_parity, export_style_onnx,
                                            model_from_style_onnx, style_parity_error)

FIXTURE_DIR = REPO_ROOT / "tests" / "fixtures" / "style_generator"


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    torch.manual_seed(3)
    model = MixtureLSTM(12, 16, 3, styles=3, style_dim=4).eval()
    with torch.no_grad():
        model.style.weight.mul_(10.0)  # styles far apart, so a wrong style or blend shows in the outputs
    path = tmp_path_factory.mktemp("style") / "tiny.onnx"
    export_style_onnx(model, path)
    return model, path


def test_the_step_has_a_style_input_and_matches_torch(tiny):
    model, path = tiny
    graph = onnx.load(str(path)).graph
    assert [i.name for i in graph.input] == INPUTS == ["x", "h", "c", "style"]
    assert [o.name for o in graph.output] == OUTPUTS
    assert style_parity_error(model, path, blend=False) < 1e-5
    assert style_parity_error(model, path, blend=True) < 1e-5
    parity = check_style_parity(model_from_style_onnx(path, 12, 16, 3, 3, 4), path)
    assert parity["one_hot"] < 1e-5 and parity["blended"] < 1e-5


def test_a_one_hot_is_the_style_id_and_a_blend_mixes_the_embeddings(tiny):
    model, path = tiny
    session = cpu_session(path)
    rng = np.random.default_rng(0)
    x = rng.normal(size=(1, 12)).astype(np.float32)
    h = rng.normal(scale=0.3, size=(2, 1, 16)).astype(np.float32)
    c = rng.normal(scale=0.3, size=(2, 1, 16)).astype(np.float32)
    run = lambda style: session.run(OUTPUTS, {"x": x, "h": h, "c": c, "style": np.array([style], np.float32)})
    with torch.no_grad():  # style id 2 through the embedding lookup, the way training feeds it
        _, mu, _, _ = StyledGenerator(model, 2)(torch.from_numpy(x).unsqueeze(1), (torch.from_numpy(h), torch.from_numpy(c)))
    np.testing.assert_allclose(run([0, 0, 1])[1], mu[:, 0].numpy(), atol=1e-5)
    # The blend feeds fc1 the mixed embedding: the same as a model whose style 0 row is that mixture.
    mixed = MixtureLSTM(12, 16, 3, styles=3, style_dim=4).eval()
    mixed.load_state_dict(model.state_dict())
    with torch.no_grad():
        mixed.style.weight[0] = 0.5 * model.style.weight[1] + 0.5 * model.style.weight[2]
        ref = StyleGeneratorStep(mixed)(*(torch.from_numpy(a) for a in (x, h, c)), torch.tensor([[1.0, 0, 0]]))
    blended = run([0, 0.5, 0.5])
    for a, b in zip(blended, ref):
        np.testing.assert_allclose(a, b.numpy(), atol=1e-5)
    assert np.abs(blended[1] - run([0, 1, 0])[1]).max() > 1e-3 and np.abs(blended[1] - run([0, 0, 1])[1]).max() > 1e-3


def test_a_model_without_styles_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no style input"):
        export_style_onnx(MixtureLSTM(12, 16, 3), tmp_path / "plain.onnx")


def test_the_shipped_generator_graph_is_unchanged(tmp_path):
    info = json.loads((MODELS_DIR / "generator.json").read_text())
    o = info["onnx"]
    model = model_from_onnx(MODELS_DIR / info["file"], o["dim"], o["hidden"], o["mixtures"])
    export_onnx(model, tmp_path / "generator.onnx", "int8")
    assert (tmp_path / "generator.onnx").read_bytes() == (MODELS_DIR / info["file"]).read_bytes()


def test_the_page_fixture_is_reproduced_by_onnxruntime():
    info = json.loads((FIXTURE_DIR / "style-tiny.json").read_text())
    ref = json.loads((FIXTURE_DIR / "style-tiny_reference.json").read_text())
    assert info["styles"][0] == "cmu" and info["onnx"]["inputs"] == INPUTS
    assert info["licence"].startswith("CC BY-NC 4.0") and info["data"]
    assert {s["style"] for s in info["seeds"]} == set(info["styles"])
    B, S, H, D = ref["inputs"]["batch"], len(info["styles"]), info["onnx"]["hidden"], info["onnx"]["dim"]
    feeds = {"x": np.array(ref["inputs"]["x"], np.float32).reshape(B, D),
             "h": np.array(ref["inputs"]["h"], np.float32).reshape(2, B, H),
             "c": np.array(ref["inputs"]["c"], np.float32).reshape(2, B, H),
             "style": np.array(ref["inputs"]["style"], np.float32).reshape(B, S)}
    assert np.allclose(feeds["style"].sum(axis=1), 1) and (feeds["style"] > 0).sum() == 4  # two one-hots, one blend
    outs = cpu_session(FIXTURE_DIR / info["file"]).run(OUTPUTS, feeds)
    for name, out in zip(OUTPUTS, outs):
        np.testing.assert_allclose(out.ravel(), ref["outputs"][name], atol=1e-5, rtol=1e-5)
