"""The ``shellsim`` command: parse arguments, call the library, print, set the exit code.

Every user mistake arrives here as a ShellsimError and is printed as a message, never a
traceback; the exit code is then 2 (1 is kept for a failed reference check).
"""

from __future__ import annotations

import functools
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import closing, contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from . import __version__
from .errors import DeckError, OutputError, SceneTooLarge, ShellsimError, Terminated
from .output.folder import output_folder
from .printable import shown
from .signals import handling
from .solver.stability import describe

app = typer.Typer(
    help="Explicit dynamics of thin and thick soft-tissue shells (9-node continuum-based shell).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # plain help: rich markup ate every "[default: ...]" and "[unit]" the option texts give
    rich_markup_mode=None,
)
out = Console()
err = Console(stderr=True)

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143  # 128 + SIGTERM, as shells report it

DeckPath = Annotated[Path, typer.Argument(help="Scene deck (TOML).", show_default=False)]
DeckChanges = Annotated[list[str] | None, typer.Option(
    "--set", help="Change a key of the deck for this run, KEY=VALUE with VALUE written as in TOML (repeat for "
                  "more), e.g. --set solver.damping=300 --set 'solver.mass_scaling={step = 4e-5}'; [[tables]] "
                  "by number from 0: contact.0.penalty=3. The run's deck.toml holds the result.")]


def _scene(deck: Path, changes: list[str] | None):
    """The deck at ``deck`` with the --set ``changes`` made, validated."""
    import tomllib

    from .deck import load_deck
    from .study.jobs import variant_deck

    if not changes:
        return load_deck(deck)
    overrides = {}
    for change in changes:
        key, _, value = change.partition("=")
        if not key.strip() or not value.strip():
            raise typer.BadParameter(f"got '{change}'; expected KEY=VALUE", param_hint="--set")
        try:
            overrides[key.strip()] = tomllib.loads(f"value = {value}")["value"]
        except tomllib.TOMLDecodeError:
            raise typer.BadParameter(f"got '{change}'; expected KEY=VALUE with VALUE as in TOML: a number, true, "
                                     "\"text\", [1, 2] or {key = 1}", param_hint="--set") from None
    return variant_deck(deck, overrides)


@contextmanager
def sigterm_as_interrupt(received: list) -> Iterator[None]:
    """Within the block, SIGTERM raises :class:`Terminated` (a KeyboardInterrupt, so every
    Ctrl-C path closes files and marks the run) and is noted in ``received``."""

    def stop(number: int, _frame: Any) -> None:
        received.append(number)
        raise Terminated

    with handling({signal.SIGTERM: stop}):
        yield


def reports_errors(command: Callable[..., Any]) -> Callable[..., Any]:
    """Turn ShellsimError into a message and exit code 2, Ctrl-C into exit code 130 and
    SIGTERM into 143."""

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        received: list[int] = []
        try:
            with sigterm_as_interrupt(received):
                return command(*args, **kwargs)
        except ShellsimError as error:
            err.print(f"[bold red]error:[/] {shown(str(error))}", highlight=False, markup=True, soft_wrap=True)
            raise typer.Exit(EXIT_USER_ERROR) from None
        except KeyboardInterrupt:
            err.print("[yellow]terminated[/]" if received else "[yellow]interrupted[/]")
            raise typer.Exit(EXIT_TERMINATED if received else EXIT_INTERRUPTED) from None

    return wrapper


def _version(show: bool) -> None:
    if show:
        out.print(f"shellsim {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
) -> None:
    """shellsim: validated TOML decks in, time series and pictures out."""


