"""The ``[geometry]`` table: one model per gmsh builder, chosen by ``builder``.

Each model declares what its builder produces, so a deck can be checked against it
without meshing: ``DIVISIONS`` (the names of the ``[mesh] divisions`` it reads, with their
defaults), ``EVEN`` (the divisions that must be even, each with why), ``IRREGULAR``
(whether it takes ``[mesh] boundaries_y0/_y1``) and :meth:`sets` (named sets and their
kind: ``surface``, ``edge`` or ``point``); :func:`division_problems` checks a deck's
``[mesh]`` against them.
The builders in :mod:`shellsim.geometry.builders` create exactly these sets (tested).
Every mesh also has the surface set ``all``.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal, Union

from pydantic import Field, model_validator

from ..table_types import Name, Positive, Section, Vec3, tag_of

SetKinds = dict[str, str]


class Rectangle(Section):
    """Flat plate or strip in the plane z = 0, corner at the origin, x along ``length``.

    Sets: edges ``x0``, ``x1`` (x = 0, x = length), ``y0``, ``y1``; corner points
    ``x0y0``, ``x1y0``, ``x1y1``, ``x0y1``. Divisions ``length`` x ``width``; irregular
    element boundaries along y = 0 and y = width come from ``[mesh] boundaries_y0/_y1``.
    """

    builder: Literal["rectangle"]
    length: Positive
    width: Positive
    DIVISIONS: ClassVar[dict[str, int]] = {"length": 2, "width": 2}
    IRREGULAR: ClassVar[bool] = True

    def sets(self) -> SetKinds:
        return _edges("x0", "x1", "y0", "y1") | _points("x0y0", "x1y0", "x1y1", "x0y1")


class CylindricalPanel(Section):
    """Open cylindrical panel (Scordelis-Lo roof), axis along y: a mid-surface point at
    angle phi from the crown and axial position y is (R sin phi, y, R cos phi),
    phi in [0, angle_deg], y in [0, length].

    Sets: edges ``phi0`` (crown line), ``phi1`` (free edge), ``y0``, ``y1`` (curved ends);
    points ``phi0_y0``, ``phi1_y0``, ``phi1_y1``, ``phi0_y1``. Divisions ``around`` x ``along``.
    """

    builder: Literal["cylindrical_panel"]
    radius: Positive
    length: Positive
    angle_deg: Annotated[float, Field(strict=True, gt=0, lt=180)]
    DIVISIONS: ClassVar[dict[str, int]] = {"around": 4, "along": 4}

    def sets(self) -> SetKinds:
        return _edges("phi0", "phi1", "y0", "y1") | _points(
            "phi0_y0", "phi1_y0", "phi1_y1", "phi0_y1"
        )


class TwistedStrip(Section):
    """Strip pre-twisted about its straight axis x: the point at axial position x and width
    coordinate w in [-width/2, width/2] is (x, w cos a, w sin a), a = twist (x / length).

    Sets: edges ``root``, ``tip``, ``side0``, ``side1``; point ``tip_centre``.
    Divisions ``length`` x ``width`` (``width`` must be even so the tip centre is a node).
    """

    builder: Literal["twisted_strip"]
    length: Positive
    width: Positive
    twist_deg: Annotated[float, Field(strict=True, ge=-180, le=180)] = 90.0
    DIVISIONS: ClassVar[dict[str, int]] = {"length": 4, "width": 2}
    EVEN: ClassVar[dict[str, str]] = {"width": "so the tip centre is a node"}

    def sets(self) -> SetKinds:
        return _edges("root", "tip", "side0", "side1") | _points("tip_centre")


class AnnularSector(Section):
    """Flat annular sector in z = 0 centred at the origin, theta in [0, angle_deg]
    (the cross-section of a thick-walled pipe, loaded in its plane).

    Sets: edges ``inner``, ``outer``, ``theta0`` (on the x axis), ``theta1``; points
    ``inner_theta0``, ``outer_theta0``, ``outer_theta1``, ``inner_theta1``.
    Divisions ``around`` x ``radial``.
    """

    builder: Literal["annular_sector"]
    inner_radius: Positive
    outer_radius: Positive
    angle_deg: Annotated[float, Field(strict=True, gt=0, lt=180)] = 90.0
    DIVISIONS: ClassVar[dict[str, int]] = {"around": 2, "radial": 2}

    @model_validator(mode="after")
    def _radii(self) -> "AnnularSector":
        if self.outer_radius <= self.inner_radius:
            raise ValueError(
                f"outer_radius ({self.outer_radius}) must exceed inner_radius ({self.inner_radius})"
            )
        return self

    def sets(self) -> SetKinds:
        return _edges("inner", "outer", "theta0", "theta1") | _points(
            "inner_theta0", "outer_theta0", "outer_theta1", "inner_theta1"
        )


class PlateWithHole(Section):
    """Quarter of a square plate 2W x 2W with a central circular hole, in z = 0:
    0 <= x, y <= half_width outside the hole. Split along the 45-degree line into two
    patches, each ``around`` x ``radial`` elements.

    Sets: edges ``hole``, ``x0`` (x = 0), ``y0`` (y = 0), ``x1`` (x = W), ``y1`` (y = W);
    points ``A`` = (a, 0), ``B`` = (0, a), ``C`` = (W, W).
    """

    builder: Literal["plate_with_hole"]
    half_width: Positive
    hole_radius: Positive
    DIVISIONS: ClassVar[dict[str, int]] = {"around": 1, "radial": 1}

    @model_validator(mode="after")
    def _hole_fits(self) -> "PlateWithHole":
        if self.hole_radius >= self.half_width:
            raise ValueError(
                f"hole_radius ({self.hole_radius}) must be smaller than half_width ({self.half_width})"
            )
        return self

    def sets(self) -> SetKinds:
        return _edges("hole", "x0", "y0", "x1", "y1") | _points("A", "B", "C")


class Tube(Section):
    """Quarter of a tube (x, y >= 0) with its axis along z, from the mid-length symmetry
    plane z = 0 to z = length, optionally closed there by a hemispherical cap.
    The shell mid-surface radius is ``inner_radius + thickness / 2`` ([section] thickness).

    Sets: surfaces ``wall`` (and ``cap``); edges ``sym_x`` (x = 0), ``sym_y`` (y = 0),
    ``z0`` (z = 0), and ``end`` (z = length) for an open tube; points ``z0_x`` and ``z0_y``
    (on the x and y axes at z = 0), and ``pole`` with a cap.
    Divisions ``around`` (over the quarter; even) x ``axial``.
    """

    builder: Literal["tube"]
    inner_radius: Positive
    length: Positive
    cap: Literal["none", "hemisphere"] = "none"
    DIVISIONS: ClassVar[dict[str, int]] = {"around": 2, "axial": 8}
    EVEN: ClassVar[dict[str, str]] = {"around": "as the tube is built from two 45-degree patches"}

    def sets(self) -> SetKinds:
        sets = {"wall": "surface"} | _edges("sym_x", "sym_y", "z0") | _points("z0_x", "z0_y")
        if self.cap == "hemisphere":
            return sets | {"cap": "surface"} | _points("pole")
        return sets | _edges("end")


class Hemisphere(Section):
    """Quarter of a hemisphere (x, y, z >= 0) centred at the origin, pole on +z, built from
    three curved patches of ``patch`` x ``patch`` elements; with a polar hole of
    ``hole_deg`` (its half-angle from the pole, e.g. 18 for the pinched hemisphere
    benchmark), from two patches between the hole and the equator.

    Sets: edges ``equator``, ``sym_x`` (x = 0), ``sym_y`` (y = 0); points ``equator_x``,
    ``equator_y`` (where the pinched hemisphere is loaded); and point ``pole``, or with a
    hole edge ``hole`` and points ``hole_x``, ``hole_y``.
    """

    builder: Literal["hemisphere"]
    radius: Positive
    hole_deg: Annotated[float, Field(strict=True, ge=0, lt=90)] = 0.0
    DIVISIONS: ClassVar[dict[str, int]] = {"patch": 2}

    def sets(self) -> SetKinds:
        sets = _edges("equator", "sym_x", "sym_y") | _points("equator_x", "equator_y")
        if self.hole_deg > 0:
            return sets | _edges("hole") | _points("hole_x", "hole_y")
        return sets | _points("pole")


class AorticValve(Section):
    """The three leaflets of an aortic valve, axis along z, in a near-closed position:
    each a structured patch between its attachment to the root and its free edge,
    commissure to commissure. The free edges run at height ``height`` along the lines
    from the commissures to the axis, each kept ``gap`` / 2 from the plane between two
    leaflets (so neighbours start ``gap`` apart: more than a thickness, or their faces
    would overlap and never be held apart by contact); the ``coaptation_height`` below
    them hangs vertically, the band where closed leaflets meet. Each leaflet hangs from a
    vertical commissure post at radius ``commissure_radius`` on either side, from the free
    edge down to half the band's lower edge's height, and from the attachment on the root
    that runs from there, leaving the posts level (so the leaflet's corners there are
    square), down to ``base_radius`` at z = 0 under the leaflet's centre; its
    belly leaves the root horizontally, turning up into the coaptation band (a quadratic
    in each section from the root to the band, the sections commissure to commissure,
    each spaced evenly along its length). Leaflet k is centred at 90 + 120 k degrees from x.
    Defaults: the mid-diastolic proportions Rb / Rc = 1.2 and H / Rc = 1.4 (Thubrikar,
    Piepgrass, Shaner & Nolan 1981, Am. J. Physiol. 241:H795) for a commissure radius of
    10 (mm).

    Sets: surfaces ``leaflet_1`` .. ``leaflet_3``; edges ``attachment`` (the root's line
    and the commissures', all three leaflets), ``free_edge`` (all three),
    ``free_edge_1`` .. ``free_edge_3``; points ``centre_1`` .. ``centre_3`` (the free
    edges' middles, nearest the axis) and ``nadir_1`` .. ``nadir_3`` (the attachments'
    lowest points). Cell vectors ``along_free_edge``: each element's direction
    commissure to commissure, for ``material.axes = { kind = "mesh", field =
    "along_free_edge" }`` (a leaflet's collagen runs parallel to its free edge).
    Divisions ``around`` (per leaflet, commissure to commissure; even) x ``belly`` x
    ``coaptation``.
    """

    builder: Literal["aortic_valve"]
    commissure_radius: Positive = 10.0
    base_radius: Positive = 12.0
    height: Positive = 14.0
    coaptation_height: Positive = 2.0
    gap: Positive = 0.5
    DIVISIONS: ClassVar[dict[str, int]] = {"around": 8, "belly": 4, "coaptation": 1}
    EVEN: ClassVar[dict[str, str]] = {"around": "so that each free edge's middle is a node"}
    LEAFLETS: ClassVar[int] = 3

    def sets(self) -> SetKinds:
        leaflets = range(1, self.LEAFLETS + 1)
        return ({f"leaflet_{k}": "surface" for k in leaflets} | _edges("attachment", "free_edge")
                | _edges(*(f"free_edge_{k}" for k in leaflets))
                | _points(*(f"{name}_{k}" for name in ("centre", "nadir") for k in leaflets)))

    @model_validator(mode="after")
    def _proportions(self) -> "AorticValve":
        if self.height <= self.coaptation_height:
            raise ValueError(f"height = {self.height:g} must exceed coaptation_height = {self.coaptation_height:g}: "
                             "the band hangs from the free edge at that height")
        if self.gap >= self.commissure_radius:
            raise ValueError(f"gap = {self.gap:g} must be smaller than commissure_radius = {self.commissure_radius:g}")
        return self


#: File endings read as triangulated surfaces, remeshed into quads.
SURFACE_SUFFIXES = (".stl", ".obj", ".ply", ".vtp", ".off")


class MeshFile(Section):
    """A mesh of 9-node quadrilaterals read with meshio (any format it reads), ``path``
    relative to the deck. Named sets come from the file's cell sets (gmsh physical groups)
    or from point-data arrays named ``set_<name>``.

    An Abaqus input file (.inp) or a FEBio model (.feb) gives its shells, made 9-node
    quads, and their sets (``shellsim import`` writes the rest of its scene as a deck).

    A triangulated surface (.stl, .obj, .ply, .vtp, .off) is remeshed with gmsh into quads
    of about ``element_size``; its open boundary loops become edge sets, each of
    ``boundaries`` naming the loop nearest its point (e.g. ``inlet = [0.0, 0.0, 0.0]``), the
    others ``open_1``, ``open_2``, ... along the surface's longest extent."""

    builder: Literal["file"]
    path: Annotated[str, Field(strict=True, min_length=1)]
    element_size: Positive | None = None
    boundaries: dict[Name, Vec3] = {}
    DIVISIONS: ClassVar[dict[str, int]] = {}

    @property
    def surface(self) -> bool:
        """Whether the file is a triangulated surface to remesh."""
        return self.path.lower().endswith(SURFACE_SUFFIXES)

    @model_validator(mode="after")
    def _remeshing(self) -> "MeshFile":
        if self.surface and self.element_size is None:
            raise ValueError(f"'{self.path}' is a triangulated surface, remeshed into quads: give element_size "
                             "(the quads' size, in the deck's length unit)")
        if not self.surface and (self.element_size is not None or self.boundaries):
            raise ValueError(f"element_size and boundaries are for a triangulated surface ({', '.join(SURFACE_SUFFIXES)}); "
                             f"'{self.path}' is read as a quad9 mesh")
        if "all" in self.boundaries:  # the set of every element would hide it
            raise ValueError("boundaries: 'all' names the set of every element; give the loop another name")
        return self


Geometry = Annotated[
    Union[
        Rectangle, CylindricalPanel, TwistedStrip, AnnularSector, PlateWithHole, Tube,
        Hemisphere, AorticValve, MeshFile,
    ],
    Field(discriminator="builder"),
]

#: builder name -> model class, for defaults and messages.
BUILDERS = {
    tag_of(cls)[1]: cls
    for cls in (
        Rectangle, CylindricalPanel, TwistedStrip, AnnularSector, PlateWithHole, Tube,
        Hemisphere, AorticValve, MeshFile,
    )
}


#: How far apart a builder's lengths may be: beyond this its elements are slivers, and
#: gmsh merges points closer than 1e-8 of the model's size.
LENGTH_RATIO = 1e6


def lengths(geometry: Section) -> dict[str, float]:
    """A builder's lengths by key: its numbers other than angles (none for a mesh file)."""
    if isinstance(geometry, MeshFile):
        return {}
    return {k: v for k, v in geometry.model_dump().items() if isinstance(v, float) and not k.endswith("_deg")}


def division_problems(geometry: Section, mesh) -> list[str]:
    """What is wrong with ``mesh`` (the deck's ``[mesh]``) for ``geometry``'s builder: a
    division it does not read, an odd one it needs even (``EVEN``), irregular element
    boundaries where it takes none (``IRREGULAR``) or of the wrong count."""
    known, even = type(geometry).DIVISIONS, getattr(geometry, "EVEN", {})
    problems = [f"mesh.divisions.{name}: builder '{geometry.builder}' has no division '{name}'; expected "
                f"{', '.join(known) or 'none (the file sets the mesh)'}" for name in mesh.divisions if name not in known]
    problems += [f"mesh.divisions.{name}: must be even {why}, got {mesh.divisions[name]}"
                 for name, why in even.items() if mesh.divisions.get(name, known[name]) % 2]
    if (mesh.boundaries_y0 or mesh.boundaries_y1) and not getattr(geometry, "IRREGULAR", False):
        problems.append(f"mesh.boundaries_y0/_y1: builder '{geometry.builder}' takes no irregular element boundaries")
    for key in ("boundaries_y0", "boundaries_y1"):
        b, n = getattr(mesh, key), mesh.divisions.get("length")
        if b is not None and n is not None and len(b) != n + 1:
            problems.append(f"mesh.{key}: {len(b)} boundaries for divisions.length = {n}; expected {n + 1}")
    return problems


def proportion_problems(geometry: Section, thickness: float) -> list[str]:
    """Lengths too far apart to mesh, and a section thicker than the model is large."""
    sizes = lengths(geometry)
    if not sizes:
        return []
    big, small = max(sizes, key=sizes.get), min(sizes, key=sizes.get)
    problems = []
    if sizes[big] > LENGTH_RATIO * sizes[small]:
        problems.append(f"geometry.{small} = {sizes[small]:g} and geometry.{big} = {sizes[big]:g} are more than "
                        f"{LENGTH_RATIO:g} times apart; the elements would be slivers (check the units)")
    if thickness > sizes[big]:
        problems.append(f"section.thickness = {thickness:g} is larger than the model itself (geometry.{big} = "
                        f"{sizes[big]:g}); a shell's thickness is small against its extent (check the units)")
    return problems


def _edges(*names: str) -> SetKinds:
    return {n: "edge" for n in names}


def _points(*names: str) -> SetKinds:
    return {n: "point" for n in names}
