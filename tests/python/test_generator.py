"""Generator pieces: feature codec, mirroring, mixture likelihood, ONNX export parity, shipped model."""
import json
import math

import numpy as np
import pytest
import torch

from training.data.cmu import load_clip, read_index
from training.generator.exporting import estimate_initial_state
from training.generator.graph import check_parity, export_onnx
from training.data.features import FeatureCodec, heading_of, mirror_clip
from training.models.generator import MixtureLSTM, mixture_nll
from training.paths import MODELS_DIR
from training.mocap.rotations import quat_to_matrix
from training.mocap.skeleton import canonical_skeleton, forward_kinematics

SKEL = canonical_skeleton()


@pytest.fixture(scope="module")
def walk(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("16_22.amc.gz"))  # walk with a turn
    from training.data.cmu import clip_contacts
    clip = load_clip(mocap, info, 30)
    return clip, clip_contacts(clip)


def test_codec_round_trip_reproduces_positions(walk):
    clip, contacts = walk
    codec = FeatureCodec()
    codec.fit_references(clip.rotations)
    x = codec.encode(clip.root, clip.rotations, contacts)
    assert x.shape == (clip.frames - 1, codec.dim)
    start_heading = float(heading_of(quat_to_matrix(clip.rotations[0, 0])))
    pos = codec.positions(x, start_xz=clip.root[0, [0, 2]], start_heading=start_heading)
    assert np.abs(pos - clip.positions[1:]).max() < 1e-5
    assert np.array_equal(x[:, -2:], contacts[1:])
    # The walk turns, so heading changes are really used.
    assert np.abs(x[:, 2]).sum() > 0.5


def test_codec_is_invariant_to_where_the_clip_starts(walk):
    clip, contacts = walk
    codec = FeatureCodec()
    codec.fit_references(clip.rotations)
    x = codec.encode(clip.root, clip.rotations, contacts)
    turn = quat_to_matrix(np.array([0, math.sin(0.6), 0, math.cos(0.6)]))  # 1.2 rad about y
    from training.mocap.rotations import matrix_to_quat
    rot = clip.rotations.copy()
    rot[:, 0] = matrix_to_quat(turn @ quat_to_matrix(rot[:, 0]))
    root = clip.root @ turn.T + [3.0, 0, -2.0]
    assert np.allclose(codec.encode(root, rot, contacts), x, atol=1e-6)


def test_mirrored_clip_is_the_mirror_image(walk):
    clip, contacts = walk
    root, rot, con = mirror_clip(clip.root, clip.rotations, contacts)
    pos = forward_kinematics(SKEL, root, rot)
    expected = clip.positions[:, SKEL.mirror_map] * [-1, 1, 1]
    assert np.abs(pos - expected).max() < 1e-6
    assert np.array_equal(con, contacts[:, ::-1])


def test_mixture_nll_matches_a_single_gaussian():
    torch.manual_seed(0)
    mu, log_sigma, target = torch.randn(2, 3, 1, 4), torch.randn(2, 3, 1, 4) * 0.3, torch.randn(2, 3, 4)
    nll = mixture_nll(torch.zeros(2, 3, 1), mu, log_sigma, target)
    normal = torch.distributions.Normal(mu[..., 0, :], log_sigma[..., 0, :].exp())
    assert torch.allclose(nll, -normal.log_prob(target).sum(-1), atol=1e-5)


def test_mixture_nll_weights_components():
    # Two components, one far away: the likelihood is the weighted one of the near component.
    mu = torch.tensor([[[[0.0], [100.0]]]])
    log_sigma = torch.zeros(1, 1, 2, 1)
    logits = torch.log(torch.tensor([[[0.25, 0.75]]]))
    nll = mixture_nll(logits, mu, log_sigma, torch.zeros(1, 1, 1))
    assert float(nll) == pytest.approx(-math.log(0.25) + 0.5 * math.log(2 * math.pi), rel=1e-5)


def test_export_parity_and_dynamic_batch(tmp_path):
    torch.manual_seed(0)
    model = MixtureLSTM(dim=11, hidden=16).eval()
    path = tmp_path / "g.onnx"
    export_onnx(model, path)
    result = check_parity(model, path, steps=5)
    assert result["max_abs_diff"] < 1e-4 and result["batches"] == [1, 7]


def test_initial_state_estimate_makes_real_frames_more_likely():
    torch.manual_seed(0)
    model = MixtureLSTM(dim=6, hidden=12).eval()
    frames = torch.randn(5, 6)
    h, c, zero_nll, est_nll = estimate_initial_state(model, frames, iterations=100)
    assert h.shape == (2, 1, 12) and est_nll < zero_nll


@pytest.mark.skipif(not (MODELS_DIR / "generator.json").exists(), reason="no generator shipped yet")
def test_shipped_generator_runs_and_stays_finite():
    from training.generator.shipped import ShippedGenerator
    gen = ShippedGenerator(MODELS_DIR)
    info = json.loads((MODELS_DIR / "generator.json").read_text())
    assert info["bytes"] <= 8 * 1024 * 1024
    assert info["parity"]["max_abs_diff"] < 1e-4
    assert len(info["features"]["names"]) == info["onnx"]["dim"] == len(gen.mean)
    feats = gen.sample([0, 1], 300, rng=np.random.default_rng(0))
    assert np.isfinite(feats).all()
    pos = gen.positions(feats[0])
    lengths = np.linalg.norm(pos[:, 1:] - pos[:, SKEL.parents[1:]], axis=-1)
    assert np.allclose(lengths, np.linalg.norm(SKEL.offsets[1:], axis=-1), atol=1e-6)
    # Same seed and random stream, same motion.
    again = gen.sample([0, 1], 300, rng=np.random.default_rng(0))
    assert np.array_equal(feats, again)
