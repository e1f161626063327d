import subprocess
import sys

import numpy as np

from training.data.cmu import build_cache, load_cache
from conftest import REPO


def test_build_cache_for_a_category(mocap, tmp_path):
    path = build_cache(mocap, 30.0, ["other"], tmp_path)
    data = load_cache(path)
    clips = data.clips
    assert len(clips) == 5 and all(c.category == "other" for c in clips)
    n = sum(c.frames for c in clips)
    assert data.fps == 30.0
    assert data.root.shape == (n, 3)
    assert data.rotations.shape == (n, len(data.joints), 4)
    assert data.positions.shape == (n, len(data.joints), 3)
    assert data.contacts.shape == (n, 2) and set(np.unique(data.contacts)) <= {0, 1}
    assert np.allclose(np.linalg.norm(data.rotations, axis=-1), 1, atol=1e-5)
    assert clips[1].start == clips[0].frames


def run_cli(*args, env=None):
    return subprocess.run([sys.executable, "-m", "training.data.build_locomotion", *args], cwd=REPO, capture_output=True, text=True,
                          env=env)


def test_missing_corpus_gives_a_one_line_error(tmp_path):
    result = run_cli("--mocap", str(tmp_path / "nowhere"), "--out", str(tmp_path))
    assert result.returncode != 0
    lines = [l for l in result.stderr.splitlines() if l.strip()]
    assert len(lines) == 1, result.stderr
    assert "nowhere" in lines[0] and "--mocap" in lines[0] and "MOCAP_DIR" in lines[0]


def test_corpus_path_from_environment(tmp_path):
    import os
    env = dict(os.environ, MOCAP_DIR=str(tmp_path / "elsewhere"))
    result = run_cli("--out", str(tmp_path), env=env)
    assert result.returncode != 0 and "elsewhere" in result.stderr and "$MOCAP_DIR" in result.stderr


def test_unknown_category_is_rejected(tmp_path):
    result = run_cli("--categories", "swim", "--out", str(tmp_path))
    assert result.returncode != 0 and "unknown category 'swim'" in result.stderr
