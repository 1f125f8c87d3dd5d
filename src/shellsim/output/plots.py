"""Line plots of a finished run (matplotlib, no display needed): each measured column that
has a quantity of its own (:mod:`shellsim.measures`: a probe's, a valve measure's)
against time, and against the load when one load follows a time curve
(load-displacement curves such as the thesis' Figures 4.29 and 4.33), with the deck's
references drawn on them; and the energies."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..deck.columns import ENERGY_COLUMNS
from ..measures import measured_columns
from ..deck.resolved import read_resolved
from .folder import output_folder, refuse_link, replacing
from .history import read_history
from .units import DisplayUnits

PLOTS_DIR = "plots"
#: Curves of at most this many points show each (a static solve's load steps).
MARKED_POINTS = 200
#: How each reference measure is drawn: as points on the curve, or as a level.
POINT_MEASURES = ("at_time", "final")
LEVEL_MEASURES = ("max", "min", "max_abs")


def _read(folder: Path) -> tuple[object, dict[str, np.ndarray]]:
    """(resolved deck, history columns) of a results folder."""
    return read_resolved(folder), read_history(folder)


def _completed(folder: Path) -> bool:
    """Whether the run in ``folder`` reached its end: its summary says 'completed' (a run
    still going, or one without a summary, has not)."""
    try:
        return json.loads((folder / "summary.json").read_text(encoding="utf-8")).get("status") == "completed"
    except (OSError, ValueError, AttributeError):
        return False


def _load_axis(deck, times: np.ndarray, units: DisplayUnits) -> tuple[np.ndarray, str] | None:
    """(the load at ``times``, in the shown units, and the axis label), or None: the first
    time-curved load summed with every other load of its type on the same place (a
    vessel's diastolic pressure and the pulse above it make one lumen pressure)."""
    curved = [load for load in deck.load if getattr(load, "curve", None) and np.ndim(load.value) == 0]
    if not curved:
        return None
    first = curved[0]
    place = lambda load: (load.type, load.set, getattr(load, "face", None))  # noqa: E731
    total = sum(load.value * deck.curves[load.curve](times) for load in curved if place(load) == place(first))
    return units.scale(first.QUANTITY) * total, units.label(_load_name(first), first.QUANTITY)


def _load_name(load) -> str:
    """What a load is, for an axis: 'pressure on the bottom face', 'edge pressure on
    inlet', ... ('all' of the shell goes unsaid)."""
    where = [] if load.set == "all" else [f"on {load.set}"]
    face = getattr(load, "face", None)
    if face is not None:
        where.append(f"{'on' if not where else 'from'} the {face} face")
    return " ".join([load.type.replace("_", " "), *where])


def plot_run(folder: Path, out_dir: Path | None = None, size: tuple[float, float] = (9.0, 4.0)) -> list[Path]:
    """PNGs of every plotted measure's history (``<name>.png``: probes, valve measures) and of the energies
    (``energy.png``) in ``out_dir`` (default ``folder/plots``). Returns the files written.
    Text from the deck is drawn as written: a '$' in a title is not TeX to parse."""
    from matplotlib import rc_context

    with rc_context({"text.parse_math": False}):
        return _plot_run(folder, out_dir, size)


def _plot_run(folder: Path, out_dir: Path | None, size: tuple[float, float]) -> list[Path]:
    from matplotlib.figure import Figure

    deck, history = _read(folder)
    out_dir = output_folder(out_dir or refuse_link(folder / PLOTS_DIR))
    units = DisplayUnits.of(deck)
    times = history["time"]
    load = _load_axis(deck, times, units)
    whole = _completed(folder)  # a run cut short is judged, and drawn, only at the times it reached
    written = []
    for name, quantity in [(c.name, c.quantity) for c in measured_columns(deck) if c.quantity is not None]:
        measured = ~np.isnan(history[name])  # some measures (a valve's) are taken at some samples only
        scale = units.scale(quantity)
        t, values = times[measured], scale * history[name][measured]
        figure = Figure(figsize=(size[0] if load else 0.6 * size[0], size[1]), layout="constrained")
        axes = figure.subplots(1, 2 if load else 1, squeeze=False)[0]
        ylabel = units.label(name.replace("_", " "), quantity)
        for ax, x, xlabel in zip(axes, (units.scale("time") * t, *((load[0][measured],) if load else ())),
                                 (units.label("time", "time"), *(load[1:] if load else ()))):
            ax.plot(x, values, color="black", lw=1.4, label="this run" + ("" if whole else " (stopped early)"),
                    marker="." if len(t) <= MARKED_POINTS else None, ms=4)
            _draw_references(ax, deck, name, t, x, scale, units.scale("time") if ax is axes[0] else None, whole)
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
        entries = dict(zip(*reversed(axes[0].get_legend_handles_labels())))  # each label once
        if len(entries) > 1 or not whole:  # a lone curve of this run needs no legend
            figure.legend(entries.values(), entries.keys(), loc="outside lower center", fontsize="small")
        figure.suptitle(deck.meta.title, fontsize="medium")
        written.append(_save(figure, out_dir / f"{name}.png"))
    written.append(_plot_energy(deck, history, out_dir / "energy.png", size))
    return written


def _draw_references(ax, deck, probe: str, times: np.ndarray, x: np.ndarray, scale: float,
                     time_scale: float | None, whole: bool = True) -> None:
    """The deck's references on ``probe`` over the axis ``x`` (a function of ``times``),
    their values times ``scale`` (into the shown units); ``time_scale`` is the time's when
    ``x`` is the time axis, None otherwise. Unless the run was ``whole`` (completed), only
    those at a time it reached: a final value or an extreme of the whole run is not
    drawn at a run's last time as if it were met."""
    colours = iter(["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"])
    measures = [r.measure for r in deck.reference if r.probe == probe
                and (whole or r.measure == "at_time" and r.time <= times[-1])]
    for measure in dict.fromkeys(measures):
        refs = [r for r in deck.reference if r.probe == probe and r.measure == measure
                and (whole or r.time <= times[-1])]
        colour = next(colours, "grey")
        label = _wrapped(f"reference ({measure.replace('_', ' ')}): {refs[0].source}")
        if measure in POINT_MEASURES:
            at = [times[-1] if r.measure == "final" else r.time for r in refs]
            ax.errorbar(np.interp(at, times, x), [scale * r.expected for r in refs], fmt="o", color=colour, ms=5,
                        yerr=[scale * _tolerance(r) for r in refs], capsize=3, label=label)
        elif measure in LEVEL_MEASURES:
            for r in refs:
                for level in ((scale * r.expected, -scale * r.expected) if measure == "max_abs"
                              else (scale * r.expected,)):
                    ax.axhline(level, color=colour, ls="--", lw=1, label=label)
        elif measure == "first_peak_time" and time_scale is not None:
            for r in refs:
                ax.axvline(time_scale * r.expected, color=colour, ls="--", lw=1, label=label)


def _tolerance(reference) -> float:
    """The reference's tolerance band half-width, in the quantity's units."""
    if reference.tolerance is not None:
        return reference.tolerance
    return abs(reference.expected) * reference.tolerance_percent / 100.0


def _wrapped(text: str, width: int = 100) -> str:
    """A legend entry in full, on lines of at most ``width`` characters."""
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def _plot_energy(deck, history: dict[str, np.ndarray], path: Path, size: tuple[float, float]) -> Path:
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, layout="constrained")
    ax = figure.subplots()
    units = DisplayUnits.of(deck)
    t = units.scale("time") * history["time"]
    # what the structure holds or has lost: every energy column the history has but the external work
    kept = [name for name in ENERGY_COLUMNS if name != "external_work" and name in history]
    for column in kept:
        ax.plot(t, history[column], label=column.replace("_energy", "").replace("_", " "))
    ax.plot(t, history["external_work"], ls="--", label="external work")
    balance = sum(history[column] for column in kept) - history["external_work"]
    names = " + ".join(column.split("_")[0] for column in kept)
    ax.plot(t, balance, color="black", ls=":", label=f"balance ({names} - external)")
    ax.set_xlabel(units.label("time", "time"))
    ax.set_ylabel(units.label("energy", "energy"))
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    figure.suptitle(deck.meta.title, fontsize="medium")
    return _save(figure, path)


def _save(figure, path: Path) -> Path:
    with replacing(path) as partial:
        figure.savefig(partial, dpi=110)
    return path
