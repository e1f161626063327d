"""Drawing the generator's next frame from its Gaussian mixture output, the same way the page does
(web/model/sampler.ts: chooseComponent, sampleMixture, snapContacts). The arithmetic follows the page's step by
step in float64, so given the same uniforms and normals both sides pick the same component and the same values;
tests/fixtures/mixture_parity.json (python -m training.fixtures.mixture) checks it.
"""
from __future__ import annotations

import numpy as np

WEIGHT_FLOOR = 1e-12  # log(max(w, floor)): a zero weight stays finite under the temperature
# How much of each frame's normals carries over to the next (generator.json "sampling"): drawn anew every frame the
# per-frame noise made sampled walking shake at 3x real motion's jitter. Chosen by measurement in
# docs/models/generator.md ("Noise held over frames").
NOISE_CORRELATION = 0.8


def tempered_weights(w: np.ndarray, temperature: float) -> np.ndarray:
    """w^(1/τ) of one row through logs, shifted by the largest, so a small τ cannot underflow every weight to 0."""
    logits = np.log(np.maximum(np.asarray(w, np.float64), WEIGHT_FLOOR)) / temperature
    return np.exp(logits - logits.max())


def choose_component(w: np.ndarray, temperature: float, u: float) -> int:
    """The component a uniform u in [0, 1) picks when component k has probability ∝ w_k^(1/τ), τ > 0: the
    cumulative walk over the tempered weights, summed in order as the page sums them."""
    p = tempered_weights(w, temperature)
    total = 0.0
    for v in p:
        total += v
    left = u * total
    for k, v in enumerate(p):
        left -= v
        if left < 0:
            return k
    return len(p) - 1


def draw_mixture(w: np.ndarray, mu: np.ndarray, sigma: np.ndarray, temperature: float,
                 u: np.ndarray | None = None, z: np.ndarray | None = None) -> np.ndarray:
    """One draw per row of w (B, M), mu and sigma (B, M, D): component k = choose_component(w_b, τ, u_b), then
    mu_k + sigma_k·τ·z_b with z (B, D) standard normals. τ ≤ 0 takes the heaviest component's mean (u and z unused)."""
    rows = np.arange(len(w))
    if temperature <= 0:
        return mu[rows, w.argmax(axis=1)].astype(np.float32)
    k = np.array([choose_component(w[b], temperature, u[b]) for b in rows])
    x = mu[rows, k].astype(np.float64) + sigma[rows, k].astype(np.float64) * temperature * np.asarray(z, np.float64)
    return x.astype(np.float32)


def held_normals(previous: np.ndarray | None, fresh: np.ndarray, correlation: float) -> np.ndarray:
    """Standard normals that drift instead of jumping: correlation·previous + sqrt(1 − correlation²)·fresh, an AR(1)
    sequence whose every value is still N(0, 1). Without previous normals (a stream's first frame) the fresh ones.
    Correlation 0 gives the fresh ones exactly. float64, as the page computes it (web/model/sampler.ts heldNormals)."""
    fresh = np.asarray(fresh, np.float64)
    if previous is None:
        return fresh.copy()
    return correlation * np.asarray(previous, np.float64) + np.sqrt(1.0 - correlation * correlation) * fresh


def sample_mixture(w: np.ndarray, mu: np.ndarray, sigma: np.ndarray, temperature: float, rng: np.random.Generator) -> np.ndarray:
    """draw_mixture with each row's own uniform and its own D normals from `rng`."""
    if temperature <= 0:
        return draw_mixture(w, mu, sigma, temperature)
    return draw_mixture(w, mu, sigma, temperature, rng.random(len(w)), rng.standard_normal((len(w), mu.shape[-1])))


def snap_contacts(x: np.ndarray, mean: np.ndarray, std: np.ndarray) -> np.ndarray:
    """Contacts are bits: the last two (normalised) values of each row become the normalised 0 or 1, whichever the
    de-normalised value is nearer to (threshold 0.5). Returns a new array."""
    mean, std = np.asarray(mean[-2:], np.float64), np.asarray(std[-2:], np.float64)
    out = x.copy()
    on = x[:, -2:].astype(np.float64) * std + mean > 0.5
    out[:, -2:] = ((on - mean) / std).astype(x.dtype)
    return out
