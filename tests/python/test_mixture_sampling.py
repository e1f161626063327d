"""The generator's mixture sampling (training/generator/sampling.py): the fixture the page is checked against is
current, and a batch's rows draw their own random numbers.

The fixture's draws are checked exactly against its own committed step outputs (numpy float64, the same on every
machine); the step outputs themselves against a fresh onnxruntime step within a tolerance, since onnxruntime's CPU
kernels may differ in the last bit between CPUs."""
import json

import numpy as np
import pytest

from training.fixtures.mixture_parity import BOUNDARY_MARGIN, OUT, boundary_distance, build_from, float32_values, step_outputs
from training.generator.sampling import choose_component, draw_mixture, held_normals, sample_mixture, snap_contacts


@pytest.fixture(scope="module")
def committed() -> dict:
    return json.loads(OUT.read_text())


def committed_arrays(data: dict) -> dict:
    """The fixture's step outputs of all rows as the float32 arrays they were written from."""
    B, M, D = data["batch"], data["mixtures"], data["dim"]
    f32 = lambda key, shape: np.array(data[key], np.float32).reshape(shape)  # noqa: E731
    return dict(w=f32("weights", (B, M)), mu=f32("mu", (B, M, D)), sigma=f32("sigma", (B, M, D)),
                mean=f32("mean", (D,)), std=f32("std", (D,)))


def test_mixture_fixture_draws_follow_from_its_inputs(committed):
    a = committed_arrays(committed)
    w, B, D = a["w"], committed["batch"], committed["dim"]
    for case in committed["cases"]:
        t, u = case["temperature"], np.array(case["u"])
        z = np.array(case["z"]).reshape(B, D)
        x = draw_mixture(w, a["mu"], a["sigma"], t, u, z)
        components = [int(w[b].argmax()) if t <= 0 else choose_component(w[b], t, u[b]) for b in range(B)]
        assert components == case["components"], t
        assert float32_values(x) == case["x"], t
        assert float32_values(snap_contacts(x, a["mean"], a["std"])[:, -2:]) == case["snapped_contacts"], t
        for ch in case["choices"]:
            assert [choose_component(w[ch["row"]], t, v) for v in ch["u"]] == ch["components"], (t, ch["row"])
        if t > 0:  # every stored uniform keeps its margin from a boundary, so exp/log rounding cannot flip a choice
            stored = [(b, v) for b, v in enumerate(case["u"])] + [(ch["row"], v) for ch in case["choices"] for v in ch["u"]]
            assert min(boundary_distance(w[b], t, v) for b, v in stored) >= BOUNDARY_MARGIN, t


def test_mixture_fixture_is_what_build_writes_for_its_step_outputs(committed):
    # The spread rows, uniforms, normals and choices as build draws them from the committed real rows.
    a, real = committed_arrays(committed), committed["real_rows"]
    out = dict(seeds=committed["rows"][:real], w=a["w"][:real], mu=a["mu"][:real], sigma=a["sigma"][:real],
               mean=a["mean"], std=a["std"])
    assert json.loads(json.dumps(build_from(out))) == committed


def test_mixture_fixture_step_outputs_match_the_shipped_generator(committed):
    a, real, fresh = committed_arrays(committed), committed["real_rows"], step_outputs()
    assert committed["rows"][:real] == fresh["seeds"]
    for key in ("w", "mu", "sigma"):
        np.testing.assert_allclose(a[key][:real], fresh[key], rtol=1e-5, atol=1e-6, err_msg=key)
    for key in ("mean", "std"):  # read from generator.json, no onnxruntime in between
        np.testing.assert_array_equal(a[key], fresh[key], err_msg=key)


def test_rows_of_a_batch_draw_their_own_normals():
    # Four identical rows: one shared normal vector would give four identical draws.
    w = np.tile(np.array([[0.5, 0.5]], np.float32), (4, 1))
    mu = np.zeros((4, 2, 3), np.float32)
    sigma = np.ones((4, 2, 3), np.float32)
    x = sample_mixture(w, mu, sigma, 1.0, np.random.default_rng(0))
    assert len({tuple(row) for row in x.tolist()}) == 4


def test_choose_component_follows_the_tempered_cumulative_weights():
    w = np.array([0.2, 0.3, 0.5])
    assert [choose_component(w, 1.0, u) for u in (0.0, 0.19, 0.21, 0.49, 0.51, 0.999)] == [0, 0, 1, 1, 2, 2]
    # τ = 0.5 squares the weights: 0.04, 0.09, 0.25 of 0.38.
    assert [choose_component(w, 0.5, u) for u in (0.10, 0.11, 0.33, 0.35)] == [0, 1, 1, 2]


def test_held_normals_drift_but_stay_standard_normal():
    rng = np.random.default_rng(0)
    fresh = rng.standard_normal((200, 4000))
    assert np.array_equal(held_normals(None, fresh[0], 0.9), fresh[0])  # a stream's first frame
    assert np.array_equal(held_normals(fresh[0], fresh[1], 0.0), fresh[1])  # correlation 0: the old sampler
    z, steps, values = None, [], []
    for n in fresh:
        new = held_normals(z, n, 0.9)
        if z is not None:
            steps.append(np.mean((new - z) ** 2))
        z = new
        values.append(z)
    assert abs(np.mean(steps) - 2 * (1 - 0.9)) < 0.01  # E[(z_t - z_{t-1})^2] = 2(1 - rho)
    assert abs(np.var(np.concatenate(values)) - 1) < 0.02
