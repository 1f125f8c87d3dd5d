"""The memory a run of a scene holds, and the refusal of one that cannot fit, before the
work that would find out by running out (meshing included).

The rates are measured on this project's reference machine (docs/verification.md, "Cost
of a scene"): a run holds about 20 kB per element after a base of 0.4 GB (a
90,000-element plate peaked at 1.9 GB).
"""

from __future__ import annotations

from .errors import SceneTooLarge

BASE_BYTES, BYTES_PER_ELEMENT = 0.4e9, 20e3


def memory_bytes(n_elements: int) -> float:
    """About how much memory a run of ``n_elements`` holds at its peak [bytes]."""
    return BASE_BYTES + BYTES_PER_ELEMENT * n_elements


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


def refuse_if_too_big(n_elements: int, what: str = "the mesh has") -> None:
    """Raise SceneTooLarge when a run of ``n_elements`` would not fit in the memory
    available; ``what`` says where the count comes from."""
    need, have = memory_bytes(n_elements), available_bytes()
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
