"""onnxruntime sessions on the CPU, as the exports' parity checks, the reports and the fixtures run them."""
from __future__ import annotations

from pathlib import Path

import onnxruntime as ort


def cpu_session(path: Path, threads: int | None = None) -> ort.InferenceSession:
    """A CPU session for the model at `path`; `threads` sets the intra-op threads (None: onnxruntime's default)."""
    options = ort.SessionOptions()
    if threads is not None:
        options.intra_op_num_threads = threads
    return ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