@app.command()
@reports_errors
def check(deck: DeckPath, changes: DeckChanges = None) -> None:
    """Validate a deck, build its mesh, summarise the scene, and say what its time step and
    step count will be."""
    from .execute import sized_mesh
    from .geometry.crossings import crossing_problem
    from .model import build_model
    from .plan import plan
    from .loads import overlaps_at_rest
    from .solver.outlook import forecast, refuse_if_hopeless

    scene = _scene(deck, changes)
    mesh = sized_mesh(scene, deck.parent, lambda text: err.print(f"[dim]{shown(text)}[/]", highlight=False))
    newton_steps = scene.solver.method != "explicit"  # static or implicit: a tangent's cost
    with err.status("building the model") as status, _compiles_shown(status):
        model = build_model(scene, mesh)
        status.update("timing a tangent and a residual" if newton_steps else "estimating the critical time step")
        outlook = forecast(scene, mesh, model, lambda count: status.update(
            f"estimating the critical time step: {count} stiffness products"), status.update)
    out.print(_summary(scene, mesh, plan(scene), outlook))
    if not newton_steps:
        refuse_if_hopeless(scene, mesh.n_elements, outlook["dt"])
    if scene.solver.ramp_end is not None:  # a static solve, or a static preload
        _warn_of_hanging_nodes(scene, mesh, model)
    with err.status("looking for parts that pass through each other"):
        crossing = crossing_problem(mesh.x, mesh.conn)
    if crossing:
        err.print(f"[yellow]warning:[/] {shown(crossing)}", highlight=False)
    for overlap in overlaps_at_rest(model, scene.contact):
        err.print(f"[yellow]warning:[/] {shown(overlap)}", highlight=False)
    if not newton_steps and scene.solver.mass == "M2" and outlook["M1"] > THIN_SHELL_GAIN * outlook["M2"]:
        err.print(
            f"[yellow]hint:[/] solver.mass = \"M1\" would take a {outlook['M1'] / outlook['M2']:.3g} times larger "
            "step: with M2 the rotary inertia of this thin shell sets the critical step (M1 floors it, "
            "thesis 3.14.1; on coarse meshes that slows bending: Test 1 on 2x2 peaks 7% late, docs/verification.md)"
        )
    if not newton_steps and scene.solver.dt_safety_factor < 1.0:
        err.print(
            f"[yellow]warning:[/] solver.dt_safety_factor = {scene.solver.dt_safety_factor} < 1 "
            "puts the time step above the critical step: the run will be unstable"
        )
    out.print(f"[green]ok[/] {deck}")


def _step_fall(outlook: dict, at_rest: float, end_time: float) -> str:
    """How the forecast followed the step as the loads act: the lowest critical step its
    static rehearsal found, or why it held the step at rest."""
    loaded = outlook["loaded"]
    if loaded["rehearsed_to"] is None:
        why = ("a scene this large is not rehearsed" if not loaded["tried"]
               else "a static solve of its loads did not get past the start")
        return (f"at the step at rest ({why}; the step falls as elements crumple or stiffen, and the steps and "
                "cost grow with it; the run's progress shows the step as it goes)")
    reach = (f"its loads followed statically to t = {loaded['rehearsed_to']:.4g}"
             + (", the step held beyond" if loaded["rehearsed_to"] < end_time * (1 - 1e-9) else ""))
    if loaded["critical"] < 0.95 * at_rest:
        return (f"the critical step falling to {loaded['critical']:.4g} at t = {loaded['at']:.4g} as the loads act "
                f"({reach}; the run's own motion and spreading contact can take it lower)")
    return f"the critical step holding as the loads act ({reach})"


def _warn_of_hanging_nodes(scene, mesh, model) -> None:
    """Warn of nodes that hang on untensioned cables alone: the static tangent has no
    stiffness across their chords at the start, and the first load step stops there."""
    from .errors import id_list, place
    from .loads.cable import untensioned_hanging_nodes

    nodes = untensioned_hanging_nodes(scene.cable, mesh, model.constraints.projector)
    if len(nodes):
        text = (f"{len(nodes)} node(s) hang on cables alone with none of their chords in tension at the start: "
                f"nodes {id_list(nodes + 1)} (the first at {place(mesh.x[nodes[0]])}). A chord at rest has no "
                "stiffness across it, so the static solve's first tangent is singular there: hold them with a "
                "[[boundary]], give their cables rest_length < 1 (a pre-tension), or solve explicitly "
                "(solver.method = \"explicit\")")
        err.print(f"[yellow]warning:[/] {shown(text)}", highlight=False)


def _compiles_shown(status):
    """The kernels compiling inside the block shown on ``status`` (a rich status line), and
    those that took a while printed when done; the status line returns to what it said."""
    from .compile_watch import FIRST_RUN_NOTE, finished_text, watching_compiles

    said = []

    def start(name: str) -> None:
        said.append(status.status)
        status.update(f"compiling {name} ({FIRST_RUN_NOTE})")

    def end(name: str, seconds: float) -> None:
        status.update(said.pop())
        if text := finished_text(name, seconds):
            err.print(f"[dim]{shown(text)}[/]", highlight=False)

    return watching_compiles(start, end)


