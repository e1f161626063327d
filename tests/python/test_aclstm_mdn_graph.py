"""Issue 42 for the page: the phrase sampler's inverse-CDF draw, the output filter (jitter_filter.py), the mdn head's
ONNX Loop graph against torch, and the exported model run as the page runs it (shipped.py). A tiny random network:
no run folder needed."""
import json
from types import SimpleNamespace

import numpy as np
import onnx
import pytest
import torch

from training.aclstm.graph import (MDN_OUTPUTS, check_parity, dance_graph, dance_model_from_onnx, mdn_parity_feeds,
                                   mdn_torch_steps)
from training.aclstm.jitter_filter import (CausalLowPass, butterworth_lowpass, choose_cutoff, gain, lowpass, rest_state)
from training.aclstm.phrase_sampling import PhraseParams, PhraseSampler, inverse_cdf_draw
from training.aclstm.shipped import ShippedDance
from training.models.aclstm import DanceLSTM
from training.onnx.sessions import cpu_session


def test_inverse_cdf_draw_takes_the_first_component_whose_cumulative_share_exceeds_the_uniform():
    w = torch.tensor([[0.1, 0.4, 0.02, 0.48]] * 6)
    u = torch.tensor([0.0, 0.1, 0.11, 0.5, 0.52, 0.9999999])
    # threshold 0.05: component 2 is not allowed; cumulative shares of the allowed 0.1, 0.4, 0.48: 0.102, 0.510, 1
    got = inverse_cdf_draw(w, torch.full((6,), 0.05), u)
    assert got.tolist() == [0, 0, 1, 1, 3, 3]
    # none allowed: the largest weight's component whatever the uniform
    assert inverse_cdf_draw(w, torch.full((6,), 0.9), u).tolist() == [3] * 6


def test_inverse_cdf_draw_frequencies_follow_the_allowed_weights():
    w = torch.tensor([[0.5, 0.03, 0.2, 0.27]]).repeat(20000, 1)
    got = inverse_cdf_draw(w, torch.full((20000,), 0.05), torch.rand(20000, generator=torch.Generator().manual_seed(0)))
    share = torch.bincount(got, minlength=4).float() / 20000
    assert share[1] == 0
    assert torch.allclose(share, torch.tensor([0.5, 0, 0.2, 0.27]) / 0.97, atol=0.015)


def test_the_sampler_gives_the_same_draws_from_the_same_uniforms_whatever_its_generator():
    torch.manual_seed(0)
    logits, mu, ls = torch.randn(3, 5), torch.randn(3, 5, 4), torch.randn(3, 5, 4).clamp(-3, 0)
    params = [PhraseParams(0.5, 3, 0.8, 0.05, 1)] * 3
    wander = torch.randn(3, 4)
    g = torch.Generator().manual_seed(7)
    randoms = [(torch.rand(3, generator=g), torch.randn(3, 4, generator=g)) for _ in range(12)]
    a = PhraseSampler(params, 4, torch.Generator().manual_seed(1), wander=wander)
    b = PhraseSampler(params, 4, torch.Generator().manual_seed(2), wander=wander)
    ya = [a.step(logits, mu, ls, u, n) for u, n in randoms]
    yb = [b.step(logits, mu, ls, u, n) for u, n in randoms]
    assert all(torch.equal(p, q) for p, q in zip(ya, yb)) and a.redraws.tolist() == b.redraws.tolist()
    assert a.redraws.min() >= 4  # a max hold of 3 frames: redrawn inside the 12 steps
    # Drawing its randoms from its generator, in the documented order (a uniform per row, then normals), is the same.
    c = PhraseSampler(params, 4, torch.Generator().manual_seed(7), wander=wander)
    assert all(torch.equal(c.step(logits, mu, ls), y) for y in ya)


