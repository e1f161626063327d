"""The VAE-LSTM's pieces: the cell of eqs. 7-9 in its two modes, generation chunk by chunk against one pass, the
4-frame posterior seed, the shipped export against its fixture, the page's z1 draws (control.Rng.normal), a
training step that lowers the loss on a fixed batch, and the network read back from its ONNX graphs (recovery.py)
in each weight format, the shipped int8 files included."""
import json

import numpy as np
import onnx
import pytest
import torch

from conftest import REPO
from training.control import Rng
from training.data.windows import CONTACT_SLICE, CONTROL_SLICE, ROW_DIM
from training.models.vae_lstm import POOLING, VaeLstm
from training.vae_lstm.exporting import FILES, PRIOR_FIXTURE_SEED, check_parity, export_graphs, files_format, generate_rows
from training.vae_lstm.generation import SEED_FRAMES, SEED_PAD, free_latents, prior_latents, seed_window
from training.vae_lstm.measures import ShippedVae
from training.models.losses import energy_loss
from training.vae_lstm.recovery import vae_lstm_from_onnx
from training.vae_lstm.stride import fit_stride, phase_start, stride_sway
from training.vae_lstm.training import kl_per_step, losses

FIXTURE = REPO / "tests" / "fixtures" / "vae_lstm_reference.json"


@pytest.fixture(scope="module")
def model() -> VaeLstm:
    torch.manual_seed(0)
    return VaeLstm(ROW_DIM, latent=16, control_features=8, inference_features=12, decoder_hidden=8).eval()


def test_teacher_mode_reads_the_latents_and_free_mode_its_own_state(model):
    hc = torch.randn(2, 6, 8)
    z = torch.randn(2, 6, 16)
    with torch.no_grad():
        teacher, _ = model.cell.run(z[:, 0], hc, latents=z)
        free, last = model.cell.run(z[:, 0], hc)
    # The first step is the same in both (its previous state is z1 either way); later steps differ.
    torch.testing.assert_close(teacher[:, 0], free[:, 0])
    assert float((teacher[:, 1:] - free[:, 1:]).abs().max()) > 1e-3
    torch.testing.assert_close(last, free[:, -1])
    # Free mode: step t's content is step t-1's output, so rerunning from any state continues the canvas.
    with torch.no_grad():
        again, _ = model.cell.run(free[:, 2], hc[:, 3:])
    torch.testing.assert_close(again, free[:, 3:])