@app.command()
@reports_errors
def mesh(
    deck: DeckPath,
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for mesh.vtu and mesh.png.")] = Path("results"),
    png: Annotated[bool, typer.Option(help="Also render mesh.png.")] = True,
) -> None:
    """Build the scene's geometry with gmsh as 9-node quads: OUT/mesh.vtu and OUT/mesh.png."""
    from .deck import load_deck
    from .geometry import build_mesh
    from .output.mesh_files import write_mesh_vtu

    scene = load_deck(deck)
    folder = output_folder(out_dir)
    err.print(f"meshing {shown(str(deck))}", highlight=False)
    built = build_mesh(scene, deck.parent)
    write_mesh_vtu(built, folder / "mesh.vtu")
    written = [folder / "mesh.vtu"]
    if png:
        from .output.render import render_mesh

        render_mesh(built, folder / "mesh.png")
        written.append(folder / "mesh.png")
    sets = ", ".join(f"{name} ({s.kind}, {len(s.nodes)})" for name, s in sorted(built.sets.items()))
    out.print(f"{shown(scene.meta.title)}: {built.n_elements} elements, {built.n_nodes} nodes, "
              f"{5 * built.n_nodes} DOFs")
    out.print(f"sets: {sets}", highlight=False)
    _announce(written)


@app.command("import")
@reports_errors
def import_model(
    model: Annotated[Path, typer.Argument(help="Model file: Abaqus input (.inp) or FEBio (.feb).",
                                          show_default=False)],
    out_dir: Annotated[Path | None, typer.Option("--out", help="Folder for deck.toml and the mesh [default: the "
                                                              "model's name].")] = None,
    user_material: Annotated[str | None, typer.Option(
        "--user-material", help="The law of the file's user materials, each with its own constants: 'MODEL: KEY = "
                                "$n | number, ...' ($n: the n-th constant), e.g. 'lee_sacks: c0 = $1, c1 = $2, "
                                "c2 = $3, c3 = 0, delta = 1'.")] = None,
    units: Annotated[str | None, typer.Option(
        "--units", help="The file's unit system (SI, mm-t-s, mm-kg-ms, in-lbf-s) [default: recognised from its "
                        "densities].")] = None,
) -> None:
    """Bring a model made with another program over as an editable deck and its mesh:
    shells as 9-node quads with their sets and material axes, and the material, section,
    supports, loads, contact, amplitudes and first step as deck tables. What has no
    counterpart is listed (and written at the top of the deck), never dropped silently."""
    from .foreign.units import DENSITY_IN_SI
    from .foreign.user_law import UserLaw
    from .imported_deck import import_model as bring_over

    user_law = UserLaw.parse(user_material) if user_material is not None else None
    if units is not None and units not in DENSITY_IN_SI:
        raise DeckError("--units", [f"got '{units}'; expected one of {', '.join(DENSITY_IN_SI)}"])
    folder = output_folder(out_dir or Path(model.stem))
    with err.status(f"reading {model}"):
        done = bring_over(model, folder, user_law, units)
    sets = ", ".join(f"{name} ({kind})" for name, kind in sorted(done.sets.items()))
    cables = f", {done.cables} cable elements" if done.cables else ""
    out.print(f"{shown(str(model))}: {done.elements} elements{cables}; sets: {shown(sets) or 'none'}",
              highlight=False)
    if done.units is not None:
        out.print(f"units: {done.units} (meta.units){'' if units else ', recognised from the densities; say --units otherwise'}")
    if done.unmapped:
        err.print("[yellow]not brought over[/] (listed at the top of the deck too):")
        for line in done.unmapped:
            err.print(f"  - {shown(line)}", highlight=False)
    _announce([done.deck, done.mesh, done.ids])
    if done.problems:
        err.print(f"[yellow]{done.deck} needs editing before it runs:[/]")
        for line in done.problems:
            err.print(f"  - {shown(line)}", highlight=False)
    else:
        out.print(f"[green]ok[/] shellsim check {done.deck}; shellsim run {done.deck}")


def _announce(paths: Any) -> None:
    """One 'wrote PATH' line per file written."""
    for path in paths:
        out.print(f"wrote {path}")


EXIT_REFERENCE_FAILED = 1
EXIT_UNSTABLE = 3


