"""python -m training.own: a folder of the user's motion in, a model pack out. The test folder is made here from two
CMU clips renamed to Mixamo's joint names (one of them resampled to 30 fps and left unzipped), a Bandai Namco clip, a CMU
ASF/AMC pair and a file broken at a known line; the refusals get folders of their own. The command runs as a
subprocess (tests/python/test_layout.py). The training run is tiny (a small network, a capped number of iterations):
what is checked is that the pack is complete and readable as the page reads it, not that the model is good."""
import gzip
import json
import re
import signal
import subprocess
import sys
import time

import numpy as np
import onnxruntime
import pytest

from conftest import MOCAP, REPO
from training.mocap.skeleton import canonical_skeleton
from training.mocap.canonical_ik import CanonicalIK
from training.mocap.canonical_points import ik_prior, to_canonical
from training.mocap.humanoid import CANONICAL_JOINTS

CMU_TO_MIXAMO = {"LHipJoint": "LeftHipJoint", "RHipJoint": "RightHipJoint", "LowerBack": "Spine", "Spine": "Spine1",
                 "Spine1": "Spine2", "LeftFingerBase": "LeftHandMiddle1", "RightFingerBase": "RightHandMiddle1",
                 "LThumb": "LeftHandThumb1", "RThumb": "RightHandThumb1"}
MIXAMO_ENDS = {"Head": "HeadTop_End", "LeftToeBase": "LeftToe_End", "RightToeBase": "RightToe_End"}
SMALL = ["--hidden", "32", "--iters-per-epoch", "20", "--checkpoint-minutes", "0.05"]


def cmu_text(name: str) -> str:
    return gzip.decompress((MOCAP / "cmu" / "bvh" / f"{name}.bvh.gz").read_bytes()).decode()


def as_mixamo(text: str) -> str:
    """A CMU BVH with Mixamo's joint names (mixamorig: namespace, Spine/Spine1/Spine2 …) and Mixamo's named end joints
    (HeadTop_End, LeftToe_End: a joint without channels before the end site)."""
    out, last = [], None
    for line in text.splitlines():
        m = re.match(r"^(\s*)(ROOT|JOINT)\s+(\S+)", line)
        if m:
            last = m.group(3)
            line = f"{m.group(1)}{m.group(2)} mixamorig:{CMU_TO_MIXAMO.get(last, last)}"
        elif line.strip() == "End Site" and last in MIXAMO_ENDS:
            indent = line[:len(line) - len(line.lstrip())]
            out.append(f"{indent}JOINT mixamorig:{MIXAMO_ENDS[last]}")
            out.append(f"{indent}{{")
            last = None
            # The end site's own offset moves to the new joint, which gets a zero-length end site.
            out.append("__END_JOINT__")
            continue
        out.append(line)
    text = "\n".join(out) + "\n"
    # Fill each placeholder: the offset of the end site that followed it, then that end site at zero length.
    return re.sub(r"__END_JOINT__\n(\s*)\{\n(\s*)OFFSET ([^\n]*)\n(\s*)\}",
                  lambda m: f"{m.group(2)}OFFSET {m.group(3)}\n{m.group(2)}CHANNELS 0\n{m.group(2)}End Site\n"
                            f"{m.group(2)}{{\n{m.group(2)}OFFSET 0 0 0\n{m.group(2)}}}\n{m.group(1)}}}", text)


def every_nth_frame(text: str, n: int) -> str:
    """The BVH at 1/n of its frame rate (every nth frame)."""
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()
    frames = [l for l in lines[2:] if l.strip()][::n]
    frame_time = float(lines[1].split(":")[1]) * n
    return f"{head}MOTION\nFrames: {len(frames)}\nFrame Time: {frame_time:.6f}\n" + "\n".join(frames) + "\n"


def first_frames(text: str, count: int) -> str:
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()
    frames = [l for l in lines[2:] if l.strip()][:count]
    return f"{head}MOTION\nFrames: {len(frames)}\n{lines[1]}\n" + "\n".join(frames) + "\n"


def broken_line(lines: list[str]) -> int:
    """The line (1-based) of the broken file where a number is replaced: its third frame."""
    return lines.index("MOTION") + 6


def run_own(*args, timeout=110):
    return subprocess.run([sys.executable, "-m", "training.own", *map(str, args)], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout)


