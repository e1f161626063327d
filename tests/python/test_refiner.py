"""Refiner pieces: torch decoding + FK against numpy, streaming step = sequence forward, foot lock, ONNX parity."""
import json

import numpy as np
import onnxruntime as ort
import pytest
import torch

from training.data.cmu import clip_contacts, load_clip, read_index
from training.paths import MODELS_DIR
from training.refiner.exporting import FIXTURE
from training.refiner.graph import OUTPUTS, export_onnx, parity_error, refiner_from_onnx, step_parity, stream_inputs
from training.data.features import FeatureCodec
from training.footlock import BLEND_IN, FLAT_PITCH, TOE_GROUND_HEIGHT, FootLock, foot_lock, two_bone_ik
from training.models.refiner import (FeatureGeometry, Refiner, RefinerStep, rotvec_to_matrix, straight_through_bits)
from training.mocap.rotations import axis_rotation
from training.mocap.skeleton import canonical_skeleton
from training.refiner.training import root_loss

SKEL = canonical_skeleton()


@pytest.fixture(scope="module")
def walk(mocap):
    info = next(i for i in read_index(mocap) if i.file.endswith("16_22.amc.gz"))  # walk with a turn
    clip = load_clip(mocap, info, 30)
    codec = FeatureCodec()
    codec.fit_references(clip.rotations)
    x = codec.encode(clip.root, clip.rotations, clip_contacts(clip))
    return codec, x


def random_refiner(codec, x, hidden=24, seed=0) -> Refiner:
    torch.manual_seed(seed)
    mean, std = x.mean(0), np.maximum(x.std(0), 1e-2)
    rng = np.random.default_rng(seed)
    model = Refiner(mean, std, codec.references, hidden, end_mean=rng.normal(size=42) * 0.1,
                    end_std=1 + rng.random(42), fps=30.0).eval()
    with torch.no_grad():
        for p in model.parameters():
            p.add_(torch.randn_like(p) * 0.2)  # FC2 starts at zero: make the residual branch matter
    return model


def normalised(model, x):
    return ((x - model.mean.numpy()) / model.std.numpy()).astype(np.float32)


def test_rotvec_matches_numpy_and_is_finite_at_zero():
    from training.data.features import rotvec_to_matrix as np_rotvec
    v = np.random.default_rng(1).normal(size=(50, 3)) * 1.5
    v[0] = 0
    v[1] = 1e-7
    got = rotvec_to_matrix(torch.from_numpy(v)).numpy()
    assert np.abs(got - np_rotvec(v)).max() < 1e-10
    t = torch.zeros(3, dtype=torch.float64, requires_grad=True)
    rotvec_to_matrix(t).sum().backward()
    assert torch.isfinite(t.grad).all()


def test_torch_fk_matches_numpy_decoder(walk):
    codec, x = walk
    geo = FeatureGeometry(codec.references).double()
    pos_world = codec.positions(x)  # start at the origin, heading 0
    root, _, _ = codec.decode(x)
    yaw = np.cumsum(x[:, 2])
    expected = np.einsum("fji,fkj->fki", axis_rotation("y", yaw), pos_world - root[:, None] * [1, 0, 1])
    got = geo.root_frame_positions(torch.from_numpy(x))
    assert len(geo.needed) >= 20
    for j in geo.needed:
        assert np.abs(got[j].numpy() - expected[:, j]).max() < 1e-7, SKEL.joints[j]  # sqrt(t^2 + 1e-12) in Rodrigues
    # end-effector velocities: world velocities in the previous frame's heading frame
    p, v = geo.end_effectors(torch.from_numpy(x[None, 1:]), torch.from_numpy(x[None, 0]))
    world_v = np.einsum("fji,fkj->fki", axis_rotation("y", yaw[:-1]), np.diff(pos_world, axis=0)) * 30
    assert np.abs(v[0].numpy() - world_v[:, geo.end_index]).max() < 1e-5
    assert np.abs(p[0].numpy() - expected[1:, geo.end_index]).max() < 1e-7
    assert np.abs(geo.root_trajectory(torch.from_numpy(x[None]))[0].numpy() - root).max() < 1e-9
    # the clip turns, so the heading terms are really exercised
    assert np.abs(x[:, 2]).sum() > 0.5


