"""The generator's mixture sampling (training/generator/sampling.py): the fixture the page is checked against is
current, and a batch's rows draw their own random numbers."""
import json

import numpy as np

from training.fixtures.mixture_parity import OUT, build
from training.generator.sampling import choose_component, sample_mixture


def test_mixture_fixture_is_current():
    committed = json.loads(OUT.read_text())
    assert json.loads(json.dumps(build())) == committed


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