@pytest.mark.parametrize("cutoff", [2.0, 6.5, 12.0])
def test_the_butterworth_lowpass_has_unit_dc_gain_and_cuts_above_its_cutoff(cutoff):
    b, a = butterworth_lowpass(cutoff, 30.0)
    assert a[0] == 1 and gain(b, a, 0.0, 30.0) == pytest.approx(1.0, abs=1e-12)
    assert gain(b, a, cutoff, 30.0) == pytest.approx(2 ** -0.5, rel=1e-9)
    assert gain(b, a, 15.0, 30.0) < 1e-9
    above = np.linspace(min(cutoff * 1.5, 14.0), 14.9, 20)
    assert (gain(b, a, above, 30.0) < 0.5).all() and (np.diff(gain(b, a, np.linspace(0, 15, 50), 30.0)) <= 1e-12).all()
    # In time: a constant from rest stays put; a sinusoid well above the cutoff comes out small, well below it passes.
    t = np.arange(600) / 30.0
    const = np.full((600, 3), 0.7)
    assert np.abs(lowpass(const, b, a) - 0.7).max() < 1e-12
    hi = min(14.0, 2.5 * cutoff)
    out_hi = lowpass(np.sin(2 * np.pi * hi * t)[:, None], b, a, initial=np.zeros(1))[300:]
    out_lo = lowpass(np.sin(2 * np.pi * cutoff / 4 * t)[:, None], b, a, initial=np.zeros(1))[300:]
    assert np.abs(out_hi).max() < 0.3 and np.abs(out_lo).max() > 0.9


def test_the_filter_is_causal_and_torch_computes_it_as_numpy():
    b, a = butterworth_lowpass(5.0, 30.0)
    x = np.random.default_rng(0).normal(size=(50, 4))
    y = lowpass(x, b, a, initial=np.zeros(4))
    x2 = x.copy()
    x2[30:] += 5.0
    y2 = lowpass(x2, b, a, initial=np.zeros(4))
    assert np.array_equal(y[:30], y2[:30]) and not np.allclose(y[30:], y2[30:])
    f = CausalLowPass(b[None], a[None], rest_state(np.zeros((1, 4))))
    yt = np.stack([f.step(torch.from_numpy(x[t][None]).float())[0].numpy() for t in range(50)])
    assert np.abs(yt - y).max() < 1e-5


def fake_clip(freq, held_out, style="salsa", seconds=40.0, fps=60.0):
    t = np.arange(int(seconds * fps)) / fps
    pos = np.zeros((len(t), 3, 3))
    pos[:, 0, 1] = 1.0
    pos[:, 1, 0] = 0.3 * np.sin(2 * np.pi * freq * t)
    pos[:, 2, 2] = 0.003 * np.sin(2 * np.pi * 9.0 * t)  # a little fast motion: 0.2% of the velocity power
    return SimpleNamespace(style=style, held_out=held_out, fps=fps, positions=pos, seconds=seconds)


def test_the_cutoff_is_where_the_training_clips_velocity_power_lies_below():
    clips = [fake_clip(2.0, False), fake_clip(2.0, False)]
    cutoff = choose_cutoff(clips, "salsa")
    assert 1.7 < cutoff < 2.6
    # Held-out clips and other styles play no part; a share covering the fast motion moves the cutoff up to it.
    assert choose_cutoff(clips + [fake_clip(7.0, True), fake_clip(7.0, False, "indian")], "salsa") == cutoff
    assert choose_cutoff(clips, "salsa", share=0.9995) > 8.0


@pytest.fixture(scope="module")
def tiny_mdn(tmp_path_factory):
    torch.manual_seed(3)
    model = DanceLSTM(6, 3, hidden=16, layers=2, head="mdn", components=4).eval()
    path = tmp_path_factory.mktemp("mdn") / "tiny-mdn.onnx"
    onnx.save(dance_graph(model), str(path))
    return model, path


def test_the_mdn_graph_matches_torch_with_a_redraw_inside_the_call(tiny_mdn):
    model, path = tiny_mdn
    parity = check_parity(model, path)
    assert parity["max_abs_diff"] < 1e-4 and parity["batches"] == [1, 3] and parity["steps"] == [1, 40]
    assert parity["redraws_in_calls"] > 0
    inputs = [i.name for i in onnx.load(str(path)).graph.input]
    assert inputs[:5] == ["x", "style", "h", "c", "steps"] and {"uniforms", "normals", "filt", "filter_b"} <= set(inputs)


