"""The unit system of a model file, which states none: recognised from its densities
(a solid's or a tissue's is 300-30,000 kg/m^3 in any system), or given (``shellsim import
--units``); written to the deck's ``meta.units``, which labels renders and plots."""

from __future__ import annotations

#: A density of 1 in each system, in kg/m^3: t/mm^3, kg/mm^3, lbf s^2/in^4.
DENSITY_IN_SI = {"SI": 1.0, "mm-t-s": 1e12, "mm-kg-ms": 1e9, "in-lbf-s": 1.0688e7}
#: The densities of tissue, water, polymers and metals, kg/m^3.
SOLID_DENSITIES = (300.0, 30_000.0)


def recognised(densities: list[float]) -> str | None:
    """The one system in which every density is a solid's, None where none or several
    are (or no density is given)."""
    if not densities:
        return None
    low, high = SOLID_DENSITIES
    fits = [name for name, size in DENSITY_IN_SI.items() if all(low <= rho * size <= high for rho in densities)]
    return fits[0] if len(fits) == 1 else None


def densities(tables: dict) -> list[float]:
    """The densities a model's deck tables give (its materials' and cables')."""
    materials = tables.get("material", [])
    materials = materials if isinstance(materials, list) else [materials]
    return [t["density"] for t in materials + tables.get("cable", []) if "density" in t]


def with_units(tables: dict, given: str | None, notes: list[str]) -> dict:
    """``tables`` with ``meta.units``: ``given``, or recognised from the densities; left
    out, and said in ``notes``, where neither tells."""
    given_densities = densities(tables)
    units = given or recognised(given_densities)
    if units is None:
        notes.append(f"units: the densities ({', '.join(f'{rho:g}' for rho in given_densities) or 'none given'}) "
                     f"name no one unit system; say which with --units ({', '.join(DENSITY_IN_SI)})")
        return tables
    return tables | {"meta": tables.get("meta", {}) | {"units": units}}
