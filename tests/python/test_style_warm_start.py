"""The style generator's warm start (training/style_generator/warm_start.py): copied from the shipped generator and
rewritten for another normalisation, it must predict the same physical mixture for every style at the start."""
import numpy as np
import torch

from training.models.generator import MixtureLSTM
from training.style_generator.warm_start import shipped_generator, warm_start


def test_warm_started_model_predicts_what_the_shipped_generator_predicts():
    shipped, m1, s1 = shipped_generator()
    rng = np.random.default_rng(3)
    # Another normalisation, as the style corpus's (Bandai included) gives: shifted means, spreads 0.5-2x.
    m2 = m1 + rng.normal(0, 1, m1.shape) * s1
    s2 = s1 * rng.uniform(0.5, 2.0, s1.shape)
    model = MixtureLSTM(shipped.dim, shipped.hidden, shipped.mixtures, styles=8, style_dim=8).eval()
    warm_start(model, m2, s2)
    physical = rng.normal(m1, s1, (2, 12, shipped.dim))
    with torch.no_grad():
        l1, mu1, ls1, _ = shipped(torch.from_numpy(((physical - m1) / s1).astype(np.float32)))
        for style in (0, 5):
            l2, mu2, ls2, _ = model(torch.from_numpy(((physical - m2) / s2).astype(np.float32)), None,
                                    torch.tensor([style, style]))
            assert torch.allclose(l1, l2, atol=1e-4)
            mu1_phys = mu1.numpy() * s1 + m1
            mu2_phys = mu2.numpy() * s2 + m2
            assert np.allclose(mu1_phys, mu2_phys, atol=1e-3 * s1.max())
            # sigma in physical units, where the clamp at LOG_SIGMA_MIN does not bite
            sig1, sig2 = np.exp(ls1.numpy()) * s1, np.exp(ls2.numpy()) * s2
            free = (ls2.numpy() > -6.9) & (ls1.numpy() > -6.9)
            assert free.mean() > 0.9
            assert np.allclose(sig1[free], sig2[free], rtol=1e-3)
