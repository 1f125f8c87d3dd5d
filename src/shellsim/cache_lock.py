"""numba's compiled-code cache saved by one process at a time.

numba saves a compiled function in two steps: it reads the function's index (its
signatures and their data files), picks the first free data file's number, and writes the
index and the data. Two processes saving different signatures of one function at once
both pick the same number: the index then names, for one signature, the code of the
other, which a later run loads and calls with the wrong argument types. Under
:func:`lock_cache_saves` each save holds an exclusive lock on its cache folder, so the
second reads the first's index and picks the next number. Loading needs no lock: files are
replaced whole, and a data file is only ever rewritten with its own signature's code.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

from numba.core import caching

try:
    import fcntl
except ImportError:  # not a POSIX system: no lock, and so no second process compiling
    fcntl = None

#: The lock's file, one in each cache folder numba writes.
LOCK_FILE = ".save.lock"


@contextmanager
def cache_folder_locked(folder: str) -> Iterator[None]:
    """Holds the exclusive save lock of the cache folder ``folder`` inside the block."""
    handle = os.open(os.path.join(folder, LOCK_FILE), os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield
    finally:
        os.close(handle)  # which releases the lock


def lock_cache_saves() -> bool:
    """From now on, every numba cache save of this process holds its folder's lock (once
    is enough: a second call changes nothing). False where the system has no such lock."""
    if fcntl is None:
        return False
    save = caching.IndexDataCacheFile.save
    if getattr(save, "locked", False):
        return True

    def locked_save(self, key, data):
        with cache_folder_locked(self._cache_path):
            save(self, key, data)

    locked_save.locked = True
    caching.IndexDataCacheFile.save = locked_save
    return True