def test_generation_in_chunks_equals_one_pass(model):
    frames = 4 * 70  # 70 steps: more than two chunks of 30
    control = np.random.default_rng(0).normal(size=(frames, 3)).astype(np.float32)
    z1 = np.random.default_rng(1).normal(size=16).astype(np.float32)
    chunked = generate_rows(model, control, z1)
    with torch.no_grad():
        whole = model.generate(torch.from_numpy(control[None]), torch.from_numpy(z1[None])).numpy()[0]
    assert chunked.shape == (frames, ROW_DIM)
    np.testing.assert_allclose(chunked, whole, atol=1e-5)
    # With z1 also a share of every step's content (a model trained with --free-mix), as the page runs it.
    zs, mix = free_latents(z1, frames // 4, {"mode": "z1", "mix": 0.3})
    mixed = generate_rows(model, control, z1, zs, mix)
    with torch.no_grad():
        whole_mixed = model.generate(torch.from_numpy(control[None]), torch.from_numpy(z1[None]), 0.3).numpy()[0]
    np.testing.assert_allclose(mixed, whole_mixed, atol=1e-5)
    assert float(np.abs(mixed - chunked).max()) > 1e-3


def test_the_posterior_seed_repeats_the_fourth_frame():
    frames = torch.randn(3, SEED_FRAMES, ROW_DIM)
    padded = seed_window(frames)
    assert padded.shape == (3, SEED_PAD, ROW_DIM)
    torch.testing.assert_close(padded[:, :SEED_FRAMES], frames)
    assert bool((padded[:, SEED_FRAMES:] == frames[:, -1:]).all())


def test_kl_is_zero_at_the_prior_and_energy_sees_a_frozen_window():
    assert float(kl_per_step(torch.zeros(2, 3, 5), torch.zeros(2, 3, 5)).abs().max()) == 0
    assert float(kl_per_step(torch.ones(1, 1, 5), torch.zeros(1, 1, 5))) == pytest.approx(2.5)
    t = torch.arange(120, dtype=torch.float32)
    stride = torch.sin(2 * np.pi * t / 30)[None, :, None].repeat(2, 1, 4)
    assert float(energy_loss(torch.roll(stride, 7, dims=1), stride)) < 1e-3  # out of phase, the same energy
    assert float(energy_loss(torch.zeros_like(stride), stride)) > 0.01


def test_a_training_step_lowers_the_loss_on_a_fixed_batch():
    torch.manual_seed(1)
    net = VaeLstm(ROW_DIM, latent=16, control_features=8, inference_features=12, decoder_hidden=8, dropout=0.0)
    x = torch.randn(4, 40, ROW_DIM) * 0.3
    c = torch.randn(4, 40, 3) * 0.3
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    first = None
    for _ in range(30):
        t = losses(net, x, c)
        loss = t["teacher"] + t["free"] + 0.01 * (t["kl"] + t["kl_first"]) / (POOLING * ROW_DIM)
        first = float(loss) if first is None else first
        opt.zero_grad()
        loss.backward()
        opt.step()
    assert float(loss) < 0.8 * first


def test_the_prior_draws_are_the_fixture_s_and_correlated_as_asked():
    p = json.loads(FIXTURE.read_text())["prior"]
    assert p["seed"] == PRIOR_FIXTURE_SEED
    rng = Rng(p["seed"])
    np.testing.assert_allclose([rng.normal() for _ in p["z1"]], p["z1"], atol=1e-6)
    z1, zs = prior_latents(p["seed"], len(p["z1"]), len(p["steps"]), p["rho"])
    np.testing.assert_allclose(zs, p["steps"], atol=1e-6)
    np.testing.assert_array_equal(zs[0], z1)
    _, long = prior_latents(5, 64, 400, 0.9)
    lag1 = float((long[1:] * long[:-1]).mean() / (long ** 2).mean())
    assert abs(lag1 - 0.9) < 0.03 and abs(float(long.std()) - 1) < 0.1


def test_a_z1_prior_picks_a_start_by_the_first_uniform_and_draws_around_it():
    prior = {"kind": "posteriors", "means": [[10.0, 10.0, 10.0], [-10.0, 0.0, 5.0]], "sigma": [0.5, 0.0, 2.0]}
    for seed in range(6):
        replay = Rng(seed)
        k = int(replay.uniform() * 2)
        expected = [prior["means"][k][i] + prior["sigma"][i] * replay.normal() for i in range(3)]
        z1, _ = prior_latents(seed, 3, z1_prior=prior)
        np.testing.assert_allclose(z1, expected, atol=1e-5)
        assert z1[1] == prior["means"][k][1]  # sigma 0: exactly the start
    # The shipped JSON's prior and the draws the page is checked against (fixture "shipped_prior").
    info = json.loads((REPO / "public" / "models" / "vae-lstm.json").read_text())
    shipped = json.loads(FIXTURE.read_text())["shipped_prior"]
    assert shipped["z1_prior"] and len(info["sampling"]["z1_prior"]["means"]) == info["sampling"]["z1_prior"]["starts"]
    for seed, z1 in shipped["z1"].items():
        np.testing.assert_array_equal(prior_latents(int(seed), info["latent"], z1_prior=info["sampling"]["z1_prior"])[0], np.float32(z1))


def test_the_stride_sway_follows_its_bands_and_period():
    shape = [[float(i), 0.0, -float(i)] for i in range(4)]
    stride = {"phase_bins": 4, "bands": [{"speed": 1.0, "period_s": 0.4, "sway": shape},
                                         {"speed": 2.0, "period_s": 0.2, "sway": [[2 * a, b, 2 * c] for a, b, c in shape]}]}
    # At 1 m/s, 10 fps: a period of 4 frames, so phase bins 0, 1, 2, 3, 0, ... frame by frame.
    sway = stride_sway(np.tile([1.0, 0.0, 0.0], (6, 1)), 10.0, stride, 0.0)
    np.testing.assert_allclose(sway[:, 0], [0, 1, 2, 3, 0, 1], atol=1e-12)
    np.testing.assert_allclose(sway[:, 2], -sway[:, 0])
    # Halfway between the bands' speeds: halfway between their sways, and a period between theirs (3 frames).
    mid = stride_sway(np.tile([1.5, 0.0, 0.0], (3, 1)), 10.0, stride, 0.25)
    np.testing.assert_allclose(mid[0], [1.5, 0.0, -1.5])
    # Slower than the first band or faster than the last: that band as it is.
    np.testing.assert_allclose(stride_sway(np.array([[0.1, 0, 0], [9.0, 0, 0]]), 10.0, stride, 0.5)[:, 0], [2.0, 2 * 3.0])
    # The shipped JSON's stride and the sway the page is checked against (fixture "stride_sway").
    info = json.loads((REPO / "public" / "models" / "vae-lstm.json").read_text())
    fixture = json.loads(FIXTURE.read_text())["stride_sway"]
    control = np.array(fixture["control"]).reshape(-1, 3)
    for seed, want in fixture["seeds"].items():
        assert phase_start(int(seed)) == want["phase"]
        np.testing.assert_allclose(stride_sway(control, info["fps"], info["stride"], want["phase"]).ravel(), want["sway"], atol=1e-12)


def test_the_fitted_stride_swings_about_the_control_and_adds_no_speed():
    """A clip that speeds up from 0.9 to 1.5 m/s (as the corpus's clips do from rest) with a stride's surge of
    +-0.1 m/s every 30 frames: the fitted sway keeps the surge and none of the speeding up, which the slow smoothing
    lags behind (before: +0.1 m/s added to the drawn control, so the model read a faster gait than asked)."""
    frames, period = 600, 30
    t = np.arange(frames)
    rows = np.zeros((frames, ROW_DIM))
    rows[:, CONTROL_SLICE.start] = 0.9 + 0.6 * np.clip(t / 400, 0, 1) + 0.1 * np.sin(2 * np.pi * t / period)
    rows[:, CONTACT_SLICE.start] = (t % period) < period // 2
    corpus = type("Corpus", (), {"train_clips": [type("Clip", (), {"rows": rows})()]})()
    stride = fit_stride(corpus, control_sigma=3.0, fps=30.0)
    for band in stride["bands"]:
        sway = np.array(band["sway"])
        np.testing.assert_allclose(sway.mean(axis=0), 0.0, atol=1e-4)
        assert np.ptp(sway[:, 0]) > 0.1  # the surge is kept
    # The shipped stride too: each band's sway averages to nothing over its stride.
    info = json.loads((REPO / "public" / "models" / "vae-lstm.json").read_text())
    for band in info["stride"]["bands"]:
        np.testing.assert_allclose(np.mean(band["sway"], axis=0), 0.0, atol=1e-4)


def test_the_shipped_graphs_reproduce_the_fixture_generation():
    fixture = json.loads(FIXTURE.read_text())
    vae = ShippedVae.load(REPO / "public" / "models")
    g = fixture["generate"]
    control = np.array(g["control"]).reshape(-1, 3)
    z1 = np.array(g["z1"], np.float32)
    rows = vae.rows(control, z1, *free_latents(z1, -(-len(control) // 4), vae.info["sampling"]))
    normalised = (rows - vae.mean) / vae.std
    np.testing.assert_allclose(normalised.ravel(), g["rows"], atol=fixture["tolerance"])
    zs = np.array(fixture["generate_steps"]["zs"], np.float32).reshape(-1, len(g["z1"]))
    teacher = (vae.rows(control, np.array(g["z1"], np.float32), zs) - vae.mean) / vae.std
    np.testing.assert_allclose(teacher.ravel(), fixture["generate_steps"]["rows"], atol=fixture["tolerance"])


def test_the_network_reads_back_from_the_shipped_graphs():
    """The recovered torch module computes what onnxruntime computes on the shipped files, every graph, batches 1
    and 3, two lengths (the anonymous MatMul weights placed by the graph's structure, recovery.py)."""
    models = REPO / "public" / "models"
    info = json.loads((models / "vae-lstm.json").read_text())
    model = vae_lstm_from_onnx(models, info["files"])
    assert (model.dim, model.latent, model.cell.gates_control.in_features) == (info["rows"]["dim"], info["latent"], info["control_features"])
    worst = check_parity(model, models)
    assert max(worst.values()) < 2e-5, worst
    assert info["weights"] == files_format(models)


@pytest.mark.parametrize("fmt", ["float32", "int8"])
def test_export_reads_back_what_it_stored(tmp_path, fmt):
    """export_graphs returns the network its files compute: float32 exactly the trained one, int8 within a step of
    each channel's scale; parity against it holds either way, and writing its int8 weights again stores the same."""
    torch.manual_seed(4)
    net = VaeLstm(ROW_DIM, latent=64, control_features=64, inference_features=32, decoder_hidden=16).eval()
    stored = export_graphs(net, tmp_path, fmt)
    assert files_format(tmp_path) == fmt
    assert max(check_parity(stored, tmp_path).values()) < 2e-5
    for (name, a), b in zip(net.state_dict().items(), stored.state_dict().values()):
        if fmt == "float32" or a.numel() < 4096:  # small weights (biases) stay float32
            assert torch.equal(a, b), name
        else:  # a scale per output channel: torch's first axis, whatever the graph's layout
            step = a.abs().amax(dim=tuple(range(1, a.dim())), keepdim=True) / 127
            assert bool(((a - b).abs() <= step / 2 * 1.001).all()), name
            assert bool((a != b).any()), name
    again = tmp_path / "again"
    again.mkdir()
    assert all(torch.equal(a, b) for a, b in zip(stored.state_dict().values(), export_graphs(stored, again, fmt).state_dict().values()))


def test_recovery_refuses_a_graph_it_cannot_place(tmp_path):
    torch.manual_seed(5)
    net = VaeLstm(ROW_DIM, latent=16, control_features=8, inference_features=12, decoder_hidden=8).eval()
    export_graphs(net, tmp_path)
    cell = onnx.load(str(tmp_path / FILES["cell"]))
    for n in cell.graph.node:  # the content MatMuls now read the control encoding only: two weights for one role
        if n.op_type == "MatMul":
            producer = next(m for m in cell.graph.node if n.input[0] in m.output)
            if producer.op_type != "Gather":
                hc_step = next(m for m in cell.graph.node if m.op_type == "Gather" and m.input[0] == "hc")
                n.input[0] = hc_step.output[0]
    onnx.save(cell, str(tmp_path / FILES["cell"]))
    with pytest.raises(ValueError, match="two weights for the cell's content_control"):
        vae_lstm_from_onnx(tmp_path, FILES)