@app.command()
@reports_errors
def run(
    deck: Annotated[Path | None, typer.Argument(help="Scene deck (TOML); none with --resume.", show_default=False)] = None,
    out_dir: Annotated[Path | None, typer.Option("--out", help="Output folder [default: results/DECK-NAME].")] = None,
    resume: Annotated[Path | None, typer.Option(
        "--resume", help="Go on from the checkpoint in a run's folder (output.checkpoint_interval), to its deck's "
                         "end.")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False,
    changes: DeckChanges = None,
) -> None:
    """Run a scene: in time by explicit central differences, or as equilibria by Newton
    load steps (solver.method = "static"), or in time by implicit Newton steps (solver.method =
    "implicit"). Writes OUT/summary.json,
    OUT/history.csv, OUT/deck.toml (the resolved deck), the frames (OUT/results.xdmf + .h5,
    and OUT/results.pvd + OUT/frames/ when asked) and the deck's renders. With --resume
    FOLDER, a run that stopped goes on from its last checkpoint there, with the deck it was
    run with, to the same answer as if it had not stopped. Exit code 1 when a reference
    check fails, 3 when the run goes unstable, 130 on Ctrl-C and 143 on SIGTERM (what was
    written stays readable; the summary says interrupted)."""
    from .compile_watch import watching_compiles
    from .deck.resolved import RESOLVED_NAME, read_resolved
    from .execute import run_scene
    from .output.checkpoint import read_checkpoint
    from .output.folder import claimed
    from .output.progress import ProgressDisplay

    if (deck is None) == (resume is None):
        raise typer.BadParameter("give a deck to run, or --resume and a run's folder to go on with it"
                                 + (", not both" if deck else ""), param_hint="DECK / --resume")
    if resume is not None:
        if out_dir is not None:
            raise typer.BadParameter("a resumed run goes on in its own folder", param_hint="--out")
        if changes:
            raise typer.BadParameter("a resumed run goes on with the deck it was run with", param_hint="--set")
        checkpoint = read_checkpoint(resume)
        scene, deck, folder = read_resolved(resume), resume / RESOLVED_NAME, resume
    else:
        checkpoint, scene = None, _scene(deck, changes)
        folder = output_folder(out_dir or Path("results") / deck.stem)  # before any work is done
    with claimed(folder):  # the renders too
        with closing(ProgressDisplay(out, scene.solver.end_time, quiet)) as progress, \
                watching_compiles(progress.compiling, progress.compiled):
            current, result = run_scene(scene, deck, folder, progress, progress.announce, checkpoint)
        message = result["message"]
        if current.status == "interrupted":
            raise KeyboardInterrupt
        if current.status == "refused":
            raise SceneTooLarge(message)
        if current.status == "output failed":
            raise OutputError(message)
        if current.status == "completed":
            from .output.render import deck_renders

            written = deck_renders(scene, folder)
            if not quiet:
                _announce(written)
    if not quiet:
        out.print(_run_report(result, folder))
        out.print(_what_to_open(folder), highlight=False)
    if current.status in ("unstable", "not converged"):
        err.print(f"[bold red]error:[/] {shown(message)}", highlight=False)
        raise typer.Exit(EXIT_UNSTABLE)
    if not all(r["passed"] for r in result["reference"]):
        raise typer.Exit(EXIT_REFERENCE_FAILED)


def _run_report(result: dict, folder: Path) -> Table | str:
    """The run's references as a table (or a line without them); the deck's texts are shown
    as written, never read as markup."""
    e = result["energy"]
    static = result.get("static")
    caption = ((f"{static['load_steps']} load steps, {static['iterations']} Newton iterations "
                f"({static['tangents']} tangents), "
                f"{static['cutbacks']} cut back, load time reached {static['load_time_reached']:.6g} (largest "
                f"{static['largest_load_time']:.6g}), {result['wall_time_s']:.2f} s") if static else
               (f"{result['steps']} steps, {result['wall_time_s']:.2f} s, "
                f"{result['us_per_element_step']:.2f} us/element-step, energy balance "
                f"{e['balance_error_percent']:+.3f}%")
               + (f", volume change {result['volume_change_percent']:+.3f}%" if "volume_change_percent" in result else "")
               + f"; results in {shown(str(folder))}")
    title = f"{shown(result['title'])}: {result['status']}"
    passed = [shown(describe(event)) for event in (static or {}).get("stability", [])]
    if not result["reference"]:
        return "\n".join([title, *passed, caption])
    notes = [*passed, *(shown(f"{r['quantity']}: {r['note']}") for r in result["reference"] if "note" in r)]
    table = Table(title=title, title_justify="left", caption="\n".join([*notes, caption]))
    for column in ("quantity", "computed", "expected", "error", "tolerance", "ok"):
        table.add_column(column)
    for r in result["reference"]:
        tolerance = f"{r['tolerance_percent']}%" if r["tolerance"] is None else f"{r['tolerance']}"
        error = "-" if r["computed"] is None else (
            f"{r['error_percent']:+.3f}%" if r["error_percent"] is not None else f"{r['error']:+.4g}")
        table.add_row(shown(r["quantity"]), "-" if r["computed"] is None else f"{r['computed']:.6g}",
                      f"{r['expected']:.6g}", error, tolerance,
                      {True: "[green]yes", False: "[red]no", None: "-"}[r["passed"]])
    return table


def _what_to_open(folder: Path) -> str:
    """The closing lines: where the results are and what to open them with."""
    series = [name for name in ("results.xdmf", "results.pvd") if (folder / name).exists()]
    lines = [f"results in {shown(str(folder))}/:"]
    if series:
        lines.append(f"  paraview {shown(str(folder / series[0]))}   every frame at its time (ParaView 5.11 or newer)")
    if (folder / "renders").is_dir():
        lines.append(f"  {shown(str(folder / 'renders'))}/   the deck's pictures; shellsim render {shown(str(folder))} "
                     "--field F for others")
    lines.append(f"  shellsim plot {shown(str(folder))}   the probes' histories, against the load too, with the "
                 "references; history.csv holds them as numbers")
    return "\n".join(lines)


def _newton_cost(outlook: dict) -> str:
    """The cost row of a static or implicit solve (:func:`shellsim.solver.outlook.forecast`)."""
    from .memory import size_text
    from .solver.outlook import duration

    iterations, tangents = outlook["pace"]
    basis = (f"the solve rehearsed to its end: {iterations:.3g} iterations and {tangents:.3g} tangents a step"
             if outlook["rehearsed"] else
             f"at {iterations:g} iterations and {tangents:g} tangents a step, as the shipped decks took them: "
             f"{duration(outlook['tangent_seconds'])} a tangent ({outlook['tangent_timed']}), "
             f"{duration(outlook['residual_seconds'])} a residual at rest; a stiffening or contacting scene takes more")
    return (f"{outlook['unknowns']:,} unknowns; about {outlook['steps']:,} steps and {duration(outlook['seconds'])} "
            f"on this machine ({basis}), {size_text(outlook['bytes'])} of memory")


def _frame_choice(value: str) -> str | int:
    if value in ("last", "all"):
        return value
    try:
        return int(value)
    except ValueError:
        raise typer.BadParameter(f"expected 'last', 'all' or a frame number, got '{value}'") from None


def _size(value: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in value.lower().split("x"))
    except ValueError:
        raise typer.BadParameter(f"expected WIDTHxHEIGHT in pixels, e.g. 1200x900, got '{value}'") from None
    if not (16 <= width <= 8192 and 16 <= height <= 8192):
        raise typer.BadParameter(f"{width}x{height}: each side must be 16 to 8192 pixels")
    return width, height


@app.command()
@reports_errors
def render(  # noqa: PLR0913 (the command's options, each defaulted)
    results: Annotated[Path, typer.Argument(help="A run's output folder.", show_default=False)],
    field: Annotated[str, typer.Option(help="Field to colour by (as written: pressure_band, von_mises, "
                                            "cauchy_stress, displacement, thickness, ..._nodal).")] = "pressure_band",
    component: Annotated[str | None, typer.Option(help="Component of a vector (x, y, z, magnitude) or "
                                                       "tensor (XX, YY, ZZ, XY, YZ, XZ; either case, either "
                                                       "order) field.")] = None,
    frame: Annotated[str, typer.Option(help="'last', 'all' (also an animated GIF) or a frame number "
                                            "(negative counts from the end).")] = "last",
    view: Annotated[str, typer.Option(help="iso, top, front or side.")] = "iso",
    size: Annotated[str, typer.Option(help="Picture size in pixels, WIDTHxHEIGHT.")] = "1200x900",
    out_dir: Annotated[Path | None, typer.Option("--out", help="Folder for the pictures [default: RESULTS/renders].")] = None,
    show: Annotated[list[str] | None, typer.Option(help="Draw also (repeat for both): 'fibres', the fibre "
                                                        "directions (written with output.fields 'fibres'); "
                                                        "'outline', the initial shape's element outlines.")] = None,
    colour_range: Annotated[str, typer.Option(
        "--range", help="The colour bar's limits: 'robust' (the middle 98% of the values, where a few stray "
                        "ones would take the scale; the picture says so), 'full' (every value), or 'LOW,HIGH' "
                        "in the units shown.")] = "robust",
) -> None:
    """Render a field of a run on its deformed shape: off-screen PNGs with a labelled scalar
    bar, element outlines, and each sub-cell coloured by its integration point's value."""
    from .output.render import VIEWS, Overlays, render_field

    if view not in ("iso", *VIEWS):
        raise typer.BadParameter(f"unknown view '{view}'; expected iso, {', '.join(VIEWS)}", param_hint="--view")
    unknown = set(show or []) - set(Overlays._fields)
    if unknown:
        raise typer.BadParameter(f"cannot show {', '.join(sorted(unknown))}; expected {', '.join(Overlays._fields)}",
                                 param_hint="--show")
    with err.status(f"rendering {field}") as status:
        written = render_field(results, field, _frame_choice(frame), view, _size(size), component, out_dir,
                               Overlays(**{name: True for name in show or []}),
                               lambda done, total: status.update(f"rendering {field}: {done} of {total} frames"),
                               _colour_range(colour_range))
    _announce(written)


def _colour_range(text: str) -> str | tuple[float, float]:
    """--range: 'robust', 'full' or 'LOW,HIGH' with LOW < HIGH."""
    if text in ("robust", "full"):
        return text
    try:
        low, high = (float(part) for part in text.split(","))
    except ValueError:
        low = high = float("nan")
    if not low < high:
        raise typer.BadParameter(f"got '{text}'; expected robust, full or LOW,HIGH with LOW < HIGH (e.g. 50,95)",
                                 param_hint="--range")
    return low, high


@app.command()
@reports_errors
def plot(
    results: Annotated[Path, typer.Argument(help="A run's output folder.", show_default=False)],
    out_dir: Annotated[Path | None, typer.Option("--out", help="Folder for the plots [default: RESULTS/plots].")] = None,
) -> None:
    """Plot a run's histories: every probe against time (and against the load when a load
    follows a time curve) with the deck's references, and the energies (PNG)."""
    from .output.plots import plot_run

    _announce(plot_run(results, out_dir))


@app.command()
@reports_errors
def report(
    study: Annotated[Path, typer.Argument(help="A study (TOML): decks and the variants of each.", show_default=False)],
    out_dir: Annotated[Path | None, typer.Option("--out", help="Report folder [default: results/STUDY-NAME].")] = None,
    scheduler: Annotated[str | None, typer.Option(help="A running dask scheduler, tcp://HOST:PORT "
                                                       "[default: a local cluster].")] = None,
    workers: Annotated[int | None, typer.Option(min=1, help="Workers of the local cluster [default: one per usable CPU].")] = None,
    connect_timeout: Annotated[float, typer.Option(min=0.1, help="Seconds to wait for --scheduler to answer.")] = 5.0,
    embed_in: Annotated[Path | None, typer.Option("--embed", help="Also write the table into this markdown file, "
                                                  "between '<!-- report STUDY-NAME -->' and "
                                                  "'<!-- end report STUDY-NAME -->'.")] = None,
) -> None:
    """Run every variant of a study through dask and report error against run time:
    OUT/report.md, OUT/report.csv and OUT/error_vs_time.png, updated as jobs finish, and
    each run's files under OUT/runs/. Exit code 1 when a job did not end as its variant
    expects (completed, or unstable on purpose) or missed a reference."""
    from rich.progress import Progress

    from .study.executor import open_client, prepare_workers, rows_in_order, run_jobs
    from .study.jobs import as_expected, study_jobs
    from .study.report import embed, embed_span, read_external, write_report
    from .study.schema import load_study

    plan_ = load_study(study)
    if embed_in is not None:
        embed_span(embed_in, study.stem)  # a missing marker is found now, not after the runs
    folder = output_folder(out_dir or Path("results") / study.stem)
    jobs = study_jobs(plan_, study, folder)
    external = read_external(study.parent / plan_.external.path) if plan_.external else []
    rows: list[dict] = []
    write_report(folder, plan_.meta.title, rows, len(jobs), external)
    with err.status(f"connecting to the dask scheduler at {scheduler}" if scheduler else
                    "starting a local dask cluster"):
        client = open_client(scheduler, workers, connect_timeout)
    with client:
        # from an empty cache the kernels compile here (a local cluster) or in each worker
        with err.status("the workers load the kernels") as status, _compiles_shown(status):
            prepare_workers(client, local=scheduler is None)
        with Progress(console=out, transient=True) as bar:
            task = bar.add_task(f"{len(jobs)} jobs", total=len(jobs))

            def on_row(row: dict) -> None:
                rows.append(row)
                write_report(folder, plan_.meta.title, list(rows_in_order(jobs, rows)), len(jobs) - len(rows),
                             external)
                bar.advance(task)
                error = "-" if row["error_percent"] is None else f"{row['error_percent']:.3g}%"
                out.print(f"{row['family']} / {row['variant']}: {row['status']}, error {error}", highlight=False)

            # a local cluster has one worker process per usable CPU: one kernel thread per job
            try:
                run_jobs(jobs, client, on_row, threads=1 if scheduler is None else None)
            except KeyboardInterrupt:  # the report says the study did not finish
                write_report(folder, plan_.meta.title, list(rows_in_order(jobs, rows)), len(jobs) - len(rows),
                             external, interrupted=True)
                raise
    written = [folder / name for name in ("report.md", "report.csv", "error_vs_time.png")]
    if embed_in is not None:
        embed(embed_in, study.stem, list(rows_in_order(jobs, rows)))
        written.append(embed_in)
    _announce(written)
    if not all(as_expected(r) for r in rows):
        raise typer.Exit(EXIT_REFERENCE_FAILED)


@app.command()
@reports_errors
def bench(
    out_dir: Annotated[Path | None, typer.Option("--out", help="Also write bench.json here.")] = None,
) -> None:
    """Measure speed: microseconds per element per step of each constitutive path on the
    Scordelis-Lo roof (16 x 16) on one thread and on every core, GFLOP/s against a
    one-thread matrix product, the bench plate's error and wall time per mesh, and the
    share of the step that contact between shells takes (two stacked plates of 9,800
    elements, every node touching)."""
    from .bench import contact_cost, dgemm_gflops, path_speeds, plate_ladder

    with err.status("bench: the constitutive paths") as status, _compiles_shown(status):
        rows = path_speeds(on_path=lambda label, count: status.update(f"bench: {label}, {count} thread(s)"))
        status.update("bench: a matrix product on one thread")
        dgemm = dgemm_gflops()
    out.print(_paths_table(rows))
    for row in rows:
        if "gflops" in row:
            out.print(f"{row['path']}, {row['threads']} thread(s): {row['flops_per_element_step']:,} flop per "
                      f"element-step, {row['gflops']:.2f} GFLOP/s = {100 * row['gflops'] / (dgemm * row['threads']):.1f}% "
                      f"of a one-thread matrix product's {dgemm:.1f} GFLOP/s per thread")
    with err.status("bench: the bench plate at 2 x 2, 4 x 4 and 8 x 8") as status, _compiles_shown(status):
        ladder = plate_ladder()
    table = Table(title="bench plate (decks/bench/plate_step.toml): first peak", title_justify="left")
    for column in ("mesh", "elements", "steps", "start-up: mesh + model + kernels + first dt [s]", "wall time [s]",
                   "us/element-step", "peak error", "peak time error"):
        table.add_column(column)
    for row in ladder:
        startup = " + ".join(f"{row['startup_s'][k]:.2f}" for k in ("mesh_s", "model_s", "kernels_s", "first_dt_s"))
        table.add_row(row["mesh"], str(row["elements"]), str(row["steps"]), startup, f"{row['wall_time_s']:.2f}",
                      f"{row['us_per_element_step']:.2f}", f"{row['peak_error_percent']:+.3f}%",
                      f"{row['peak_time_error_percent']:+.3f}%")
    out.print(table)
    with err.status("bench: contact between shells, two plates of 9,800 elements") as status, _compiles_shown(status):
        contact = contact_cost()
    costs = Table(title="contact between shells (two stacked plates, every node touching)", title_justify="left")
    for column in ("scene", "elements", "us/element-step", "contact's share of the step"):
        costs.add_column(column)
    for row in contact:
        share = f"{100 * row['contact_share']:.0f}%" if "contact_share" in row else "-"
        costs.add_row(row["scene"], str(row["elements"]), f"{row['us_per_element_step']:.2f}", share)
    out.print(costs)
    if out_dir is not None:
        from .output.summary import write_json

        write_json({"paths": rows, "dgemm_gflops_one_thread": dgemm, "plate": ladder, "contact": contact},
                   output_folder(out_dir) / "bench.json")


def _paths_table(rows: list[dict]) -> Table:
    """Microseconds per element-step of each constitutive path (rows of
    :func:`shellsim.bench.path_speeds`), one column per thread count."""
    elements = rows[0]["elements"]
    threads = sorted({r["threads"] for r in rows})
    paths = Table(title=f"constitutive paths (Scordelis-Lo, {elements} elements, {rows[0]['steps']} steps): "
                        "us per element-step", title_justify="left")
    for column in ("path", *(f"{t} thread{'s' * (t > 1)}" for t in threads), "speed-up"):
        paths.add_column(column)
    by_path: dict[str, dict[int, dict]] = {}
    for row in rows:
        by_path.setdefault(row["path"], {})[row["threads"]] = row
    for path, runs in by_path.items():
        first, last = runs[threads[0]]["us_per_element_step"], runs[threads[-1]]["us_per_element_step"]
        paths.add_row(path, *(f"{runs[t]['us_per_element_step']:.2f}" for t in threads), f"{first / last:.2f} x")
    return paths


#: ``check`` suggests M1 to an M2 scene when M1's critical step is this many times larger.
THIN_SHELL_GAIN = 2.0


def _summary(scene: Any, built: Any, needs: Any, outlook: dict) -> Table:
    from .memory import size_text
    from .solver.outlook import duration

    table = Table(title=shown(scene.meta.title), show_header=False, title_justify="left")
    table.add_column(style="bold")
    table.add_column()

    def row(label: str, text: str) -> None:  # deck text is shown as written, never read as markup
        table.add_row(label, shown(text))

    g = scene.geometry
    params = ", ".join(f"{k}={v}" for k, v in g.model_dump().items() if k != "builder")
    row("units", scene.meta.units)
    if scene.meta.source:
        row("source", scene.meta.source)
    row("geometry", f"{g.builder} ({params})")
    divisions = " x ".join(f"{v} {k}" for k, v in scene.mesh.divisions.items())
    cables = f", {len(built.lines)} cable elements" if len(built.lines) else ""
    row("mesh", f"{built.n_elements} elements ({divisions or 'from file'}){cables}, "
                          f"{built.n_nodes} nodes, {5 * built.n_nodes} DOFs")
    for m in scene.material:
        params = ", ".join(f"{k}={v}" for k, v in m.model_dump().items() if k not in ("model", "axes", "sets"))
        row("material", f"{m.model} ({params})" + (f" on {', '.join(repr(s) for s in m.sets)}" if m.sets else ""))
    s = scene.section
    strain = f"technique {s.technique}" if s.technique else "small strain"
    row("section", f"thickness {s.thickness}, {s.points_through_thickness} points through "
                             f"it, {strain}, {s.formulation} formulation"
                             + (", plane strain" if s.plane_strain else ""))
    for bc in scene.boundary:
        row("boundary", f"{bc.type} on '{bc.set}'")
    for load in scene.load:
        curve = f" x curve '{load.curve}'" if load.curve else ""
        row("load", f"{load.type} {load.value}{curve} on '{load.set}'")
    for contact in scene.contact:
        row("contact", f"{contact.summary} ({len(built.sets[contact.set].nodes)} nodes)")
    for cable in scene.cable:
        row("cable", cable.summary)
    sv = scene.solver
    if sv.method == "static":
        st = sv.static
        steps = ("arc-length steps along the path (the load found with the shape) until the clock passes"
                 if st.control == "arc_length" else f"{st.newton} Newton-Raphson load steps to")
        row("solver", f"static: {steps} t = {sv.end_time}, {st.increments} "
                                f"first, at most {st.max_iterations} iterations each, tolerances force "
                                f"{st.force_tolerance:g}, energy {st.energy_tolerance:g}")
        row("cost", _newton_cost(outlook))
    elif sv.method == "implicit":
        im = sv.implicit
        row("solver", f"implicit dynamics (HHT, alpha {im.alpha:g}) to t = {sv.end_time} in {im.increments} time "
                      f"steps first ({im.newton} Newton, at most {im.max_iterations} iterations each), mass {sv.mass}"
                      + (f", damping {sv.damping}/s" if sv.damping else ""))
        row("cost", _newton_cost(outlook))
    else:
        if sv.preload is not None:
            row("preload", f"static load steps to t = {sv.preload} ({sv.static.increments} first), "
                                     "then the explicit run from rest in that equilibrium")
        row("solver", f"to t = {sv.end_time}, dt = dt_crit / {sv.dt_safety_factor} "
                                f"(TSSFAC {1 / sv.dt_safety_factor:.3g}), mass {sv.mass}"
                                + (f", damping {sv.damping}/s" if sv.damping else ""))
        row("time step", f"critical {outlook[sv.mass]:.4g} at t = 0 (M1 {outlook['M1']:.4g}, "
                                   f"M2 {outlook['M2']:.4g})"
                                   + (f"; every mass x {outlook['mass_factor']:.4g} for the mass scaling's step "
                                      f"{outlook['dt']:.4g}" if outlook["mass_factor"] > 1.0 else "")
                                   + f": about {outlook['steps']:,} steps "
                                   + ("to the end" if outlook["until"] >= sv.end_time else
                                      f"to t = {outlook['until']:.4g}, where its curves hold and it may first come "
                                      "to rest")
                                   + ", " + _step_fall(outlook, outlook[sv.mass], sv.end_time))
        contact = (f"; contact {100 * outlook['contact_share']:.0f}% of each step at rest, more as it spreads"
                   if outlook["contact_share"] else "")
        row("cost", f"about {duration(outlook['seconds'])} of stepping on this machine "
                    f"({duration(outlook['seconds'] / sv.end_time)} per unit of simulated time{contact}), "
                    f"{size_text(outlook['bytes'])} of memory")
    for ref in scene.reference:
        tolerance = f"{ref.tolerance_percent}%" if ref.tolerance is None else f"{ref.tolerance}"
        row("reference", f"{ref.quantity}: {ref.expected} ± {tolerance} "
                                   f"({ref.measure} of probe '{ref.probe}'; {ref.source})")
    row("uses", ", ".join(needs.used()) or "linear small-strain shell only")
    row("leaves out", ", ".join(needs.left_out()))
    return table


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
