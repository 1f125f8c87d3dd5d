"""Output folders, created and proven writable before any work is done, held by one run
at a time and cleared of an earlier run's files, and files replaced atomically in them (a
reader never sees half a file)."""

from __future__ import annotations

import os
import shutil
import sys
from collections.abc import Iterator
from contextlib import contextmanager
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
        partial.unlink(missing_ok=True)  # on a full disk, the room it took is the summary's
        raise OutputError(f"cannot write '{path}': {error.strerror or error}") from None


#: The file in a run's folder that a run holds locked while it writes there.
LOCK_NAME = ".shellsim.lock"
#: The folders this process holds (a run's renders are written under its caller's hold).
_HELD: set[Path] = set()


@contextmanager
def claimed(folder: Path) -> Iterator[None]:
    """Hold ``folder`` for one run: an exclusive lock on its LOCK_NAME file, which the
    system releases however the process ends (no stale lock after a kill), naming this
    process and its command for whoever finds it taken; within a hold of this process's, a
    second is the same one. Raises OutputError, having written nothing, when another run
    holds it."""
    try:
        import fcntl
    except ImportError:  # no POSIX locks here: runs are not kept apart
        yield
        return
    key = folder.resolve()
    if key in _HELD:
        yield
        return
    try:
        lock = open(folder / LOCK_NAME, "a+", encoding="utf-8")
    except OSError as error:
        raise OutputError(f"cannot lock the output folder '{folder}': {error.strerror or error}") from None
    with lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.seek(0)
            raise OutputError(f"'{folder}' is in use by another run ({lock.read().strip() or 'holder unknown'}); wait "
                              "for it to end, or write to another folder (--out)") from None
        lock.seek(0)
        lock.truncate()
        lock.write(f"pid {os.getpid()}: {' '.join(sys.argv)}\n")
        lock.flush()
        _HELD.add(key)
        try:
            yield
        finally:
            _HELD.discard(key)


def clear_earlier_run(folder: Path, names: tuple[str, ...]) -> None:
    """Remove the files and folders ``names`` an earlier run left in ``folder``, so that
    none is taken for the new run's (a summary of a run that ended, frames beyond the new
    run's last)."""
    for name in names:
        path = folder / name
        try:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink(missing_ok=True)
        except OSError as error:
            raise OutputError(f"cannot clear the earlier run's '{path}': {error.strerror or error}") from None