def test_refiner_starts_as_identity_and_root_loss_sees_root_changes(walk):
    codec, x = walk
    model = Refiner(x.mean(0), np.maximum(x.std(0), 1e-2), codec.references, 16)
    xn = torch.from_numpy(normalised(model, x))[None]
    y, _ = model(xn[:, 1:], xn[:, 0])
    assert torch.equal(y, xn[:, 1:])
    assert float(root_loss(model, xn, xn)) == 0.0
    bent = xn.clone()
    bent[..., 2] += 0.5  # turn a bit more each frame: the integrated root path moves away
    assert float(root_loss(model, xn, bent)) > 1e-3


def test_straight_through_bits():
    c = torch.tensor([0.2, 0.7, 0.51], requires_grad=True)
    b = straight_through_bits(c)
    assert b.tolist() == [0.0, 1.0, 1.0]
    b.sum().backward()
    assert c.grad.tolist() == [1.0, 1.0, 1.0]


def test_streaming_step_equals_sequence_forward(walk):
    codec, x = walk
    model = random_refiner(codec, x)
    xn = normalised(model, x[None, :60])
    with torch.no_grad():
        ref, _ = model(torch.from_numpy(xn[:, 1:]), torch.from_numpy(xn[:, 0]))
    q = stream_inputs(model, xn)
    step = RefinerStep(model).eval()
    h = torch.zeros(1, 1, model.hidden)
    c = torch.zeros(1, 1, model.hidden)
    outs = []
    with torch.no_grad():
        for t in range(1, xn.shape[1]):
            out, h, c = step(torch.from_numpy(xn[:, t]), torch.from_numpy(q[:, t]), torch.from_numpy(q[:, t - 1]), h, c)
            outs.append(out)
    got = torch.stack(outs, 1)
    assert (got - ref).abs().max() < 1e-5
    assert (ref - torch.from_numpy(xn[:, 1:])).abs().max() > 0.1  # the refiner really changes the frames


def test_onnx_step_parity(walk, tmp_path):
    codec, x = walk
    model = random_refiner(codec, x, hidden=32, seed=4)
    path = tmp_path / "r.onnx"
    export_onnx(model, path)
    xn = normalised(model, x)
    frames = np.stack([xn[a:a + 21] for a in np.linspace(0, len(xn) - 21, 8).astype(int)])
    assert parity_error(model, path, frames) < 1e-4
    assert step_parity(model, path, frames) < 1e-4
    # dynamic batch
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    q = stream_inputs(model, frames)
    out = session.run(OUTPUTS, {"x": frames[:3, 1:6], "ends": q[:3, 1:6], "ends_prev": q[:3, 0],
                                "h": np.zeros((1, 3, 32), np.float32), "c": np.zeros((1, 3, 32), np.float32)})
    assert out[0].shape == (3, 5, model.dim) and out[1].shape == (1, 3, 32)


def test_refiner_rebuilt_from_its_export_computes_the_same(walk, tmp_path):
    codec, x = walk
    model = random_refiner(codec, x, hidden=16, seed=5)
    path = tmp_path / "r.onnx"
    export_onnx(model, path)
    meta = {"mean": model.mean.tolist(), "std": model.std.tolist(), "references": codec.references.tolist(), "fps": 30.0,
            "end_mean": np.zeros(42).tolist(), "end_std": np.ones(42).tolist()}  # other end statistics than the model's
    rebuilt = refiner_from_onnx(path, meta)
    xn = torch.from_numpy(normalised(model, x[None, :40]))
    with torch.no_grad():
        a, _ = model(xn[:, 1:], xn[:, 0])
        b, _ = rebuilt(xn[:, 1:], xn[:, 0])
    assert (a - b).abs().max() < 1e-4


