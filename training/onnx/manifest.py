"""public/models/index.json: the list of shipped models that the page reads at start-up."""
from __future__ import annotations

import json
from pathlib import Path

from ..paths import MODELS_DIR

MANIFEST = MODELS_DIR / "index.json"


def register_model(entry: dict, manifest: Path = MANIFEST) -> None:
    """Add or replace the entry with the same id: {id, kind, skeleton, fps, styles?, bytes, file}."""
    data = json.loads(manifest.read_text()) if manifest.exists() else {"models": []}
    models = [m for m in data["models"] if m["id"] != entry["id"]] + [entry]
    data["models"] = sorted(models, key=lambda m: m["id"])
    manifest.write_text(json.dumps(data, indent=1) + "\n")
