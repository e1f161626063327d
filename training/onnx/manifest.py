"""public/models/index.json: the list of shipped models that the page reads at start-up."""
from __future__ import annotations

import json
from pathlib import Path

from ..paths import MODELS_DIR

MANIFEST = MODELS_DIR / "index.json"

# What each shipped model learnt from, and the terms that come with it (../shared/mocap/README.md): the page's model
# pickers and docs/api.md show them. A model trained on Bandai Namco data is non-commercial (CC BY-NC 4.0).
CMU_TERMS = "CMU Graphics Lab Motion Capture Database: free for research and commercial use"
TRAINED_ON = {
    "cmu-locomotion": {"data": "CMU motion capture (mocap.cs.cmu.edu): walking and running", "licence": CMU_TERMS,
                       "commercial": True},
    "aclstm-dance": {"data": "the acLSTM dance set (CMU motion capture: salsa, Indian dance, martial arts)",
                     "licence": CMU_TERMS, "commercial": True},
    "cmu-and-bandai": {"data": "CMU walking and running, and the Bandai Namco Research Motiondataset (walks, turns and "
                               "runs in 7 styles)",
                       "licence": "CC BY-NC 4.0 (Bandai Namco Research Inc.): non-commercial use only", "commercial": False},
}


def register_model(entry: dict, trained_on: str, manifest: Path = MANIFEST) -> None:
    """Add or replace the entry with the same id: {id, kind, skeleton, fps, styles?, bytes, file}, with the data and
    licence of TRAINED_ON[trained_on]. The manifest's order is the page's (the first model listed with a capability is
    its default, web/runtime/registry.ts): a replaced entry keeps its place, a new one goes last."""
    entry = {**entry, **TRAINED_ON[trained_on]}
    data = json.loads(manifest.read_text()) if manifest.exists() else {"models": []}
    ids = [m["id"] for m in data["models"]]
    if entry["id"] in ids:
        data["models"][ids.index(entry["id"])] = entry
    else:
        data["models"].append(entry)
    manifest.write_text(json.dumps(data, indent=1) + "\n")
