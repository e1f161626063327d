"""The acLSTM's mixture-density head and phrase-scale sampling (issue 42), and the older heads left as they were."""
import pytest
import torch

from training.aclstm.phrase_sampling import PhraseParams, PhraseSampler
from training.models.aclstm import DanceLSTM, mixture_nll


def tiny_batch():
    g = torch.Generator().manual_seed(0)
    t = torch.linspace(0, 6, 21)
    x = torch.stack([torch.stack([torch.sin(t * (1 + k) + b) for k in range(6)], -1) for b in range(4)])
    return x + 0.05 * torch.randn(x.shape, generator=g), torch.eye(3)[[0, 1, 2, 0]]


def test_mdn_loss_is_finite_and_decreases_on_a_tiny_batch():
    torch.manual_seed(0)
    model = DanceLSTM(6, 3, hidden=32, layers=2, head="mdn", components=4)
    x, style = tiny_batch()
    optimiser = torch.optim.Adam(model.parameters(), lr=3e-3)
    losses = []
    for _ in range(60):
        logits, mu, log_sigma = model.auto_conditioned_mixture(x[:, :-1], style, 5, 5, 1.0, torch.Generator().manual_seed(1))
        assert logits.shape == (4, 20, 4) and mu.shape == log_sigma.shape == (4, 20, 4, 6)
        loss = mixture_nll(logits, mu, log_sigma, x[:, 1:])
        assert torch.isfinite(loss)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        losses.append(loss.item())
    assert losses[-1] < losses[0] - 0.5


def test_mixture_nll_of_one_component_is_the_gaussian_heads_loss():
    g = torch.Generator().manual_seed(3)
    mu, log_sigma, target = (torch.randn(5, 7, generator=g) for _ in range(3))
    gauss = (0.5 * ((target - mu) * torch.exp(-log_sigma)) ** 2 + log_sigma).mean()
    mdn = mixture_nll(torch.zeros(5, 1), mu.unsqueeze(1), log_sigma.unsqueeze(1), target)
    assert mdn.item() == pytest.approx(gauss.item(), rel=1e-5)


def test_auto_conditioned_mixture_feeds_back_its_own_draws():
    torch.manual_seed(0)
    model = DanceLSTM(6, 3, hidden=16, layers=2, head="mdn", components=3)
    x, style = tiny_batch()
    a = model.auto_conditioned_mixture(x[:, :-1], style, 5, 5, 1.0, torch.Generator().manual_seed(1))[1]
    b = model.auto_conditioned_mixture(x[:, :-1], style, 5, 5, 1.0, torch.Generator().manual_seed(1))[1]
    c = model.auto_conditioned_mixture(x[:, :-1], style, 5, 5, 1.0, torch.Generator().manual_seed(2))[1]
    tf = model.auto_conditioned_mixture(x[:, :-1], style, 5, 0)[1]
    assert torch.equal(a, b)
    # Same while reading real frames (positions 0-4), then the draws differ.
    assert torch.allclose(a[:, :5], tf[:, :5], atol=1e-6) and not torch.allclose(a[:, 5:], tf[:, 5:])
    assert not torch.allclose(a[:, 5:], c[:, 5:])


def mixture_of(weights, dim=2):
    logits = torch.log(torch.tensor(weights)).unsqueeze(0).repeat(2, 1)
    k = logits.shape[-1]
    mu = (torch.arange(k, dtype=torch.float32) * 10).view(1, k, 1).expand(2, k, dim).clone()
    return logits, mu, torch.full((2, k, dim), -3.0)


def test_phrase_sampler_holds_a_component_for_a_phrase_and_redraws():
    params = [PhraseParams(temperature=0.5, max_hold=8, rho=0.9, threshold=0.05, min_hold=2)] * 2
    sampler = PhraseSampler(params, 2, torch.Generator().manual_seed(0))
    logits, mu, log_sigma = mixture_of([0.25, 0.25, 0.25, 0.25])
    comps = []
    for _ in range(40):
        y = sampler.step(logits, mu, log_sigma)
        comps.append(torch.round(y[:, 0] / 10).long())  # the component a frame came from (means 10 apart, σ small)
    comps = torch.stack(comps)  # (40, 2)
    for row in range(2):
        for start in range(0, 40, 8):
            assert len(set(comps[start:start + 8, row].tolist())) == 1  # held for the whole phrase of 8 frames
        assert len(set(comps[:, row].tolist())) > 1  # and redrawn
    assert sampler.redraws.tolist() == [5, 5]
    # The held component's weight falls below the threshold: redrawn at once (after min_hold), among the others.
    held = sampler.held.clone()
    w = [0.3] * 4
    w[held[0]] = 0.01
    logits, mu, log_sigma = mixture_of([x / sum(w) for x in w])
    sampler.age[:] = 3
    y = sampler.step(logits, mu, log_sigma)
    assert sampler.held[0] != held[0] and torch.round(y[0, 0] / 10).long() == sampler.held[0]


def test_phrase_sampler_noise_is_correlated_over_frames():
    params = [PhraseParams(temperature=1.0, max_hold=1000, rho=0.95, threshold=0.0, min_hold=0)]
    sampler = PhraseSampler(params, 200, torch.Generator().manual_seed(0))
    logits, mu, log_sigma = torch.zeros(1, 1), torch.zeros(1, 1, 200), torch.zeros(1, 1, 200)
    ys = torch.stack([sampler.step(logits, mu, log_sigma)[0] for _ in range(300)])
    lag1 = (ys[1:] * ys[:-1]).mean() / (ys ** 2).mean()
    assert 0.9 < lag1.item() < 1.0 and 0.8 < ys.std().item() < 1.2


@pytest.mark.parametrize("head,sums", [("mean", (8.458335876464844, 8.641682624816895, 27.51366424560547)),
                                       ("gauss", (2.0350494384765625, 2.045313835144043, 16.53900146484375))])
def test_the_older_heads_are_unchanged(head, sums):
    """Numbers from the heads before the mdn head was added (training/models/aclstm.py at a3cf659)."""
    torch.manual_seed(0)
    m = DanceLSTM(6, 3, hidden=16, layers=2, head=head)
    assert [tuple(p.shape) for p in m.parameters()][-2:] == [(6 if head == "mean" else 12, 16), (6 if head == "mean" else 12,)]
    g = torch.Generator().manual_seed(0)
    x, s = torch.randn(2, 12, 6, generator=g), torch.eye(3)[[0, 2]]
    with torch.no_grad():
        torch.manual_seed(1)
        a = m.auto_conditioned(x, s, 3, 3)
        y, _ = m(x, s, sample=True, generator=torch.Generator().manual_seed(2), temperature=0.5)
    assert (a.sum().item(), y.sum().item(), a.abs().sum().item()) == pytest.approx(sums, rel=1e-6)
