"""The deck: one TOML file describing one scene. Every table is validated here; references
between tables (set, curve and probe names) are checked in :mod:`shellsim.deck.references`.

A deck states only what its scene needs: everything else has a default, and the resolved
deck (defaults filled) is what the program runs.
"""

from __future__ import annotations

import json
from itertools import combinations
from typing import Annotated, ClassVar, Literal, Union, get_args

import numpy as np
from pydantic import BeforeValidator, Field, create_model, field_serializer, field_validator, model_validator

from .curves import Curve
from .output_fields import FIELD_KINDS, WRITTEN_AS, field_problems
from .geometry import BUILDERS, Geometry, division_problems, proportion_problems
from .material import MATERIALS, Material
from ..materials.axes import CentrelineAxes, CylindricalAxes
from ..loads import CABLE_TABLES, CONTACT_TABLES, friction_in_newton
from ..loads import TABLES as LOAD_TABLES
from ..measures import OUTPUT_FIELDS
from ..table_types import Count, Line, Name, NonNegative, Positive, Real, Section, Text, Vec3

Axis = Literal["x", "y", "z"]

#: Each unit system's units of length, stress (and pressure) and time (``consistent``
#: names none).
SYSTEMS = {name: {"length": length, "stress": stress, "pressure": stress, "time": time, "energy": energy}
           for name, (length, stress, time, energy) in {
               "SI": ("m", "Pa", "s", "J"), "mm-t-s": ("mm", "MPa", "s", "mJ"), "mm-kg-ms": ("mm", "GPa", "ms", "J"),
               "in-lbf-s": ("in", "psi", "s", "in lbf")}.items()}
SYSTEMS["consistent"] = {}
#: The units a render or plot may show, by kind, each with its size in SI units. A
#: pressure (a pressure load) may be shown in other units than the stresses.
_STRESS_SIZES = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9, "mmHg": 133.322387415, "psi": 6894.757293168}
UNIT_SIZES = {"length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "in": 0.0254},
              "stress": _STRESS_SIZES, "pressure": _STRESS_SIZES, "time": {"s": 1.0, "ms": 1e-3}}


class Meta(Section):
    """What the scene is. ``units`` names the unit system the deck's numbers are in, for
    printouts; nothing is converted."""

    title: Annotated[Line, Field(min_length=1)]
    units: Literal[tuple(SYSTEMS)] = "SI"
    description: Text = ""
    source: Text = ""


class MeshOptions(Section):
    """``[mesh]``: element divisions per builder direction (see the builder), optional
    irregular element boundaries of a rectangle (fractions of its length along y = 0 and
    y = width, 0 first and 1 last), and extra named points at nodes (on a remeshed surface,
    the node nearest within half an element)."""

    divisions: dict[str, Count] = {}
    boundaries_y0: list[Real] | None = None
    boundaries_y1: list[Real] | None = None
    points: dict[Name, Vec3] = {}

    @field_validator("boundaries_y0", "boundaries_y1")
    @classmethod
    def _fractions(cls, b: list[float] | None) -> list[float] | None:
        if b is None:
            return b
        if len(b) < 2 or b[0] != 0.0 or b[-1] != 1.0:
            raise ValueError(f"must run from 0 to 1 (fractions of the length), got {b}")
        if any(b1 <= b0 for b0, b1 in zip(b, b[1:])):
            raise ValueError(f"must be strictly increasing, got {b}")
        return b


class ShellSection(Section):
    """``[section]``: the shell through its thickness.

    ``technique`` selects the large-strain constitutive treatment of thesis 3.10; leave it
    out for small strain (linear elastic only). 1: total formulation with a strain energy
    (the hyperelastic laws; St. Venant-Kirchhoff for a linear elastic material). 2 and 3:
    a linear elastic material at large strain, its stresses accumulated step by step from
    the strain increments in the lamina frame (2 also pushes them forward with each
    step's stretch, Eqs 3.29-3.30); they set the formulation themselves. ``plane_strain`` replaces the
    zero-normal-stress lamina law by plane strain through the thickness direction (an
    in-plane model of a long body, thesis Test 7). ``thickness_update`` is the fibre-length
    update of thesis 3.11 (on by default with a large-strain technique).
    """

    thickness: Positive
    points_through_thickness: Literal[1, 2, 3] = 2
    technique: Literal[1, 2, 3] | None = None
    formulation: Literal["total", "incremental"] = "total"
    plane_strain: bool = False
    thickness_update: bool | None = None

    @model_validator(mode="after")
    def _thickness_update_needs_large_strain(self) -> "ShellSection":
        if self.thickness_update and self.technique is None:
            raise ValueError("thickness_update needs a large-strain technique (technique = 1, 2 or 3)")
        return self


