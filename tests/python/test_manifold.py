"""The motion manifold's data rows, the autoencoder's exported decoder, the latent ERD's online stream, and the
shipped files' agreement with them."""
import json

import numpy as np
import onnx
import pytest
import torch

from conftest import REPO
from training.autoencoder.exporting import RADIUS, ValidDecoder, autoencoder_from_onnx, decode_clip, export_graphs
from training.autoencoder.exporting import check_parity as autoencoder_parity
from training.data.locomotion import load_clips
from training.data.windows import CONTROL_SLICE, ROW_DIM, ground_frame, motion_rows, rows_to_world
from training.latent_erd.exporting import ERDStep, check_parity, erd_from_onnx, export_step
from training.latent_erd.streaming import LatentStream, Normalisation, OnnxBackend, Root, TorchBackend, run_stream
from training.models.autoencoder import POOLING, MotionAutoencoder, masked_noise
from training.models.erd import ControlERD
from training.onnx.compact import weight_format

MODELS = REPO / "public" / "models"


@pytest.fixture(scope="module")
def clip(mocap):
    return next(c for c in load_clips(str(mocap)) if c.frames >= 200)


def test_rows_place_the_clip_back_where_it_was(clip):
    from training.mocap.skeleton import canonical_skeleton, forward_kinematics
    pos = forward_kinematics(canonical_skeleton(), clip.root, clip.rotations)
    rows = motion_rows(pos, clip.contacts)
    assert rows.shape == (clip.frames, ROW_DIM)
    xz, heading = ground_frame(pos)
    back = rows_to_world(rows, start_xz=xz[0], start_heading=heading[0])
    assert np.abs(back - pos).max() < 1e-9
    # The control is the course, not each step's sway: the turn rate is smooth.
    turn = rows[:, CONTROL_SLICE][:, 2]
    assert np.abs(np.diff(turn)).max() < 1.0


def small_models(seed=0):
    torch.manual_seed(seed)
    ae = MotionAutoencoder(ROW_DIM, hidden=8, latent=16).eval()
    erd = ControlERD(16, 12, hidden=8, layers=3).eval()
    return ae, erd


def test_unpadded_decoder_is_the_trained_decoder_inside_a_sequence():
    ae, _ = small_models()
    z = torch.randn(2, 30, 16).abs()
    with torch.no_grad():
        full, valid = ae.decode(z), ValidDecoder(ae)(z)
    assert valid.shape[1] == POOLING * (30 - 2 * RADIUS)
    np.testing.assert_allclose(valid.numpy(), full[:, POOLING * RADIUS: POOLING * RADIUS + valid.shape[1]].numpy(), atol=1e-5)
    # A window of 2R+1 steps gives exactly the 4 frames of its centre step; a padded clip gives every frame.
    assert ValidDecoder(ae)(z[:, :2 * RADIUS + 1]).shape[1] == POOLING
    assert decode_clip(ae, z[0].numpy()).shape == (POOLING * 30, ROW_DIM)


def test_masked_noise_keeps_the_scale():
    x = torch.ones(200, 200)
    y = masked_noise(x, 0.3)
    assert 0.25 < float((y == 0).float().mean()) < 0.35
    assert abs(float(y.mean()) - 1.0) < 0.05


def stream(backend, erd, seed=0):
    rng = np.random.default_rng(seed)
    norm = Normalisation(rng.normal(size=16), np.full(16, 0.5), np.zeros(ROW_DIM), np.ones(ROW_DIM))
    return LatentStream(backend, norm, rng.normal(size=(4, 16)).astype(np.float32), rng.normal(size=(4, 12)).astype(np.float32),
                        (erd.layers, erd.hidden), 30.0, 3, Root(1.0, -2.0, 0.5))


