"""training/onnx/manifest.register_model keeps the manifest's order, which is the page's (the first model listed with a
capability is its default): a re-exported model keeps its place, a new one goes last."""
import json

from training.onnx.manifest import register_model


def entry(model_id: str, bytes_: int = 1) -> dict:
    return {"id": model_id, "kind": "aclstm", "skeleton": "aclstm-standard", "fps": 30, "bytes": bytes_, "file": f"{model_id}.onnx"}


def test_a_replaced_entry_keeps_its_place_and_a_new_one_goes_last(tmp_path):
    manifest = tmp_path / "index.json"
    manifest.write_text(json.dumps({"models": [entry("zeta"), entry("alpha")]}))
    register_model(entry("zeta", 99), "aclstm-dance", manifest)
    register_model(entry("beta"), "aclstm-dance", manifest)
    models = json.loads(manifest.read_text())["models"]
    assert [m["id"] for m in models] == ["zeta", "alpha", "beta"]
    assert models[0]["bytes"] == 99 and models[0]["commercial"] is True
