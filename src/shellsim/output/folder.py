"""Output folders: created and proven writable before any work is done."""

from __future__ import annotations

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