def test_the_exported_stream_matches_torch(tmp_path):
    ae, erd = small_models()
    export_graphs(ae, tmp_path / "enc.onnx", tmp_path / "dec.onnx")
    export_step(erd, tmp_path / "erd.onnx")
    assert check_parity(erd, tmp_path / "erd.onnx") < 1e-4
    control = np.tile([[1.0, 0.1, 0.4]], (24, 1))
    a = run_stream(stream(TorchBackend(erd, ae), erd), control)
    b = run_stream(stream(OnnxBackend(tmp_path / "erd.onnx", tmp_path / "dec.onnx"), erd), control)
    assert a.positions.shape == (24, 25, 3)
    np.testing.assert_allclose(a.rows, b.rows, atol=1e-4)
    np.testing.assert_allclose(a.positions, b.positions, atol=1e-4)


def test_the_look_ahead_and_the_control_change_the_stream():
    ae, erd = small_models()
    control = np.tile([[1.0, 0.0, 0.0]], (16, 1))
    base = run_stream(stream(TorchBackend(erd, ae), erd), control)
    s = stream(TorchBackend(erd, ae), erd)
    s.lookahead = 0
    assert np.abs(run_stream(s, control).rows - base.rows).max() > 1e-4
    turned = run_stream(stream(TorchBackend(erd, ae), erd), control + [0.0, 0.0, 1.0])
    assert np.abs(turned.rows - base.rows).max() > 1e-4
    # The root moves by the decoded frames' own control channels.
    r = base.rows[0, CONTROL_SLICE] / 30.0
    c, s_ = np.cos(0.5), np.sin(0.5)
    np.testing.assert_allclose(base.roots[1, :2], [1.0 + c * r[1] + s_ * r[0], -2.0 - s_ * r[1] + c * r[0]], atol=1e-9)


@pytest.mark.parametrize("fmt", ["float32", "float16", "int8"])
def test_the_erd_reads_back_from_its_export_whatever_its_weights(tmp_path, fmt):
    """export_step returns the ERD the file computes (torch with the weights as stored): the parity reference."""
    torch.manual_seed(4)
    erd = ControlERD(16, 12, hidden=32, layers=3).eval()  # every LSTM weight >= 4096 values: stored as fmt
    erd.set_range(-torch.rand(16) - 0.5, torch.rand(16) + 0.5)
    path = tmp_path / "erd.onnx"
    stored = export_step(erd, path, fmt)
    assert weight_format(onnx.load(str(path))) == fmt
    assert check_parity(stored, path) < 1e-4
    z, control = torch.randn(3, 16), torch.randn(3, 12)
    h, c = (0.3 * torch.randn(3, 3, 32) for _ in range(2))
    with torch.no_grad():
        a, b = ERDStep(erd)(z, control, h, c), ERDStep(stored)(z, control, h, c)
    worst = max(float((x - y).abs().max()) for x, y in zip(a, b))
    assert worst < {"float32": 1e-6, "float16": 1e-2, "int8": 5e-2}[fmt]
    if fmt == "float32":
        for name, value in erd.state_dict().items():
            torch.testing.assert_close(stored.state_dict()[name], value, rtol=0, atol=0)
    else:
        assert worst > 0  # lossy, within the format's step


def test_the_autoencoder_exports_int8_and_reads_back(tmp_path):
    torch.manual_seed(5)
    ae = MotionAutoencoder(ROW_DIM, hidden=8, latent=16).eval()
    enc, dec = tmp_path / "enc.onnx", tmp_path / "dec.onnx"
    stored = export_graphs(ae, enc, dec, "int8")
    assert weight_format(onnx.load(str(enc))) == weight_format(onnx.load(str(dec))) == "int8"
    windows = torch.randn(3, 4 * (2 * RADIUS + 3), ROW_DIM).numpy()
    assert max(autoencoder_parity(stored, enc, dec, windows).values()) < 1e-4
    again = autoencoder_from_onnx(enc, dec, ROW_DIM, 8, 16)
    for name, value in stored.state_dict().items():
        torch.testing.assert_close(again.state_dict()[name], value, rtol=0, atol=0)
    with torch.no_grad():
        x = torch.from_numpy(windows)
        assert float((ae(x)[0] - stored(x)[0]).abs().max()) < 5e-2


