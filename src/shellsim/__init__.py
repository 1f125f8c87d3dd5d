"""shellsim: explicit dynamics of thin and thick soft-tissue shells with the 9-node
continuum-based shell element."""

import hashlib
import os
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

try:
    __version__ = version("shellsim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"


def _numba_cache_dir() -> str:
    """A compiled-code cache folder keyed by the package's source and LLVM's optimisation
    level.

    numba checks a cached function against its own file only, so after a change to
    element/response.py the time loop in solver/explicit.py would keep running the old
    element code compiled into it. One folder per version of the whole source avoids that.
    """
    digest = hashlib.sha1(os.environ["NUMBA_OPT"].encode())
    for path in sorted(Path(__file__).parent.rglob("*.py")):
        digest.update(path.read_bytes())
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return str(base / "shellsim" / "numba" / digest.hexdigest()[:16])


# LLVM's level 1 compiles the kernels a fifth faster than numba's default 3 and runs them as
# fast, to the same bits (no fast-math is used; docs/verification.md, "Optimisation level").
# Read by numba when it is first imported, or again here when it was imported before shellsim.
os.environ.setdefault("NUMBA_OPT", "1")
os.environ.setdefault("NUMBA_CACHE_DIR", _numba_cache_dir())
# libgomp, the OpenMP runtime numba's parallel loops run on, lets a thread that waits at a
# loop's end spin 300,000 turns before it sleeps: on a busy machine the spinning threads
# hold the CPUs the thread they wait for needs (two threads ran 2-80x slower than one).
# 10,000 turns still bridge the gaps between a step's loops on an idle machine
# (docs/verification.md, "Threads on a busy machine"). Read when numba starts its threads;
# the user's own OMP_WAIT_POLICY or GOMP_SPINCOUNT is kept.
if "OMP_WAIT_POLICY" not in os.environ:
    os.environ.setdefault("GOMP_SPINCOUNT", "10000")
if "numba" in sys.modules:  # imported first, it has read its settings: read them again
    sys.modules["numba"].core.config.reload_config()

#: The Python interface (:mod:`shellsim.api`), imported on first use: ``import shellsim``
#: alone compiles and loads nothing.
__all__ = ["load", "run", "Results"]


def __getattr__(name: str):
    if name in __all__:
        from . import api

        return getattr(api, name)
    raise AttributeError(f"module 'shellsim' has no attribute '{name}'")
