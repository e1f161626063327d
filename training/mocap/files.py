"""Reading motion files: plain or gzipped text, with clear errors for malformed input."""
from __future__ import annotations

import gzip
from pathlib import Path

# Anything bigger than this is not a motion clip we want to hold in memory.
MAX_FRAMES = 1_000_000
MAX_VALUES = 100_000_000


class MotionFormatError(ValueError):
    """Malformed motion input: names the file, the line (1-based) if known, and what was expected."""

    def __init__(self, source: str, message: str, line: int | None = None):
        where = f"{source}:{line}" if line is not None else source
        super().__init__(f"{where}: {message}")
        self.source = source
        self.line = line


def read_text(path: str | Path) -> str:
    """Read a motion file as text; `.gz` files (or gzip magic) are decompressed."""
    path = Path(path)
    data = path.read_bytes()
    if data[:2] == b"\x1f\x8b":
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError) as err:
            raise MotionFormatError(str(path), f"corrupt gzip data ({err})") from None
    return decode_text(data, str(path))


def decode_text(data: bytes, source: str) -> str:
    if not data.strip():
        raise MotionFormatError(source, "file is empty")
    sample = data[:4096]
    junk = sum(1 for b in sample if b < 9 or 13 < b < 32)
    if b"\x00" in sample or junk > len(sample) * 0.05:
        raise MotionFormatError(source, "binary data where a text motion file was expected")
    return data.decode("utf-8", errors="replace")


def parse_floats(tokens: list[str], source: str, line: int) -> list[float]:
    values = []
    for tok in tokens:
        try:
            v = float(tok)
        except ValueError:
            raise MotionFormatError(source, f"expected a number, found {tok!r}", line) from None
        if v != v or v in (float("inf"), float("-inf")):
            raise MotionFormatError(source, f"non-finite value {tok!r}", line)
        values.append(v)
    return values