class Clamped(Section):
    """All translations and the director fixed."""

    type: Literal["clamped"]
    set: Name


class Fixed(Section):
    """Chosen global translations fixed; the director ``free``, ``fixed``, or kept in the
    plane with normal ``director_plane_normal`` (a hard simple support along an edge keeps
    the director in the plane normal to the edge)."""

    type: Literal["fixed"]
    set: Name
    translations: list[Axis] = []
    director: Literal["free", "fixed"] = "free"
    director_plane_normal: Vec3 | None = None

    @model_validator(mode="after")
    def _fixes_something(self) -> "Fixed":
        if not self.translations and self.director == "free" and self.director_plane_normal is None:
            raise ValueError("fixes nothing: give translations, director = 'fixed' or director_plane_normal")
        if self.director == "fixed" and self.director_plane_normal is not None:
            raise ValueError("director = 'fixed' already fixes the director; drop director_plane_normal")
        return self


class Symmetry(Section):
    """Symmetry plane with unit normal ``normal``: u . n = 0 and the director stays in
    the plane."""

    type: Literal["symmetry"]
    set: Name
    normal: Vec3

    @field_validator("normal")
    @classmethod
    def _unit(cls, n: tuple[float, float, float]) -> tuple[float, float, float]:
        length = sum(c * c for c in n) ** 0.5
        if length == 0.0:
            raise ValueError("must not be the zero vector")
        return tuple(c / length for c in n)


class Prescribed(Section):
    """A global translation prescribed as ``value * curve(t)``, or as ``value * field *
    curve(t)`` with ``field`` the name of a scalar point field of the mesh file (each
    node's own motion, as a model brought over from another program gives it)."""

    type: Literal["prescribed"]
    set: Name
    translation: Axis
    value: Real
    curve: Name | None = None
    field: Name | None = None


Boundary = Annotated[Union[Clamped, Fixed, Symmetry, Prescribed], Field(discriminator="type")]


def _chosen_by_type(tables: tuple) -> object:
    """The item of a deck list: its one table, or its tables chosen by ``type``."""
    return tables[0] if len(tables) == 1 else Annotated[Union[tables], Field(discriminator="type")]


#: A ``[[load]]``, a ``[[contact]]`` and a ``[[cable]]`` table, among every registered kind's tables.
Load = _chosen_by_type(LOAD_TABLES)
Contact = _chosen_by_type(CONTACT_TABLES)
Cable = _chosen_by_type(CABLE_TABLES)


class NewtonSteps(Section):
    """The Newton-Raphson steps a static or implicit solve takes (the keys
    ``[solver.static]`` and ``[solver.implicit]`` share; see :class:`Static`)."""

    newton: Literal["modified", "full"] = "modified"
    increments: Count = 1
    max_iterations: Count = 25
    force_tolerance: Positive = 1e-6
    energy_tolerance: Positive = 1e-12
    min_increment: Positive = 1e-6


class Static(NewtonSteps):
    """``[solver.static]``: the Newton-Raphson load steps of ``method = "static"``.

    The pseudo-time runs from 0 to ``solver.end_time``; the loads follow their curves in it,
    and a load or prescribed motion without a curve grows linearly from 0 to its value over
    it. ``increments``: load steps to try first (more are taken where Newton needs them:
    a step that does not converge in ``max_iterations`` is cut to a quarter, one that
    converges with a few tangents formed grows by half, down to ``min_increment`` of the
    span). An iteration has converged when the residual force is within
    ``force_tolerance`` of the largest of the external and internal force norms and the
    residual's work on the correction within ``energy_tolerance`` of the step's first.
    ``newton = "modified"`` keeps the last tangent (from earlier steps too) while each
    iteration removes at least half of the residual and forms a new one where an
    iteration does not (going back first when it made the residual larger): forming a
    tangent costs about forty residuals, so this takes more iterations and less time.
    ``"full"`` forms the tangent at every iteration (quadratic convergence). A tangent
    formed at a converged state at the start, after every load step of ``increments``
    and at the end tells by the signs of its pivots where the path passed a limit point
    or a bifurcation; the run reports both, and any step that jumped (moved the shape ten
    times as far as its first correction), in ``summary.json``'s ``static.stability``.
    ``check_stability = false`` leaves out the tangents formed only for that (after each
    load step of ``increments``, and the end's; arc length's and the start's serve the
    solve anyway): a one-step linear solve is then 40% faster.

    ``control = "arc_length"`` follows the equilibrium path through limit points instead
    (a snapping shell, a tube past its inflation maximum): each step moves the
    translations a fixed distance and finds the load time with the shape, so the load
    may fall as well as rise; it forms the tangent at every iteration. The first step is
    as long as the linear response to the
    first of ``increments``; later steps grow or shrink with the iterations they take,
    to at most four times the first, and are cut to a quarter when they fail (down to
    ``min_increment`` of the first), and shorter after a step where the path turned
    sharply. A step that converges pointing back along the path is taken again shorter.
    Where an output time or a knot of a load curve is within the next step's reach, a load
    step goes there instead (undone where it lands on another equilibrium, more than two
    steps away); no step passes an output time, so each has a frame of its own; where the
    curves hold or have ended, the load time moves on with nothing to solve. The run's
    clock is then the load time's path length (the load time until the first limit
    point); it ends at the first step that reaches ``end_time``, or where the path comes
    back to loads that no longer change (reported as ``unloaded`` in
    ``static.stability``), and history.csv's load factors tell the load reached."""

    control: Literal["load", "arc_length"] = "load"
    check_stability: bool = True


