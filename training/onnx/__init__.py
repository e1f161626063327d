"""Shared ONNX helpers: the graph builder (graph.py), the manifest of shipped models (manifest.py) and CPU
onnxruntime sessions (sessions.py)."""
