"""The style-conditioned generator (issue 39): the style input of models/generator.py MixtureLSTM (absent by default,
so the shipped generator's network is unchanged) and data/style_locomotion.py's corpus (a style id per clip, held-out
clips in every style, each style drawn equally often)."""
import numpy as np
import pytest
import torch

from conftest import MOCAP
from training.data.bandai import BandaiClip, is_held_out, ranks, read_index
from training.data.locomotion import LocomotionClip
from training.data.style_locomotion import STYLES, StyleCorpus, sampling_weights, styled_clips
from training.models.generator import MixtureLSTM, StyledGenerator

# The shipped generator's network (public/models/generator.onnx: 69 features, width 192, 5 components), as it was
# before the style input existed.
SHIPPED_SHAPES = {
    "fc1.weight": (192, 69), "fc1.bias": (192,), "fc2.weight": (192, 192), "fc2.bias": (192,),
    "lstm.weight_ih_l0": (768, 192), "lstm.weight_hh_l0": (768, 192), "lstm.bias_ih_l0": (768,), "lstm.bias_hh_l0": (768,),
    "lstm.weight_ih_l1": (768, 192), "lstm.weight_hh_l1": (768, 192), "lstm.bias_ih_l1": (768,), "lstm.bias_hh_l1": (768,),
    "fc3.weight": (695, 192), "fc3.bias": (695,),
}


def test_the_default_model_is_the_shipped_network():
    model = MixtureLSTM(69, 192, 5)
    assert {k: tuple(v.shape) for k, v in model.state_dict().items()} == SHIPPED_SHAPES
    assert list(model.state_dict()) == list(SHIPPED_SHAPES)  # same order too
    assert sum(p.numel() for p in model.parameters()) == 777_527  # docs/models/generator.md
    with pytest.raises(ValueError, match="no style input"):
        model(torch.zeros(1, 2, 69), None, torch.tensor([0]))


def test_a_style_model_adds_one_embedding_per_style_to_the_input():
    model = MixtureLSTM(69, 192, 5, styles=8, style_dim=8)
    shapes = {k: tuple(v.shape) for k, v in model.state_dict().items()}
    assert shapes == {**SHIPPED_SHAPES, "fc1.weight": (192, 77), "style.weight": (8, 8)}
    with pytest.raises(ValueError, match="pass style ids"):
        model(torch.zeros(1, 2, 69))


def test_a_style_changes_the_output():
    torch.manual_seed(0)
    model = MixtureLSTM(12, 32, 3, styles=8).eval()
    x = torch.randn(2, 5, 12)
    out = lambda s: model(x, None, torch.tensor(s))
    a, b, again = out([1, 1]), out([2, 2]), out([1, 1])
    for k in range(3):  # logits, mu, log sigma
        assert torch.equal(a[k], again[k])
        assert (a[k] - b[k]).abs().max() > 1e-3
    mixed = out([1, 2])  # each window its own style
    assert torch.allclose(mixed[1][0], a[1][0]) and torch.allclose(mixed[1][1], b[1][1])
    # the fixed-style wrapper is the model with that style
    assert torch.equal(StyledGenerator(model, 2)(x)[1], b[1])


def still_clip(frames: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    root = np.tile([0.0, 0.93, 0.0], (frames, 1))
    root[:, 2] = np.linspace(0, 0.3, frames)  # walking forward a little
    rotations = np.zeros((frames, 25, 4))
    rotations[..., 3] = 1.0
    return root, rotations, np.ones((frames, 2), np.uint8)


@pytest.fixture(scope="module")
def corpus_clips():
    """Every Bandai clip of the index and 20 CMU walks and 10 runs, with still motion: the split and the style labels
    are what is tested, not the motion."""
    index = read_index(MOCAP)
    rank = ranks(index)
    bandai = [BandaiClip(i.file, i.content, i.style, rank[i.file], *still_clip()[:2], np.zeros((8, 25, 3)), still_clip()[2])
              for i in index]
    cmu = [LocomotionClip(f"{cat}_{k:02d}", "01", cat, "", k, *still_clip())
           for cat, n in (("walk", 20), ("run", 10)) for k in range(n)]
    return styled_clips(cmu, bandai), index


def test_the_corpus_gives_every_style_held_out_clips(corpus_clips):
    clips, index = corpus_clips
    corpus = StyleCorpus(clips, speed_factors=(1.0,))
    assert sorted(set(corpus.valid_styles.tolist())) == list(range(len(STYLES)))
    held = {(STYLES[s], c) for s, c in zip(corpus.valid_styles, corpus.valid_contents)}
    for i in index:  # every Bandai style keeps held-out clips of every content
        assert (i.style, i.content) in held
    rank = ranks(index)
    expected = sorted(i.file for i in index if is_held_out(rank[i.file]))
    assert sorted(f for f, s in zip(corpus.valid_files, corpus.valid_styles) if s > 0) == expected
    assert sorted(f for f, s in zip(corpus.valid_files, corpus.valid_styles) if s == 0) == ["run_03", "walk_03", "walk_11", "walk_19"]
    # training clips: every style, mirrored, none held out
    assert len(corpus.train) == 2 * (len(clips) - len(corpus.valid))
    assert sorted(set(corpus.train_styles.tolist())) == list(range(len(STYLES)))


def test_each_style_is_drawn_equally_often(corpus_clips):
    clips, _ = corpus_clips
    corpus = StyleCorpus(clips, speed_factors=(1.0,))
    share = [corpus.weights[corpus.train_styles == s].sum() for s in range(len(STYLES))]
    assert np.allclose(share, 1 / len(STYLES))
    _, _, style = corpus.batch(np.random.default_rng(0), 4000, 4)
    counts = np.bincount(style.numpy(), minlength=len(STYLES)) / 4000
    assert np.abs(counts - 1 / len(STYLES)).max() < 0.03
    # within a style, in proportion to the (weighted) frames
    w = sampling_weights(np.array([0, 0, 1]), np.array([1.0, 3.0, 5.0]))
    assert np.allclose(w, [0.125, 0.375, 0.5])
    # or CMU with a share of its own, the Bandai styles splitting the rest
    w = sampling_weights(np.array([0, 0, 1, 2]), np.array([1.0, 3.0, 5.0, 1.0]), cmu_share=0.5)
    assert np.allclose(w, [0.125, 0.375, 0.25, 0.25])
    corpus = StyleCorpus(clips, speed_factors=(1.0,), mirror=False, cmu_share=0.25)
    assert np.isclose(corpus.weights[corpus.train_styles == 0].sum(), 0.25)
    assert np.allclose([corpus.weights[corpus.train_styles == s].sum() for s in range(1, len(STYLES))], 0.75 / 7)
    with pytest.raises(ValueError, match="cmu_share"):
        sampling_weights(np.array([1, 2]), np.array([1.0, 1.0]), cmu_share=0.5)