class Implicit(NewtonSteps):
    """``[solver.implicit]``: implicit dynamics (``method = "implicit"``), the HHT-alpha
    method (Hilber, Hughes and Taylor 1977) on the static solve's Newton steps: each time
    step solves M a + (1 + alpha) f_int(u) - alpha f_int(u_n) = (1 + alpha) f_ext(t) -
    alpha f_ext(t_n) with Newmark's beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha, the
    lumped masses of the explicit run (``solver.mass``) giving the tangent its
    M / (beta dt^2). ``alpha`` = 0 is the trapezoidal rule (energy kept exactly in a
    linear system, no numerical damping); down to -1/3 it damps the highest frequencies
    (the step's) ever more while keeping the low ones, as Abaqus/Standard's dynamics
    (-0.05 by default, as there) and a quasi-static closing (-1/3, with long steps) use.
    The masses keep a node with no stiffness (a slack chord's) well posed, where a static
    solve finds its tangent singular. Time is real time: loads act as their curves say
    (in full from the start without one), and the steps (``increments`` over
    ``solver.end_time`` first) grow by half after easy steps and are cut to a quarter
    where Newton fails, down to ``min_increment`` of the end time, as static load steps
    are; each lands on the output times. Kinetic energy joins the energies; what HHT damps
    shows as the balance error."""

    increments: Count = 100
    alpha: Real = Field(default=-0.05, ge=-1.0 / 3.0, le=0.0)
    #: The static path's check of the converged states' stability has no meaning here:
    #: the mass term makes every tangent positive definite.
    check_stability: ClassVar[bool] = False


class MassScaling(Section):
    """``[solver.mass_scaling]``: uniform mass scaling for a quasi-static explicit run.
    When the first time step is shorter than ``step``, every mass (translational, rotary,
    the cables') is multiplied by (``step`` / Δt)², which makes the step ``step``: that
    many times fewer steps to the end time. The factor and the mass added are reported
    (``mass_scaling`` in summary.json). Every period of the structure grows by the same
    factor as the step, so the loads must still come on slowly against the longest one,
    and a mass-proportional ``damping`` acts (step / Δt) times more strongly on it.

    ``throughout``: also whenever a later estimate finds the step shorter than ``step``
    (a stiffening tissue, an element thinning), every mass is scaled again to bring it
    back, as Abaqus/Explicit's variable uniform mass scaling does; the velocities are
    divided by the square root of that factor, which keeps the kinetic energy, and the
    contact springs keep their stiffness. The factor reached and the count of such
    rescalings are reported. A cable's own ``min_step`` holds its elements' steps apart
    from this."""

    step: Positive
    throughout: bool = False


class Relaxation(Section):
    """``[solver.relaxation]``: dynamic relaxation by kinetic damping, for an explicit run
    whose answer is the state of rest. Whenever the kinetic energy has passed a peak,
    every velocity is set to zero (the energy taken counted as damping work); where a
    rigid tool moves on a curve, only once every such tool has stopped (a reset stops the
    nodes a moving tool pushes, and it runs into them: a crushed ring folded so), the
    deck's ``damping`` acting before. Once every
    curve holds its last value, the run ends at the first history sample whose residual
    force (over the free DOFs) is within ``residual`` of the larger of the external and
    internal force norms, as a static step converges; ``relaxation`` in summary.json
    records when and how far."""

    residual: Positive = 1e-4