def test_shipped_refiner_matches_its_fixture():
    path = MODELS_DIR / "refiner.onnx"
    if not path.exists():
        pytest.skip("no shipped refiner yet")
    info = json.loads((MODELS_DIR / "refiner.json").read_text())
    fx = json.loads(FIXTURE.read_text())
    assert path.stat().st_size <= 8e6 and info["bytes"] == path.stat().st_size
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    b, d, h, e3 = fx["batch"], fx["dim"], fx["hidden"], info["onnx"]["ends"]
    for call in fx["calls"]:
        n = call["frames"]
        shapes = {"x": (b, n, d), "ends": (b, n, e3), "ends_prev": (b, e3), "h": (1, b, h), "c": (1, b, h)}
        feed = {k: np.array(v, np.float32).reshape(shapes[k]) for k, v in call["inputs"].items()}
        out = session.run(OUTPUTS, feed)
        for name, got in zip(OUTPUTS, out):
            assert np.abs(got.ravel() - np.array(call["outputs"][name])).max() < 1e-4, name
    # The fixture's ends are the torch geometry of its frames (the convention the browser must reproduce).
    geo = FeatureGeometry(np.array(fx_references(info)), fps=info["fps"]).double()
    frames = torch.tensor(fx["frames_physical"], dtype=torch.float64).reshape(b, fx["frames"], d)
    ends = geo.end_positions(frames).flatten(-2).numpy().ravel()
    assert np.abs(ends - np.array(fx["ends"])).max() < 1e-5


def fx_references(info):
    from training.mocap.rotations import quat_to_matrix
    gen = json.loads((MODELS_DIR / "generator.json").read_text())
    return quat_to_matrix(np.array(gen["features"]["references"]))


# ---- foot lock ------------------------------------------------------------------------------------

def bone_lengths(pos):
    return np.stack([np.linalg.norm(pos[:, j] - pos[:, p], axis=-1) for j, p in enumerate(SKEL.parents) if p >= 0], 1)