def test_shipped_latent_erd_files_agree():
    info = json.loads((MODELS / "latent-erd.json").read_text())
    manifold = json.loads((MODELS / "manifold.json").read_text())
    assert info["latent"] == manifold["latent"] and info["radius"] == manifold["radius"] == RADIUS
    assert manifold["rows"]["dim"] == ROW_DIM and len(manifold["normalisation"]["mean"]) == ROW_DIM
    from training.latent_erd.exporting import SEED_STEPS
    assert all(np.array(s["latents"]).shape == (SEED_STEPS, info["latent"]) for s in info["seeds"])
    for name in ("latent-erd.onnx", "manifold-encoder.onnx", "manifold-decoder.onnx"):
        assert (MODELS / name).stat().st_size <= 8 * 1024 * 1024, name
    # The JSONs say how the files store their weights and what the parity was checked against.
    assert info["weights"] == weight_format(onnx.load(str(MODELS / info["file"])))
    assert manifold["weights"] == weight_format(onnx.load(str(MODELS / manifold["files"]["encoder"])))
    assert info["bytes"] == (MODELS / info["file"]).stat().st_size
    assert manifold["bytes"] == sum((MODELS / f).stat().st_size for f in manifold["files"].values())
    for parity_of in (info, manifold):
        assert parity_of["parity_reference"] == f"torch with the weights as stored ({parity_of['weights']})"
    index = {m["id"]: m for m in json.loads((MODELS / "index.json").read_text())["models"]}
    assert index["latent-erd"]["kind"] == "latent-erd" and index["manifold"]["kind"] == "autoencoder"


def test_the_shipped_networks_read_back_from_their_files():
    """What --from-shipped starts from: the ERD and the autoencoder rebuilt in torch compute what the files compute."""
    info = json.loads((MODELS / "latent-erd.json").read_text())
    erd = erd_from_onnx(MODELS / info["file"], info["latent"], info["control_dim"], info["hidden"], info["layers"])
    assert check_parity(erd, MODELS / info["file"], steps=5) < 1e-4
    manifold = json.loads((MODELS / "manifold.json").read_text())
    enc, dec = (MODELS / manifold["files"][k] for k in ("encoder", "decoder"))
    ae = autoencoder_from_onnx(enc, dec, manifold["rows"]["dim"], manifold["hidden"], manifold["latent"])
    windows = np.random.default_rng(0).normal(size=(1, 4 * (2 * RADIUS + 3), ROW_DIM)).astype(np.float32)
    assert max(autoencoder_parity(ae, enc, dec, windows).values()) < 1e-4


def test_shipped_seeds_carry_the_control_as_the_erd_reads_it(mocap):
    """Each seed's controls are its held-out clip's signal smoothed as in training (control_smoothing_frames)."""
    from training.data.windows import WindowCorpus
    from training.latent_erd.sequences import step_control
    info = json.loads((MODELS / "latent-erd.json").read_text())
    sigma = info["control_smoothing_frames"]
    corpus = WindowCorpus(load_clips(str(mocap)))
    for seed in info["seeds"]:
        i = next(k for k, c in enumerate(corpus.valid_clips) if c.file == seed["file"])
        rows = corpus.valid[i]
        steps = len(rows) // POOLING
        start = min(steps // 3, steps - len(seed["controls"]))
        want = step_control(rows, steps, sigma)[start:start + len(seed["controls"])]
        np.testing.assert_allclose(seed["controls"], want, atol=1e-5)
        if sigma > 0:  # and not the raw signal, which sways with the stride
            assert np.abs(step_control(rows, steps)[start:start + len(seed["controls"])] - want).max() > 1e-3