class Imaged(Section):
    """``[solver.imaged]``: the mesh is a shape imaged under load, as a segmented vessel is
    imaged at its diastolic pressure, and the scene starts from its unloaded shape. ``at``
    is the load time the image was taken at (the loads read their curves there); the
    unloaded shape is found by the backward displacement method (Bols et al. 2013, J.
    Biomech. 46:2313-2318): from the image X_0, solve statically to ``at``, move the reference
    back by what it moved, X_{k+1} = X_k - (x_k - x_image) (directors alike, fibre lengths by
    their ratio), until the loaded shape is the image within ``tolerance`` of the model's
    size (1e-4: 6 um on a 60 mm vessel, far below an image's voxels), in at most
    ``iterations`` solves. An artery imaged in situ is also stretched along its axis
    (tethered, lambda_z about 1.1 to 1.5): a ``prescribed`` boundary that moves an end
    along the axis by L (1 - 1/lambda_z) over the load to ``at`` (L the imaged length) makes
    the unloaded shape that much shorter, and the image is reached stretched."""

    at: Positive
    tolerance: Positive = 1e-4
    iterations: Count = 30


class Solver(Section):
    """``[solver]``: central differences from t = 0 to ``end_time`` (``method =
    "explicit"``, the default), static equilibrium by Newton-Raphson load steps over
    the pseudo-time 0 to ``end_time`` (``method = "static"``, settings in
    ``[solver.static]``), or implicit dynamics by Newton-Raphson time steps (``method =
    "implicit"``, settings in ``[solver.implicit]``). Which to choose: slow loading
    without contact (a vessel's pressure) is static; a valve of a few thousand shells
    closing under contact, implicit; 10^3 to 10^4 shells with chordae and self-contact,
    explicit with ``mass_scaling`` throughout and ``damping``; waves and impacts,
    explicit (docs/start-valve.md gives the costs measured on the valves).

    Δt = Δt_critical / ``dt_safety_factor`` (thesis Eq 3.43; LS-DYNA's TSSFAC is its
    inverse), Δt_critical re-estimated at least every ``dt_update_every`` steps, and more
    often while it moves: each interval is as long as keeps its change, at the fastest rate
    seen over the last ``dt_update_every`` steps, within a quarter of the margin the safety
    factor leaves (5 steps to the first, each at most twice the one before), and at most
    ``dt_max`` (no limit by default): a scene that stiffens as it deforms (soft leaflets
    pressed shut) may need a step well below its step at rest, and contact's penalty
    springs are then set on the critical step that step stands for (``dt_max`` x
    ``dt_safety_factor`` / the penalties' share), stiffer by its square. ``mass``: lumped M1
    (Hughes) or M2 (row-summed consistent), thesis 3.14. ``damping``: mass-proportional
    coefficient in 1/s (0 = undamped, the default). ``mass_scaling`` and ``relaxation``
    reach a state of rest in fewer steps (``[solver.mass_scaling]``, ``[solver.relaxation]``).

    ``preload``: a time before ``end_time`` up to which an explicit run is solved
    statically instead (load steps of ``[solver.static]``), the way an explicit code's
    dynamic relaxation or a preceding static step sets up a prestressed state: the
    integration then starts from rest in that equilibrium, its stresses and fibre lengths
    carried over, and the frames and history show both phases in one time series. A
    load without a curve grows linearly to its value over the preload and then holds.

    ``imaged``: the mesh is the shape at a load, the scene starts unloaded (``[solver.imaged]``)."""

    method: Literal["explicit", "static", "implicit"] = "explicit"
    static: Static = Static()
    implicit: Implicit = Implicit()
    end_time: Positive
    preload: Positive | None = None
    dt_safety_factor: Positive = 1.25
    dt_update_every: Count = 100
    dt_max: Positive | None = None
    mass: Literal["M1", "M2"] = "M2"
    damping: NonNegative = 0.0
    mass_scaling: MassScaling | None = None
    relaxation: Relaxation | None = None
    imaged: Imaged | None = None

    @property
    def newton(self) -> bool:
        """Whether a run takes Newton steps, and so holds a tangent's factors: static,
        implicit, a preload, or the unloaded shape of an imaged mesh found first."""
        return self.method != "explicit" or self.preload is not None or self.imaged is not None

    @model_validator(mode="after")
    def _explicit_only(self) -> "Solver":
        if self.method != "explicit":
            for key in ("mass_scaling", "relaxation", "preload"):
                if getattr(self, key) is not None:
                    raise ValueError(f"'{key}' is for explicit runs (it scales, relaxes or prestresses the central "
                                     f"differences' time loop), and method = '{self.method}'; drop it or set "
                                     "method = 'explicit'")
        return self

    @model_validator(mode="after")
    def _preload_fits(self) -> "Solver":
        if self.preload is None:
            return self
        if self.preload >= self.end_time:
            raise ValueError(f"preload = {self.preload} must come before end_time = {self.end_time}")
        if self.static.control != "load":
            raise ValueError("a preload reaches its time by load steps: static.control must be 'load'")
        return self

    @model_validator(mode="after")
    def _imaged_within_static_loading(self) -> "Solver":
        if self.imaged is None:
            return self
        if self.static.control != "load":
            raise ValueError("the unloaded shape is found by load steps to imaged.at: static.control must be 'load'")
        statically = self.end_time if self.method == "static" else self.preload
        if statically is None:
            raise ValueError("the unloaded shape is found by static solves to imaged.at: give method = 'static', or "
                             "a preload that reaches imaged.at")
        if self.imaged.at > statically:
            raise ValueError(f"imaged.at = {self.imaged.at} lies beyond the static part of the run "
                             f"({'end_time' if self.method == 'static' else 'preload'} = {statically})")
        return self

    @property
    def ramp_end(self) -> float | None:
        """The time over which loads without a curve grow from 0 to their value: the span
        of a static run, a preload; None when they act in full from the start."""
        return self.end_time if self.method == "static" else self.preload