@pytest.fixture(scope="module")
def folder(tmp_path_factory, mocap):
    root = tmp_path_factory.mktemp("own") / "my-walks"
    (root / "mixamo" / "more").mkdir(parents=True)
    (root / "bandai").mkdir()
    (root / "asf").mkdir()
    (root / "mixamo" / "more" / "07_04.bvh.gz").write_bytes(gzip.compress(as_mixamo(cmu_text("07_04")).encode()))
    (root / "mixamo" / "07_05_30fps.bvh").write_text(every_nth_frame(as_mixamo(cmu_text("07_05")), 4))
    bandai = "dataset-2_walk-turn-left_active_001.bvh.gz"
    (root / "bandai" / bandai).write_bytes((mocap / "bandai" / "bvh" / bandai).read_bytes())
    (root / "asf" / "02.asf").write_bytes((mocap / "cmu" / "asf" / "02.asf").read_bytes())
    (root / "asf" / "02_01.amc.gz").write_bytes((mocap / "cmu" / "amc" / "02_01.amc.gz").read_bytes())
    broken = as_mixamo(cmu_text("08_07")).splitlines()
    bad = broken_line(broken) - 1
    broken[bad] = broken[bad].replace(broken[bad].split()[3], "oops", 1)
    (root / "mixamo" / "broken.bvh").write_text("\n".join(broken) + "\n")
    return root


@pytest.fixture(scope="module")
def pack(folder, tmp_path_factory):
    out = tmp_path_factory.mktemp("pack") / "my-walks"
    run = tmp_path_factory.mktemp("run")
    done = run_own("--data", folder, "--kind", "locomotion", "--out", out, "--run", run, "--iterations", "30", *SMALL)
    assert done.returncode == 0, done.stderr[-3000:]
    return out, run, done


def test_a_pack_is_written_from_a_mixed_folder(pack):
    out, run, done = pack
    assert sorted(p.name for p in out.iterdir()) == ["card.md", "my-walks.json", "my-walks.onnx", "pose_change.png"]
    # Mixed frame rates are resampled; the broken file is named with its line and the others go on.
    assert re.search(r"read mixamo/07_05_30fps\.bvh: [\d.]+ s at 30 fps", done.stdout)
    assert re.search(r"read mixamo/more/07_04\.bvh\.gz: [\d.]+ s at 120 fps", done.stdout)
    assert "read asf/02_01.amc.gz" in done.stdout and "read bandai/" in done.stdout
    line = broken_line(as_mixamo(cmu_text("08_07")).splitlines())
    assert f"skipped: mixamo/broken.bvh:{line}: expected a number, found 'oops'" in done.stdout
    assert (run / "checkpoint.pt").exists() and (run / "best.pt").exists() and (run / "train.log").exists()


def test_the_json_holds_what_the_page_checks(pack):
    """The fields web/model/generatorInfo.ts parseGeneratorInfo requires, with their shapes."""
    out, _, _ = pack
    info = json.loads((out / "my-walks.json").read_text())
    assert info["id"] == "my-walks" and info["file"] == "my-walks.onnx" and info["fps"] > 0
    J = len(info["skeleton"]["joints"])
    assert info["skeleton"]["parents"][0] == -1 and len(info["skeleton"]["offsets"]) == 3 * J
    o, f = info["onnx"], info["features"]
    assert o["inputs"] == ["x", "h", "c"] and o["outputs"] == ["weights", "mu", "sigma", "h_out", "c_out"]
    D = o["dim"]
    assert D == 7 + 3 * len(f["joints"]) + 2 == len(f["names"])
    assert sorted(f["joints"] + f["fixed_joints"]) == list(range(1, J))
    assert len(f["references"]) == J and all(abs(np.linalg.norm(q) - 1) < 1e-3 for q in f["references"])
    assert len(info["normalisation"]["mean"]) == D and min(info["normalisation"]["std"]) > 0
    assert info["seeds"], "no seeds"
    for s in info["seeds"]:
        assert isinstance(s["name"], str) and len(s["x"]) == D
        assert len(s["h"]) == len(s["c"]) == o["layers"] * o["hidden"]
    assert 0 <= info["sampling"]["noise_correlation"] < 1
    # The ONNX step runs in onnxruntime with the JSON's shapes.
    session = onnxruntime.InferenceSession(str(out / info["file"]), providers=["CPUExecutionProvider"])
    s = info["seeds"][0]
    w, mu, sigma, h, c = session.run(None, {"x": np.array([s["x"]], np.float32),
                                             "h": np.array(s["h"], np.float32).reshape(o["layers"], 1, o["hidden"]),
                                             "c": np.array(s["c"], np.float32).reshape(o["layers"], 1, o["hidden"])})
    assert w.shape == (1, o["mixtures"]) and mu.shape == (1, o["mixtures"], D) and np.isfinite(mu).all()


