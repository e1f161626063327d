"""Write tests/fixtures/footlock_reference.json: generator motion before and after training/footlock.py.

    python -m training.fixtures_footlock

The browser's port (web/motion/footLock.ts) is checked against these numbers within 1 mm. Two streams
sampled from the shipped generator with onnxruntime (a walk at temperature 0.5 and a run at 1.0, whose
jittery contacts exercise the blends, pivots and reach limits), decoded to world positions. The positions
are rounded to 10 µm first and the foot lock runs on exactly the rounded values, so both sides get the
same input. Only the leg joints of the output are stored: the lock never moves the rest.
"""
from __future__ import annotations

import json

import numpy as np

from .export_generator import MODELS_DIR
from .footlock import BLEND_IN, BLEND_OUT, LEGS, POLE_BIAS, REACH, TOE_GROUND_HEIGHT, foot_lock
from .generate import ShippedGenerator
from .paths import REPO_ROOT

OUT = REPO_ROOT / "tests" / "fixtures" / "footlock_reference.json"
STREAMS = [{"seed_state": 0, "temperature": 0.5}, {"seed_state": 6, "temperature": 1.0}]
FRAMES = 240


def main() -> None:
    gen = ShippedGenerator(MODELS_DIR)
    skel = gen.skel
    gen_offsets = np.array(gen.info["skeleton"]["offsets"]).reshape(-1, 3)
    if np.abs(gen_offsets - skel.offsets).max() > 1e-6:
        raise SystemExit("error: generator.json's skeleton differs from training/canonical_skeleton.json")
    legs = [n for side in ("left", "right") for n in LEGS[side][1:]]  # the joints the lock may move
    leg_index = [skel.index(n) for n in legs]
    streams = []
    for k, s in enumerate(STREAMS):
        features = gen.sample([s["seed_state"]], FRAMES, s["temperature"], rng=np.random.default_rng(k))[0]
        positions = np.round(gen.positions(features), 5)
        contacts = (features[:, -2:] > 0.5).astype(np.uint8)
        locked = foot_lock(positions, contacts, skel)
        moved = np.delete(locked - positions, leg_index, axis=1)
        assert np.abs(moved).max() == 0.0, "the foot lock moved a joint outside the legs"
        streams.append({
            **s, "seed_name": gen.info["seeds"][s["seed_state"]]["name"], "frames": FRAMES,
            "positions": [float(v) for v in positions.reshape(-1)],
            "contacts": contacts.reshape(-1).tolist(),
            "locked_legs": [round(float(v), 6) for v in locked[:, leg_index].reshape(-1)],
        })
    OUT.write_text(json.dumps({
        "joints": skel.joints, "parents": skel.parents, "offsets": [round(float(v), 6) for v in skel.offsets.reshape(-1)],
        "fps": gen.info["fps"], "legs": legs,
        "settings": {"toe_ground_height": TOE_GROUND_HEIGHT, "blend_in_frames": BLEND_IN, "blend_out_frames": BLEND_OUT,
                     "reach": REACH, "pole_bias": POLE_BIAS},
        "streams": streams,
        "note": "positions (frames, joints, 3) world metres rounded to 1e-5, contacts (frames, 2); locked_legs "
                "(frames, legs, 3): footlock.foot_lock of exactly those positions, the joints named in `legs`.",
    }, separators=(",", ":")) + "\n")
    print(f"wrote {OUT} ({OUT.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