#: A field a frame may hold (:data:`shellsim.deck.output_fields.FIELDS`).
OutputField = Literal[tuple(FIELD_KINDS)]
#: The axes a vessel's stresses are read in: a tube's or a curved vessel's.
VesselAxes = Annotated[Union[CylindricalAxes, CentrelineAxes], Field(discriminator="kind")]
#: What a render may colour: a field, or an array one writes.
Drawn = Literal[(*get_args(OutputField), *(name for names in WRITTEN_AS.values() for name in names))]
class Render(Section):
    """PNGs written at the end of a completed run (as ``shellsim render``): ``field``
    (one of the written ``output.fields``, or an array one of them writes, e.g.
    ``hoop_stress`` of ``vessel_stress``) on the deformed shape, for the ``last`` frame,
    a frame number, or ``all`` (also an animated GIF), seen from ``view``, ``size`` pixels;
    ``fibres`` draws the fibre directions over it (with ``fibres`` among the fields),
    ``outline`` the initial shape's element outlines; ``range`` the colour bar's limits:
    ``robust`` (the middle 98% of the values where a few stray ones would take the scale,
    which the picture then says), ``full`` or [low, high] in the units shown."""

    field: Drawn = "pressure_band"
    frame: Literal["last", "all"] | Count = "last"
    view: Literal["iso", "top", "front", "side"] = "iso"
    size: tuple[Count, Count] = (1200, 900)
    fibres: bool = False
    outline: bool = False
    range: Literal["robust", "full"] | tuple[float, float] = "robust"

    @field_validator("range")
    @classmethod
    def _rising(cls, limits):
        if not isinstance(limits, str) and not limits[0] < limits[1]:
            raise ValueError(f"got {list(limits)}; expected [low, high] with low < high")
        return limits

    @field_validator("field")
    @classmethod
    def _coloured(cls, field: str) -> str:
        if field == "fibres":
            raise ValueError("fibres are drawn over a coloured field: give another field and fibres = true")
        if field in WRITTEN_AS:
            raise ValueError(f"'{field}' writes {', '.join(WRITTEN_AS[field])}: colour one of them")
        return field