@pytest.fixture(scope="module")
def sliding_walk(walk):
    """The real walk decoded, with its planted feet made to slide: the leg below the hip is swung by a smooth
    rotation about the hip (bone lengths kept), so the toe moves while the contact bit says planted."""
    codec, x = walk
    pos = codec.positions(x)
    contacts = (x[:, -2:] > 0.5).astype(np.uint8)
    out = pos.copy()
    t = np.arange(len(pos)) / 30.0
    for side, names in enumerate([("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "LeftToeBase_end"),
                                  ("RightUpLeg", "RightLeg", "RightFoot", "RightToeBase", "RightToeBase_end")]):
        hip = SKEL.index(names[0])
        rot = axis_rotation("x", 0.08 * np.sin(2 * np.pi * 1.3 * t + side))  # +-0.08 rad: about +-7 cm at the toe
        for n in names[1:]:
            j = SKEL.index(n)
            out[:, j] = pos[:, hip] + np.einsum("fij,fj->fi", rot, pos[:, j] - pos[:, hip])
    return out, contacts


def planted_toe_steps(pos, contacts):
    steps = []
    for side, name in enumerate(("LeftToeBase", "RightToeBase")):
        toe = pos[:, SKEL.index(name)][:, [0, 2]]
        planted = (contacts[1:, side] > 0) & (contacts[:-1, side] > 0)
        steps.append(np.linalg.norm(np.diff(toe, axis=0), axis=-1)[planted])
    return np.concatenate(steps)


def test_foot_lock_keeps_planted_toes_fixed_and_bones_rigid(sliding_walk):
    pos, contacts = sliding_walk
    out = foot_lock(pos, contacts)
    raw_steps, locked_steps = planted_toe_steps(pos, contacts), planted_toe_steps(out, contacts)
    assert raw_steps.mean() > 3e-3  # the input really slides (m per frame)
    assert np.percentile(locked_steps, 95) < 1e-6 and locked_steps.max() < 5e-3
    assert np.abs(bone_lengths(out) - bone_lengths(pos)).max() < 1e-9
    # hips and the upper body never move
    upper = [j for j, n in enumerate(SKEL.joints) if not n.startswith(("LeftLeg", "LeftFoot", "LeftToe", "RightLeg", "RightFoot", "RightToe"))]
    assert np.abs(out[:, upper] - pos[:, upper]).max() == 0.0


def test_foot_lock_puts_planted_toes_on_the_ground_without_popping(sliding_walk):
    pos, contacts = sliding_walk
    out = foot_lock(pos, contacts)
    for side, name in enumerate(("LeftToeBase", "RightToeBase")):
        j = SKEL.index(name)
        c = contacts[:, side] > 0
        settled = c.copy()
        for k in range(BLEND_IN):  # frames at least BLEND_IN into a contact
            settled &= np.roll(c, k + 1)
        assert np.abs(out[settled, j, 1] - TOE_GROUND_HEIGHT).max() < 1e-9
    # No popping: the largest frame-to-frame change of velocity (second difference, m/frame^2) of the cleaned
    # leg stays moderate, and well below what switching the lock on and off without blending gives.
    def jerk(p):
        legs = [SKEL.index(n) for n in ("LeftLeg", "LeftFoot", "LeftToeBase", "RightLeg", "RightFoot", "RightToeBase")]
        return np.linalg.norm(np.diff(p[:, legs], 2, axis=0), axis=-1).max()
    unblended = foot_lock(pos, contacts, blend_in=1, blend_out=1)
    assert jerk(out) < 0.12
    assert jerk(out) < 0.5 * jerk(unblended)


def test_foot_lock_holds_the_heel_of_a_flat_planted_foot(walk):
    """The raw feet swivel about their toes (heading +-0.3 rad) while planted: locked, a flat planted foot's heel
    (the ankle) stays nearly where it was, as its toe does; raw, it sweeps about a centimetre per frame."""
    codec, x = walk
    pos = codec.positions(x)
    contacts = (x[:, -2:] > 0.5).astype(np.uint8)
    swivel = pos.copy()
    t = np.arange(len(pos)) / 30.0
    heel_steps = {"raw": [], "locked": []}
    for side, (ankle, toe, end) in enumerate((("LeftFoot", "LeftToeBase", "LeftToeBase_end"),
                                             ("RightFoot", "RightToeBase", "RightToeBase_end"))):
        a, k, e = SKEL.index(ankle), SKEL.index(toe), SKEL.index(end)
        turn = axis_rotation("y", 0.3 * np.sin(2 * np.pi * 2.0 * t + side))
        for j in (a, e):
            swivel[:, j] = pos[:, k] + np.einsum("fij,fj->fi", turn, pos[:, j] - pos[:, k])
    out = foot_lock(swivel, contacts)
    for side, (ankle, toe) in enumerate((("LeftFoot", "LeftToeBase"), ("RightFoot", "RightToeBase"))):
        a, k = SKEL.index(ankle), SKEL.index(toe)
        c = contacts[:, side] > 0
        held = c[1:] & c[:-1] & np.roll(c, 1)[1:] & np.roll(c, 2)[1:] & np.roll(c, 3)[1:]  # past the blend-in
        foot = swivel[:, k] - swivel[:, a]
        pitch = np.arctan2(-foot[:, 1], np.hypot(foot[:, 0], foot[:, 2]))
        flat = held & (pitch[1:] < FLAT_PITCH) & (pitch[:-1] < FLAT_PITCH)
        for name, p in (("raw", swivel), ("locked", out)):
            heel_steps[name].append(np.linalg.norm(np.diff(p[:, a][:, [0, 2]], axis=0), axis=-1)[flat])
    raw, locked = (np.concatenate(heel_steps[n]) for n in ("raw", "locked"))
    assert len(raw) > 20
    assert raw.mean() > 0.005
    # held: what is left is the raw foot's pitch changing the heel's reach from the toe (about a millimetre a frame)
    assert locked.mean() < 0.15 * raw.mean()


def test_foot_lock_leaves_free_feet_alone():
    pos = np.random.default_rng(0).normal(size=(10, len(SKEL.joints), 3))
    out = foot_lock(pos, np.zeros((10, 2), np.uint8))
    assert np.array_equal(out, pos)


def test_two_bone_ik_reaches_and_keeps_lengths():
    hip, knee = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.6, 0.1])
    for target in (np.array([0.1, 0.3, 0.2]), np.array([0.0, -2.0, 0.0])):
        k, a = two_bone_ik(hip, knee, target, 0.4, 0.43)
        assert abs(np.linalg.norm(k - hip) - 0.4) < 1e-9 and abs(np.linalg.norm(a - k) - 0.43) < 1e-9
        assert np.dot(k - hip, [0, 0, 1]) > 0  # the knee bends to the raw knee's side
    k, a = two_bone_ik(hip, knee, np.array([0.1, 0.3, 0.2]), 0.4, 0.43)
    assert np.linalg.norm(a - [0.1, 0.3, 0.2]) < 1e-9


