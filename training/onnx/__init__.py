"""Writing ONNX files: the graph builder and the manifest of shipped models."""