class _Output(Section):
    """``[output]``: frames at t = 0, every ``interval``, at the listed ``times`` (both
    landed on exactly: a static solve's load steps, whose states the history records,
    end there too, so a few ``times`` where the load rises fast draw its curve) and at the
    end; the ``fields`` written in
    them (stresses and strains per integration-point sub-cell, with a smoothed nodal
    version); the ``formats`` (``xdmf``: results.xdmf + results.h5; ``vtu``: results.pvd +
    frames/), their numbers' ``precision`` (``single``: about 7 digits, half the size of
    ``double``) and whether they are compressed (``compress``, lossless); ``solid`` writes
    the shell as a solid between its faces instead of its mid-surface; ``mirror`` names the
    ``symmetry`` boundaries (by their sets) that are planes of the model's symmetry, and
    writes the model whole, reflected across them (a quarter tube as eight copies with a z
    symmetry plane); ``faces`` adds, in the shell view, each stress and strain field at the
    integration layer nearest the ``bottom`` face (a vessel's inner wall, its directors
    pointing out) and the ``top`` face as ``<field>_bottom`` and ``<field>_top``;
    ``display_units`` shows lengths, stresses, pressures and times in renders and plots in
    other units than the deck's, e.g. { length = "mm", stress = "kPa", pressure = "mmHg" }
    (pressures follow the stresses' unit unless given; the files keep the deck's units);
    ``vessel_axes`` are the axes ``vessel_stress`` reads the radial, hoop and axial
    stresses in (by default the material's, when they are a tube's or a centreline's);
    ``checkpoint_interval`` (explicit runs) writes checkpoint.npz at the first frame at or
    after each multiple of it, which ``shellsim run --resume FOLDER`` goes on from, to the
    same answer; renders; and the tables of what a run measures into history.csv
    (:mod:`shellsim.measures`: probes, a valve's measures)."""

    interval: Positive | None = None
    times: list[NonNegative] | None = None
    fields: list[OutputField] = ["displacement", "director", "thickness", "cauchy_stress", "pressure_band"]
    formats: list[Literal["xdmf", "vtu"]] = ["xdmf"]
    precision: Literal["single", "double"] = "single"
    compress: bool = True
    solid: bool = False
    mirror: bool | list[str] = []
    vessel_axes: VesselAxes | None = None
    faces: list[Literal["bottom", "top"]] = []
    display_units: dict[Literal[tuple(UNIT_SIZES)], str] = {}
    checkpoint_interval: Positive | None = None
    render: list[Render] = []

    @model_validator(mode="after")
    def _consistent(self) -> "_Output":
        if self.times is not None and any(b <= a for a, b in zip(self.times, self.times[1:])):
            raise ValueError(f"'times' must be strictly increasing, got {self.times}")
        written_by = {name: field for field, names in WRITTEN_AS.items() for name in names}
        drawn = {written_by.get(r.field, r.field) for r in self.render} | {"fibres" for r in self.render if r.fibres}
        unwritten = sorted(drawn - set(self.fields))
        if unwritten:
            raise ValueError(f"render field(s) {', '.join(unwritten)} must also be in 'fields'")
        if self.vessel_axes is not None and self.vessel_axes.angle_deg != 0.0:
            raise ValueError(f"vessel_axes.angle_deg = {self.vessel_axes.angle_deg}: a vessel's axes are not turned; "
                             "leave it out")
        for kind, unit in self.display_units.items():
            if unit not in UNIT_SIZES[kind]:
                raise ValueError(f"display_units.{kind} = '{unit}' is not a unit of {kind}; expected one of "
                                 f"{', '.join(UNIT_SIZES[kind])}")
        return self


#: ``[output]`` with each measure family's table (:data:`shellsim.measures.FAMILIES`).
Output = create_model("Output", __base__=_Output, __module__=__name__, __doc__=_Output.__doc__, **OUTPUT_FIELDS)


class Reference(Section):
    """The value a verification deck is checked against.

    ``measure`` turns the probe's history into one number: its ``final`` value, ``max``,
    ``min``, ``max_abs`` (the largest magnitude: a bound on something that should stay
    zero), ``amplitude`` (half the first peak-to-trough excursion, benchmarks 0.2),
    ``first_peak_time``, or the value ``at_time`` ``time``. The check passes within
    ``tolerance_percent`` of ``expected``, or within ``tolerance`` (absolute, in the
    quantity's units) where a criterion is stated that way. ``source`` cites where
    ``expected`` comes from (closed form, literature)."""

    quantity: Annotated[str, Field(strict=True, min_length=1)]
    probe: Name
    measure: Literal["final", "max", "min", "max_abs", "amplitude", "first_peak_time", "at_time"] = "final"
    time: NonNegative | None = None
    expected: Real
    tolerance_percent: Positive | None = None
    tolerance: Positive | None = None
    source: Annotated[str, Field(strict=True, min_length=3)]

    @model_validator(mode="after")
    def _consistent(self) -> "Reference":
        if (self.measure == "at_time") != (self.time is not None):
            raise ValueError("'time' is needed with measure = 'at_time', and only then")
        if (self.tolerance_percent is None) == (self.tolerance is None):
            raise ValueError("give exactly one of 'tolerance_percent' and 'tolerance'")
        if self.expected == 0.0 and self.tolerance is None:
            raise ValueError("expected = 0 has no relative error; give an absolute 'tolerance'")
        return self