def test_the_card_is_written_from_measurements(pack):
    out, _, _ = pack
    card = (out / "card.md").read_text()
    info = json.loads((out / "my-walks.json").read_text())
    measures = info["pack"]["measures"]
    assert f"{info['pack']['data_minutes']:.2f} minutes of motion in 4 clips" in card
    assert "Mixamo" in card and "Bandai Namco" in card and "CMU ASF" in card
    assert "30 iterations" in card
    assert f"{measures['real']['sliding_low_foot']:.3f}" in card
    assert f"{measures['generated']['sliding_low_foot_locked']:.3f}" in card
    assert measures["stability"]["frames"] == 10_000 and "10,000 frames" in card
    assert measures["stability"]["seconds"] == 10_000 // 30
    assert f"mixamo/broken.bvh:{broken_line(as_mixamo(cmu_text('08_07')).splitlines())}" in card
    assert (out / "pose_change.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_resume_continues_the_run(pack, folder, tmp_path):
    out, run, _ = pack
    done = run_own("--data", folder, "--kind", "locomotion", "--out", tmp_path / "again", "--run", run, "--resume",
                   "--iterations", "45", "--stability-frames", "300", *SMALL)
    assert done.returncode == 0, done.stderr[-3000:]
    log = (run / "train.log").read_text()
    assert "resumed at epoch 1 iteration 10" in log
    assert json.loads((run / "summary.json").read_text())["iterations"] == 45
    # A checkpoint of another network is not resumed.
    other = run_own("--data", folder, "--kind", "locomotion", "--out", tmp_path / "other", "--run", run, "--resume",
                    "--iterations", "60", "--hidden", "16", "--iters-per-epoch", "20")
    assert other.returncode != 0 and "was trained on other data or another --hidden" in other.stderr


def test_ctrl_c_stops_cleanly_keeping_the_checkpoint(tmp_path):
    run, folder = tmp_path / "run", tmp_path / "two-clips"
    folder.mkdir()
    for name in ("07_04", "07_05"):
        (folder / f"{name}.bvh").write_text(every_nth_frame(as_mixamo(cmu_text(name)), 4))
    command = [sys.executable, "-m", "training.own", "--data", str(folder), "--kind", "locomotion", "--out",
               str(tmp_path / "pack"), "--run", str(run), "--iterations", "1000000", *SMALL[:4], "--checkpoint-minutes", "0.005"]
    process = subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 90
        while not (run / "checkpoint.pt").exists():  # training has started once the first timed checkpoint is written
            assert process.poll() is None and time.monotonic() < deadline, "training did not start"
            time.sleep(0.2)
        process.send_signal(signal.SIGINT)
        out, _ = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 130 and "stopped by Ctrl-C" in out and "--resume" in out
    assert "stopped: stopped by Ctrl-C" in (run / "train.log").read_text()
    assert json.loads((run / "summary.json").read_text())["iterations"] > 0
    assert not (tmp_path / "pack").exists()


def write_chain_bvh(path, joints: int = 5) -> None:
    """A snake: one chain of joints, no legs or arms."""
    text = "HIERARCHY\nROOT j0\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
    for j in range(1, joints):
        text += f"JOINT j{j}\n{{\n OFFSET 0 0 10\n CHANNELS 3 Zrotation Yrotation Xrotation\n"
    text += "End Site\n{\n OFFSET 0 0 10\n}\n" + "}\n" * joints
    values = " ".join(["0"] * (6 + 3 * (joints - 1)))
    text += f"MOTION\nFrames: 3\nFrame Time: 0.033333\n" + f"{values}\n" * 3
    path.write_text(text)


def test_refusals_before_training(tmp_path, mocap):
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "notes.txt").write_text("no motion here")
    done = run_own("--data", empty, "--kind", "locomotion", "--out", tmp_path / "p1")
    assert done.returncode != 0 and "error: no motion in" in done.stderr and len(done.stderr.strip().splitlines()[-1]) <= 300

    snake = tmp_path / "snake"
    snake.mkdir()
    (snake / "walk.bvh").write_text(as_mixamo(cmu_text("07_04")))
    write_chain_bvh(snake / "snake.bvh")
    done = run_own("--data", snake, "--kind", "locomotion", "--out", tmp_path / "p2")
    message = done.stderr.strip().splitlines()[-1]
    assert done.returncode != 0 and message.startswith("error: snake.bvh: not a humanoid skeleton"), message
    assert len(message) <= 300

    short = tmp_path / "short"
    short.mkdir()
    for name in ("07_04", "07_05"):
        (short / f"{name}.bvh").write_text(first_frames(as_mixamo(cmu_text(name)), 120))  # 1 s at 120 fps
    done = run_own("--data", short, "--kind", "locomotion", "--out", tmp_path / "p3")
    message = done.stderr.strip().splitlines()[-1]
    assert done.returncode != 0 and "clips too short: training needs at least 2 clips of 1.73 s or more" in message, message
    assert len(message) <= 300
    assert not (tmp_path / "p1").exists() and not (tmp_path / "p2").exists() and not (tmp_path / "p3").exists()