def test_streaming_foot_lock_equals_batch(sliding_walk):
    pos, contacts = sliding_walk
    lock = FootLock()
    streamed = np.stack([lock.step(p, c) for p, c in zip(pos[:80], contacts[:80] > 0)])
    assert np.array_equal(streamed, foot_lock(pos[:80], contacts[:80]))


def test_stronger_two_sample_classifier_sees_accelerations():
    """The stronger classifier's input adds each frame's joint accelerations; it tells jittered windows from smooth
    ones, and is near chance on two samples of the same process."""
    from training.refiner.measures import two_sample_accuracy, with_accelerations
    rng = np.random.default_rng(0)
    joints, frames = 3, 32

    def smooth(n):  # (n, T, 6J + 2): slow sines for positions and their velocities, contacts off
        t = np.arange(frames)[None, :, None] / 30.0
        phase = rng.uniform(0, 6.3, (n, 1, 3 * joints))
        pos, vel = np.sin(2 * t + phase), 2 * np.cos(2 * t + phase)
        return np.concatenate([pos, vel, np.zeros((n, frames, 2))], axis=-1).astype(np.float32)

    w = smooth(4)
    acc = with_accelerations(w, 30.0)
    assert acc.shape == (4, frames - 1, 9 * joints + 2)
    np.testing.assert_allclose(acc[:, :, -3 * joints:], np.diff(w[:, :, 3 * joints:6 * joints], axis=1) * 30.0, rtol=1e-6)
    jittered = smooth(200)
    jittered[:, :, 3 * joints:6 * joints] += rng.normal(0, 0.3, (200, frames, 3 * joints)).astype(np.float32)
    apart = two_sample_accuracy(smooth(200), jittered[:100], smooth(100), jittered[100:], seed=0, steps=200, kind="strong")
    same = two_sample_accuracy(smooth(200), smooth(200), smooth(200), smooth(200), seed=0, steps=200, kind="strong")
    assert apart["balanced_accuracy"] > 0.9
    assert same["balanced_accuracy"] < 0.75


def test_joint_features_are_what_the_two_sample_classifiers_see(walk):
    """A discriminator with --d-input joints judges a frame as the report's classifiers do: every joint's root-frame
    position and velocity (classifier_frames' first 6J columns)."""
    from training.models.refiner import JointFeatures
    from training.refiner.measures import classifier_frames
    codec, x = walk
    joints = len(SKEL.joints)
    features = JointFeatures(codec.references, np.zeros(6 * joints), np.ones(6 * joints)).double()
    got = features(torch.from_numpy(x[None, 1:]), torch.from_numpy(x[None, 0]))[0].numpy()
    expected = classifier_frames(codec.positions(x), np.cumsum(x[:, 2]), np.zeros((len(x), 2)), 30.0)[:, :6 * joints]
    assert np.abs(got - expected).max() < 1e-5
    assert np.abs(x[:, 2]).sum() > 0.5  # the clip turns: the velocities' heading frame matters


def test_planted_toe_speed_is_the_skating_measure(walk):
    """R's --skate-weight term is the validation skating measure, differentiable, with the bits of its input."""
    from training.refiner.training import planted_toe_speed, skating
    codec, x = walk
    model = random_refiner(codec, x)
    xn = torch.from_numpy(normalised(model, x))[None]
    y = xn[:, 1:].clone().requires_grad_(True)
    speed = planted_toe_speed(model, y, xn[:, 0], y.detach())
    assert abs(float(speed) - skating(model, y.detach(), xn[:, 0])[0]) < 1e-4
    speed.backward()
    assert torch.isfinite(y.grad).all() and float(y.grad.abs().sum()) > 0