def _tag(table: object, key: str) -> str | None:
    """The discriminating name of a raw table (builder, model), if it is a string."""
    value = table.get(key) if isinstance(table, dict) else None
    return value if isinstance(value, str) else None


def _one_or_many(value: object) -> object:
    """``[reference]`` (one) and ``[[reference]]`` (several) are both accepted."""
    return [value] if isinstance(value, dict) else value


def _part_problems(materials: list) -> list[str]:
    """Several materials each name the sets they cover, and no set twice."""
    if len(materials) == 1:
        return []
    problems = [f"material[{i}].sets: missing; with several materials each names the surface sets it covers"
                for i, m in enumerate(materials) if not m.sets]
    first: dict[str, int] = {}
    for i, m in enumerate(materials):
        for name in m.sets:
            if name in first:
                problems.append(f"material[{i}].sets: '{name}' is already material[{first[name]}]'s; an element "
                                "has one material")
            first.setdefault(name, i)
    return problems


def _constitutive_path_problems(material, section: ShellSection) -> list[str]:
    """What the element cannot run of this material and section: a hyperelastic law
    runs Technique 1 in the total formulation; Techniques 2 and 3 take a linear elastic
    material; plane strain is a small-strain section."""
    problems = []
    technique = section.technique
    if material.HYPERELASTIC and technique != 1:
        problems.append(f"section.technique: got {technique}: material.model = '{material.model}' is a strain "
                        "energy and runs Technique 1; Techniques 2 and 3 take a linear elastic material")
    if technique == 1 and section.formulation != "total":
        problems.append("section.formulation: got 'incremental': Technique 1 runs in the total formulation "
                        "(formulation = 'total')")
    if technique is not None and section.plane_strain:
        problems.append(f"section.plane_strain: plane strain is a small-strain section (thesis Test 7); "
                        f"drop technique = {technique} or plane_strain")
    return problems


def _mirror_problems(mirror: bool | list[str], boundaries: list) -> list[str]:
    """What is wrong with ``output.mirror``: it names symmetry boundaries' sets. ``true``
    does not say which: a symmetry boundary may hold a vessel's cut end in its plane
    rather than halve the model, and a copy reflected there is no part of the model."""
    symmetric = [b.set for b in boundaries if b.type == "symmetry"]
    if mirror is True:
        if not symmetric:
            return ["output.mirror: the deck has no symmetry boundary to mirror across"]
        return [f"output.mirror = true: name the symmetry boundaries that are planes of the model's symmetry, "
                f"as mirror = {json.dumps(symmetric)} or fewer (a "
                "symmetry boundary may also hold a cut end in its plane, and a copy reflected there is no part "
                "of the model)"]
    known = f"they are {', '.join(repr(name) for name in symmetric)}" if symmetric else "the deck has none"
    problems = [f"output.mirror: '{name}' is not the set of a symmetry boundary; {known}"
                for name in mirror or [] if name not in symmetric]
    normals = {b.set: np.asarray(b.normal, dtype=float) / np.linalg.norm(b.normal) for b in boundaries
               if b.type == "symmetry" and b.set in (mirror or [])}
    for (a, n_a), (b, n_b) in combinations(normals.items(), 2):
        cosine = abs(float(n_a @ n_b))
        if 1e-9 < cosine < 1.0 - 1e-9:  # reflections across planes at another angle make more copies, overlapping
            problems.append(f"output.mirror: the planes of '{a}' and '{b}' meet at {np.degrees(np.arccos(cosine)):.4g} "
                            "degrees; the model is mirrored across planes at right angles only")
    return problems