def test_ik_points_every_segment_as_the_corpus_loader_does():
    """The IK's rotations from positions alone point every modelled segment where the loader's rotations point it
    (tests/fixtures/feature_encoding.json; the page's IK is held to the same bound in featureEncodeParity.test.ts)."""
    from training.mocap.rotations import quat_to_matrix
    from training.data.features import FIXED_JOINTS
    skel = canonical_skeleton()
    ik = CanonicalIK(skel, *ik_prior())
    fixture = json.loads((REPO / "tests" / "fixtures" / "feature_encoding.json").read_text())
    for case in fixture["cases"]:
        F = case["frames"]
        world = ik.solve(np.array(case["positions"]).reshape(F, -1, 3))
        truth = quat_to_matrix(np.array(case["world_rotations"]).reshape(F, -1, 4))
        for j in range(1, len(skel.joints)):
            if skel.joints[j] in FIXED_JOINTS:
                continue
            a, b = world[:, j] @ skel.offsets[j], truth[:, j] @ skel.offsets[j]
            cos = np.sum(a * b, -1) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
            assert np.arccos(np.clip(cos, -1, 1)).max() < 1e-5, (case["name"], skel.joints[j])


def test_derived_points_follow_the_page():
    """A skeleton without toes, spine points or hand tips: the derived points as web/motion/skeletonMap.ts places them."""
    # Points in file units (scale 2): hips, both legs and arms, neck base and head; everything else derived.
    source = [-1] * len(CANONICAL_JOINTS)
    named = {"Hips": (0, 1, 0), "LeftUpLeg": (0.1, 0.95, 0), "LeftLeg": (0.1, 0.5, 0), "LeftFoot": (0.1, 0.05, 0),
             "RightUpLeg": (-0.1, 0.95, 0), "RightLeg": (-0.1, 0.5, 0), "RightFoot": (-0.1, 0.05, 0),
             "Neck": (0, 1.5, 0), "Head": (0, 1.7, 0), "LeftArm": (0.2, 1.45, 0), "LeftForeArm": (0.45, 1.45, 0),
             "LeftHand": (0.7, 1.45, 0), "RightArm": (-0.2, 1.45, 0), "RightForeArm": (-0.45, 1.45, 0),
             "RightHand": (-0.7, 1.45, 0)}
    positions = np.zeros((1, len(named), 3))
    for j, (point, p) in enumerate(named.items()):
        source[CANONICAL_JOINTS.index(point)] = j
        positions[0, j] = p
    out = to_canonical(positions, source, 2.0)[0]
    at = lambda name: out[CANONICAL_JOINTS.index(name)]
    assert np.allclose(at("Hips"), (0, 2, 0)) and np.allclose(at("Spine"), (0, 2 + 0.33 * 1.0, 0))
    assert np.allclose(at("Neck1"), (0, 3.2, 0)) and np.allclose(at("Head_end"), (0, 3.6, 0))
    # The figure's left is +x, so it faces +z: toes ahead of the ankle along +z, 2.9 cm below it.
    assert np.allclose(at("LeftToeBase"), (0.2, 0.1 - 0.029, 0.114))
    assert np.allclose(at("LeftToeBase_end"), at("LeftFoot") + 1.5 * (at("LeftToeBase") - at("LeftFoot")))
    assert np.allclose(at("RightHand_end"), (-1.4 - 0.3 * 0.5, 2.9, 0))


def test_own_canonical_fixture_is_current(mocap):
    """tests/fixtures/own_canonical.json (the page's parity cases, tests/unit/ownCanonicalParity.test.ts) is what
    python -m training.fixtures.own_canonical writes today."""
    from training.fixtures.own_canonical_cases import OUT, build
    from conftest import assert_same_json
    assert_same_json(json.loads(json.dumps(build(mocap))), json.loads(OUT.read_text()))
