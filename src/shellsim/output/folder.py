"""Output folders, created and proven writable before any work is done, and files
replaced atomically in them (a reader never sees half a file)."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import OutputError


def output_folder(path: Path) -> Path:
    """Create ``path`` and prove it writable before any work is done."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".shellsim-write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as error:
        raise OutputError(f"output folder '{path}' is not writable: {error.strerror or error}") from None
    return path


def write_atomically(path: Path, data: str | bytes) -> None:
    """Write ``data`` (text as UTF-8) to ``path`` through a partial file renamed over it."""
    partial = path.with_name(path.name + ".partial")
    try:
        partial.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
        os.replace(partial, path)
    except OSError as error:
        raise OutputError(f"cannot write '{path}': {error.strerror or error}") from None