class Deck(Section):
    """A whole scene. Tables may come in any order; names are resolved after parsing."""

    meta: Meta
    geometry: Geometry
    mesh: MeshOptions = MeshOptions()
    material: Annotated[list[Material], BeforeValidator(_one_or_many), Field(min_length=1)]
    section: ShellSection
    boundary: list[Boundary] = []
    load: list[Load] = []
    contact: list[Contact] = []
    cable: list[Cable] = []
    curves: dict[Name, Curve] = {}
    solver: Solver
    output: Output = Output()
    reference: Annotated[list[Reference], BeforeValidator(_one_or_many)] = []

    def curve_index(self, name: str | None) -> int:
        """Curve ``name``'s place in the model's curve tables (the deck's curves in order,
        then the ramp of a static solve or a preload); a load without a curve is constant
        (-1), or follows that ramp when there is one."""
        if name is None:
            return -1 if self.solver.ramp_end is None else len(self.curves)
        return list(self.curves).index(name)

    @model_validator(mode="before")
    @classmethod
    def _fill_defaults_that_depend_on_other_tables(cls, data: object) -> object:
        """Builder-specific division defaults and the hyperelastic default technique."""
        if not isinstance(data, dict):
            return data
        data = dict(data)
        builder = BUILDERS.get(_tag(data.get("geometry"), "builder"))
        mesh = data.get("mesh", {})
        if builder is not None and isinstance(mesh, dict) and isinstance(mesh.get("divisions", {}), dict):
            data["mesh"] = mesh | {"divisions": builder.DIVISIONS | mesh.get("divisions", {})}
        materials = [(table, MATERIALS.get(_tag(table, "model"))) for table in _one_or_many(data.get("material"))
                     if isinstance(table, dict)] if isinstance(data.get("material"), (dict, list)) else []
        section = data.get("section")
        if any(model is not None and model.HYPERELASTIC for _, model in materials) and isinstance(section, dict):
            data["section"] = {"technique": 1} | section
        output = data.get("output")
        if isinstance(output, dict) and "vessel_stress" in output.get("fields", []) and "vessel_axes" not in output:
            for table, model in materials:  # the first fibre-reinforced material's tube or centreline
                axes = table.get("axes", {"kind": "cylindrical"})  # the law's own default
                if (model is not None and model.ANISOTROPIC and isinstance(axes, dict)
                        and axes.get("kind") in ("cylindrical", "centreline")):
                    data["output"] = output | {"vessel_axes": {key: value for key, value in axes.items()
                                                               if key != "angle_deg"}}
                    break
        return data

    @field_serializer("material", mode="wrap")
    def _one_table(self, materials: list, handler) -> dict | list:
        """One material covering every element is written as the one table it was."""
        tables = handler(materials)
        return tables[0] if len(tables) == 1 and not tables[0].get("sets") else tables

    @model_validator(mode="after")
    def _consistent(self) -> "Deck":
        problems = division_problems(self.geometry, self.mesh)
        problems += _part_problems(self.material)
        for material in self.material:
            problems += _constitutive_path_problems(material, self.section)
        problems += _mirror_problems(self.output.mirror, self.boundary)
        problems += field_problems(self)
        if self.output.checkpoint_interval is not None and self.solver.method != "explicit":
            problems.append(f"output.checkpoint_interval = {self.output.checkpoint_interval:g}: checkpoints are of "
                            f"the explicit time loop, and solver.method = '{self.solver.method}' solves in Newton "
                            "steps; drop it")
        if self.output.display_units and self.meta.units == "consistent":
            problems.append("output.display_units: meta.units = 'consistent' names no units to convert from; give "
                            f"meta.units (one of {', '.join(u for u in SYSTEMS if u != 'consistent')})")
        problems += proportion_problems(self.geometry, self.section.thickness)
        if self.solver.method == "static":
            problems += [f"contact[{i}].friction = {c.friction:g}: friction opposes sliding velocities, and a static "
                         "solve has none (it is frictionless); give friction = 0, or solver.method = 'explicit'"
                         for i, c in enumerate(self.contact) if c.friction]
        if self.solver.method == "implicit":
            problems += [f"contact[{i}].friction = {c.friction:g}: the implicit solve takes friction between shells "
                         f"(type = 'shells'), not on a {c.type!r} contact; give friction = 0, or solver.method = "
                         "'explicit'" for i, c in enumerate(self.contact) if c.friction and not friction_in_newton(c)]
        if self.solver.ramp_end is not None:  # a static solve, or a static preload
            problems += [f"cable[{i}].segments = {c.segments}: a chord's interior nodes have no stiffness while it "
                         "is slack, so a static solve cannot find them; give segments = 1, or an explicit run "
                         "without a preload" for i, c in enumerate(self.cable) if c.segments > 1]
        if self.solver.method == "static" and self.solver.static.control == "arc_length":
            moved = [f"boundary[{i}]" for i, b in enumerate(self.boundary) if b.type == "prescribed" and b.value != 0]
            if moved:
                problems.append(f"solver.static.control = 'arc_length' finds the load with the shape, but "
                                f"{', '.join(moved)} prescribe a motion; use control = 'load' for displacement "
                                "control")
        if problems:
            raise ValueError("\n".join(problems))
        return self

    @property
    def thickness_update(self) -> bool:
        """Whether fibre lengths follow the deformation (thesis 3.11)."""
        if self.section.thickness_update is not None:
            return self.section.thickness_update
        return self.section.technique is not None
