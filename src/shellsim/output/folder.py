"""Output folders, created and proven writable before any work is done, held by one run
at a time and cleared of an earlier run's files, and files replaced atomically in them (a
reader never sees half a file).

Output folders get shared, and a link left in one must not make shellsim write outside
it: every file is written under a new name of its own (created exclusively, so never
through a link) and renamed over its place, which replaces a link there instead of
following it; a file appended to, a subfolder and the lock are refused when a link
stands at their name.
"""

from __future__ import annotations

import functools
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import OutputError


def output_folder(path: Path) -> Path:
    """Create ``path`` and prove it writable before any work is done."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        handle, probe = tempfile.mkstemp(prefix=".shellsim-write-test", dir=path)
        os.close(handle)
        os.unlink(probe)
    except OSError as error:
        raise OutputError(f"output folder '{path}' is not writable: {error.strerror or error}") from None
    return path


@functools.cache
def _umask() -> int:
    """The process's umask (read by setting it, and set back at once)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def refuse_link(path: Path) -> Path:
    """``path``; OutputError when a symbolic link stands at its name (shellsim writes
    nothing through one)."""
    if path.is_symlink():
        raise OutputError(f"'{path}' is a symbolic link: shellsim writes nothing through a link in an output folder; "
                          "remove it, or write to another folder (--out)")
    return path


def open_unlinked(path: Path, mode: str, **options):
    """``open(path, mode, **options)``, refused (OutputError) where a link stands at its
    name, and opened without following one that appears there meanwhile."""
    return open(refuse_link(path), mode, opener=lambda name, flags: os.open(name, flags | os.O_NOFOLLOW, 0o666),
                **options)


def subfolder(folder: Path, name: str) -> Path:
    """``folder / name`` made a folder if it is none yet; OutputError for a link there."""
    path = refuse_link(folder / name)
    try:
        path.mkdir(exist_ok=True)
    except OSError as error:
        raise OutputError(f"cannot make the folder '{path}': {error.strerror or error}") from None
    return path


@contextmanager
def replacing(path: Path) -> Iterator[Path]:
    """A new file of its own beside ``path`` (its suffix kept, for writers that go by
    it) for the body to write, renamed over ``path`` when the body ends, removed when it
    raises. OutputError when it cannot be made or renamed."""
    path = Path(path)
    try:
        handle, partial = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".partial{path.suffix}", dir=path.parent)
        os.close(handle)
        os.chmod(partial, 0o666 & ~_umask())  # as a file opened for writing would be, not mkstemp's 0600
    except OSError as error:
        raise OutputError(f"cannot write '{path}': {error.strerror or error}") from None
    try:
        yield Path(partial)
        os.replace(partial, path)
    except OSError as error:
        raise OutputError(f"cannot write '{path}': {error.strerror or error}") from None
    finally:
        Path(partial).unlink(missing_ok=True)  # on a full disk, the room it took is the summary's


def write_atomically(path: Path, data: str | bytes) -> None:
    """Write ``data`` (text as UTF-8) to ``path`` through a new file renamed over it."""
    with replacing(path) as partial:
        partial.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)


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
        lock = open_unlinked(folder / LOCK_NAME, "a+", encoding="utf-8")
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