def test_the_mdn_graph_gives_the_same_dance_in_one_call_or_two(tiny_mdn):
    model, path = tiny_mdn
    session = cpu_session(path)
    feeds = mdn_parity_feeds(model, 2, 30, np.random.default_rng(4))
    whole = dict(zip(MDN_OUTPUTS, session.run(MDN_OUTPUTS, feeds)))
    first = dict(zip(MDN_OUTPUTS, session.run(MDN_OUTPUTS, {**feeds, "steps": np.array([12]), "uniforms": feeds["uniforms"][:12],
                                                                 "normals": feeds["normals"][:12]})))
    rest = {**feeds, "x": first["ys"][-1], "h": first["h_out"], "c": first["c_out"], "held": first["held_out"],
            "age": first["age_out"], "wander": first["wander_out"], "filt": first["filt_out"], "steps": np.array([18]),
            "uniforms": feeds["uniforms"][12:], "normals": feeds["normals"][12:]}
    second = dict(zip(MDN_OUTPUTS, session.run(MDN_OUTPUTS, rest)))
    for name in ("ys", "display", "weights"):
        assert np.abs(np.concatenate([first[name], second[name]]) - whole[name]).max() < 1e-6
    assert np.array_equal(second["held_out"], whole["held_out"]) and np.array_equal(second["age_out"], whole["age_out"])
    # display is ys through the filter, not fed back: the drawn frames differ from the shown ones
    assert np.abs(whole["display"] - whole["ys"]).max() > 1e-2


def test_the_mdn_graph_reads_back_into_the_same_network(tiny_mdn):
    model, path = tiny_mdn
    back = dance_model_from_onnx(path, 6, 3, 16, 2)
    assert back.head == "mdn" and back.components == 4
    feeds = mdn_parity_feeds(model, 2, 10, np.random.default_rng(5))
    a, b = mdn_torch_steps(model, feeds), mdn_torch_steps(back, feeds)
    assert max(float(np.abs(a[n] - b[n]).max()) for n in MDN_OUTPUTS) < 1e-5


FILTERS = {s: butterworth_lowpass(f, 30.0) for s, f in (("salsa", 8.0), ("indian", 6.0), ("martial", 10.0))}


def tiny_export(path, folder):
    """The tiny graph with the JSON fields the mdn export writes that the runner and the fixture read."""
    rng = np.random.default_rng(1)
    info = {"file": path.name, "styles": ["salsa", "indian", "martial"], "head": "mdn", "components": 4,
            "normalisation": {"mean": [0.1] * 6, "std": [2.0] * 6},
            "onnx": {"layers": 2, "hidden": 16, "dim": 6, "styles": 3, "inputs": [i.name for i in onnx.load(str(path)).graph.input],
                     "outputs": MDN_OUTPUTS},
            "seeds": [{"style": s, "name": f"{s} {k}", "frames": rng.normal(size=(10, 6)).tolist()}
                      for s in ("salsa", "indian", "martial") for k in range(2)],
            "sampling": {"params": {s: PhraseParams(0.5, 10 + 5 * k, 0.9, 0.05, 2).to_json() for k, s in enumerate(FILTERS)},
                         "filter": {s: {"cutoff_hz": 0, "b": b.tolist(), "a": a.tolist()} for s, (b, a) in FILTERS.items()}}}
    (folder / path.name).write_bytes(path.read_bytes())
    (folder / "tiny-mdn.json").write_text(json.dumps(info))
    return info