def test_training_streams_hold_their_normals_as_the_page_does():
    """The refiner trains on generator streams drawn the way the page draws them: z = rho z' + sqrt(1 - rho^2) n."""
    from training.refiner.streams import sample_torch
    b, m, d = 3, 2, 5
    logits, mu, log_sigma = torch.zeros(b, m), torch.zeros(b, m, d), torch.zeros(b, m, d)
    gen = torch.Generator().manual_seed(0)
    x0, z0 = sample_torch(logits, mu, log_sigma, 1.0, gen, None, 0.8)
    assert torch.allclose(x0, z0)
    state = gen.get_state()
    x1, z1 = sample_torch(logits, mu, log_sigma, 1.0, gen, z0, 0.8)
    gen.set_state(state)
    torch.multinomial(torch.full((b, m), 0.5), 1, generator=gen)
    fresh = torch.randn(b, d, generator=gen)
    assert torch.allclose(z1, 0.8 * z0 + 0.6 * fresh, atol=1e-6)


def test_a_style_model_s_training_streams_come_in_every_style_from_that_style_s_clips(tmp_path, monkeypatch):
    """Issue 39: a refiner for the style generator learns from streams in every style, an equal share each, each warmed
    up on real frames of its own style and drawn in that style."""
    from types import SimpleNamespace

    import training.refiner.streams as streams
    from training.models.generator import MixtureLSTM

    monkeypatch.setattr(streams, "DEFAULT_CACHE", tmp_path)
    dim, warmup = 6, 4
    # Two styles whose real frames differ by their level: style 0 near -3, style 1 near +3 (normalised units).
    train = [np.full((12, dim), -3.0 if k % 2 == 0 else 3.0, np.float32) for k in range(6)]
    corpus = SimpleNamespace(train=train, train_styles=np.array([0, 1] * 3), weights=np.full(6, 1 / 6),
                             mean=np.zeros(dim), std=np.ones(dim))
    torch.manual_seed(0)
    model = MixtureLSTM(dim, 16, 2, styles=2, style_dim=3).eval()
    args = SimpleNamespace(streams=8, window=5, long_streams=2, warmup=warmup)
    short, long = streams.generated_cache(model, corpus, args, "train", styles=2, tag="_test")
    assert short.shape == (8, args.window + 30 + 1, dim) and long.shape == (2, 1201, dim)
    # Frame 0 is the last real warm-up frame: the first half of each set from style 0's clips, the rest from style 1's.
    assert np.all(short[:4, 0, :-2] == -3.0) and np.all(short[4:, 0, :-2] == 3.0)
    assert long[0, 0, 0] == -3.0 and long[1, 0, 0] == 3.0
    # Each share is drawn in its own style: the same warm-up under the other style's embedding gives other frames.
    other = streams.generate_streams(streams.StyledGenerator(model, 1), corpus, 4, 35, warmup, streams.TEMPERATURE, 1,
                                     pool=[0, 2, 4])
    assert np.all(other[:, 0, :-2] == -3.0) and np.abs(other[:, 1:] - short[:4, 1:]).max() > 1e-3
    assert any(p.name.startswith("refiner_generated_test_") for p in tmp_path.iterdir())


def test_style_shares_follow_the_real_windows_style_mix():
    """D must see the same mix of styles in generated as in real windows: a corpus that draws CMU (style 0) for 35% of
    its windows gets 35% of the streams in CMU, the rest split as the other styles are drawn."""
    from types import SimpleNamespace

    from training.refiner.streams import style_shares

    styles = np.array([0, 0, 1, 2, 2, 2])
    weights = np.array([0.2, 0.15, 0.325, 0.1, 0.1, 0.125])
    assert style_shares(SimpleNamespace(train_styles=styles, weights=weights), 100, 3) == [35, 33, 32]
    assert style_shares(SimpleNamespace(train_styles=styles, weights=weights), 7, 3) == [3, 2, 2]
    assert style_shares(SimpleNamespace(train_styles=np.array([0, 1]), weights=np.array([0.5, 0.5])), 2048, 2) == [1024, 1024]
