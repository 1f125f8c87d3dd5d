"""The memory a run of a scene holds, and the refusal of one that cannot fit, before the
work that would find out by running out (meshing included).

The rates are measured on this project's reference machine (docs/verification.md, "Cost
of a scene"): an explicit run holds about 20 kB per element after a base of 0.4 GB (a
90,000-element plate peaked at 1.9 GB); one that takes Newton steps about 165 kB per
element, its tangent and factors (which grow a little faster than its elements) included:
the pinched hemisphere's whole static runs (benchmarks/static_scaling.py; docs/verification.md,
"The pinched hemisphere") peaked at 152, 149 and 163 kB per element over the base at 10^4,
4 x 10^4 and 10^5 elements.
"""

from __future__ import annotations

from .errors import SceneTooLarge

BASE_BYTES, BYTES_PER_ELEMENT = 0.4e9, 20e3
#: A Newton path's (static, implicit, a preload), its tangent and factors included.
NEWTON_BYTES_PER_ELEMENT = 165e3


def memory_bytes(n_elements: int, newton: bool = False) -> float:
    """About how much memory a run of ``n_elements`` holds at its peak [bytes]; ``newton``:
    one that solves by Newton steps (static, implicit or a preload)."""
    return BASE_BYTES + (NEWTON_BYTES_PER_ELEMENT if newton else BYTES_PER_ELEMENT) * n_elements


def available_bytes() -> float | None:
    """Memory available to a new process now [bytes] (Linux), or None where it cannot be read."""
    try:
        with open("/proc/meminfo") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def refuse_if_too_big(n_elements: int, what: str = "the mesh has", newton: bool = False) -> None:
    """Raise SceneTooLarge when a run of ``n_elements`` would not fit in the memory
    available; ``what`` says where the count comes from, ``newton`` as :func:`memory_bytes`."""
    need, have = memory_bytes(n_elements, newton), available_bytes()
    if have is not None and need > have:
        raise SceneTooLarge(f"{what} {n_elements:,} elements: a run needs about {size_text(need)} of memory "
                            f"and {size_text(have)} is available; coarsen [mesh] divisions or use a larger machine")


def size_text(n_bytes: float) -> str:
    """'1.9 GB', '420 MB', '1,000,000,000 GB', '35 kB', '512 bytes'."""
    for unit, size in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n_bytes >= size:
            value = n_bytes / size
            return f"{value:,.0f} {unit}" if value >= 100 else f"{value:.3g} {unit}"
    return f"{n_bytes:,.0f} bytes"