def test_the_mdn_fixture_holds_a_redraw_in_every_call(tiny_mdn, tmp_path):
    from training.aclstm.exporting import MDN_FIXTURE_STEPS, write_mdn_reference_fixture

    _, path = tiny_mdn
    info = tiny_export(path, tmp_path)
    write_mdn_reference_fixture(tmp_path / path.name, info, tmp_path / "fixture.json")
    fixture = json.loads((tmp_path / "fixture.json").read_text())
    session = cpu_session(tmp_path / path.name)
    for name, batch in (("batch1", 1), ("batch2", 2)):
        case = fixture["cases"][name]
        assert case["batch"] == batch and case["steps"] == MDN_FIXTURE_STEPS >= 40 and case["redraws_after_the_first"][-1] >= 1
        feeds = {k: np.array(v, np.int64 if k in ("steps", "held", "age", "max_hold", "min_hold") else np.float32).reshape(case["input_shapes"][k])
                 for k, v in case["inputs"].items()}
        got = dict(zip(MDN_OUTPUTS, session.run(MDN_OUTPUTS, feeds)))  # the listed inputs are exactly what gave the outputs
        for k in MDN_OUTPUTS:
            assert list(got[k].shape) == case["output_shapes"][k]
            assert np.abs(got[k].ravel() - np.array(case["outputs"][k])).max() < 1e-5
    assert fixture["cases"]["batch2"]["inputs"]["held"] == [-1, 0]


def test_the_exported_mdn_model_runs_as_the_page_runs_it(tiny_mdn, tmp_path):
    model, path = tiny_mdn
    filters = FILTERS
    tiny_export(path, tmp_path)
    dance = ShippedDance(tmp_path, "tiny-mdn")
    seeds = np.random.default_rng(0).normal(size=(3, 10, 6)).astype(np.float32)
    styles = ["salsa", "indian", "martial"]
    shown, drawn = dance.generate_mdn(seeds, styles, 70, seed=5)
    dance.STEPS_PER_CALL = 9
    shown9, drawn9 = dance.generate_mdn(seeds, styles, 70, seed=5)
    assert np.abs(drawn - drawn9).max() < 1e-4 and np.abs(shown - shown9).max() < 1e-4  # however the frames are split
    assert not np.allclose(drawn, dance.generate_mdn(seeds, styles, 70, seed=6)[1])
    # what is shown is each row's drawn frames through its style's filter, from rest on the last seed frame
    for r, s in enumerate(styles):
        assert np.abs(lowpass(drawn[r], *filters[s], initial=seeds[r, -1]) - shown[r]).max() < 1e-4
    # generate() of an mdn model gives the shown frames
    assert np.abs(dance.generate(seeds, styles, 70, seed=5) - shown9).max() < 1e-6


def test_the_mdn_reports_deterministic_prediction_is_the_most_likely_components_mean(tiny_mdn, tmp_path):
    from training.aclstm.report import MDN_MODE

    model, path = tiny_mdn
    tiny_export(path, tmp_path)
    dance = ShippedDance(tmp_path, "tiny-mdn")
    seeds = np.random.default_rng(2).normal(size=(2, 10, 6)).astype(np.float32)
    a = dance.generate_mdn(seeds, ["salsa", "martial"], 20, seed=1, override=MDN_MODE)[1]
    b = dance.generate_mdn(seeds, ["salsa", "martial"], 20, seed=2, override=MDN_MODE)[1]
    assert np.array_equal(a, b)
    # torch: each frame the argmax component's mean, fed back
    style = torch.eye(3)[[0, 2]]
    x = torch.from_numpy((seeds - 0.1) / 2.0)
    with torch.no_grad():
        logits, mu, _, state = model.mixture(x, style)
        for t in range(20):
            y = mu[torch.arange(2), -1, logits[:, -1].argmax(-1)]
            assert np.abs(y.numpy() * 2.0 + 0.1 - a[:, t]).max() < 1e-4
            logits, mu, _, state = model.mixture(y[:, None], style, state)


def test_evaluate_adds_a_row_only_when_measured_as_the_stored_report():
    import subprocess
    import sys

    from training.paths import REPO_ROOT

    stored = json.loads((REPO_ROOT / "docs" / "models" / "aclstm.json").read_text())
    done = subprocess.run([sys.executable, "-m", "training.aclstm.evaluate", "--add", "x=/nonexistent/aclstm-mdn.json",
                           "--frames", str(stored["frames_per_seed"] + 1)], cwd=REPO_ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode != 0 and f"--frames {stored['frames_per_seed']}" in done.stderr
