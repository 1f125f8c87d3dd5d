"""An Abaqus shell model as a shellsim mesh and deck tables.

Shells (S4, S4R, S8R, S9R5 and their variants) become 9-node quads (:mod:`.quad_upgrade`;
triangles S3, S3R split into quads first), 2-node trusses and beams (T3D2, B31) cables with
their section's area and a 1D law of their material,
their node and element sets and element-based surfaces named sets, ``*ORIENTATION`` (with
per-element ``*DISTRIBUTION``) material axes; the model data and the first step become the
deck's material, section, boundaries, loads, contact, curves and solver. Every keyword,
element or option that has no counterpart is listed with its line (``unmapped``).

Signs: Abaqus' positive shell normal follows the corner order by the right-hand rule, and
is kept as the director where the mesh is consistently oriented; a pressure on a shell's
positive face (``SPOS``, or ``*DLOAD P``) pushes against that normal. It is brought over
on the mid-surface, Abaqus' reference surface, as ``face = "mid"`` with the opposite sign.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np

from ..deck.material import MATERIALS
from ..errors import MeshError
from ..loads.cable_laws import OGDEN_TERMS
from . import ForeignModel, meta_table
from .abaqus_model import OUTPUT_REQUESTS, AbaqusModel, Keyword, qualified, read_model
from .deck_tables import AXES, pressure_loads, support_table
from .shell_mesh import ShellMesh, deck_name, listed
from .user_law import UserLaw

#: Abaqus shell types by their number of nodes.
SHELLS = {3: {"S3", "S3R", "S3RS", "STRI3"}, 4: {"S4", "S4R", "S4R5", "S4RS", "S4RSW"}, 8: {"S8R", "S8R5"},
          9: {"S9R5"}}
#: Abaqus' 2-node line elements, brought over as cables (tension only: a beam's bending and
#: a truss' compression are dropped, and listed).
LINES = {"T3D2", "T3D2H", "B31", "B31H"}
#: Why other element types cannot come over.
NOT_SHELLS = {
    "STRI65": "6-node triangles: bring them as 3-node ones (S3)",
    "T3D3": "3-node line elements: bring them as 2-node ones (T3D2), which come over as cables",
    "B32": "3-node beams: bring them as 2-node ones (B31), which come over as cables",
    "M3D4": "membranes: shellsim's shells carry bending; model the membrane as a thin shell",
}
#: Abaqus' named boundary types: the degrees of freedom they fix.
BOUNDARY_TYPES = {"encastre": {1, 2, 3, 4, 5, 6}, "pinned": {1, 2, 3}, "xsymm": {1, 5, 6}, "ysymm": {2, 4, 6},
                  "zsymm": {3, 4, 5}, "xasymm": {2, 3, 4}, "yasymm": {1, 3, 5}, "zasymm": {1, 2, 6}}


def read_abaqus(path: Path, user_law: UserLaw | None = None) -> ForeignModel:
    """The model of the Abaqus input file ``path``, its user materials mapped by
    ``user_law`` (left out, listed, without); MeshError for one without usable shells."""
    model = read_model(path)
    builder = _Builder(model, user_law)
    builder.mesh()
    builder.material_and_section()
    builder.curves_of_amplitudes()
    builder.supports_and_loads()
    builder.contact()
    builder.solver()
    builder.mass_scaling()
    tables = {"meta": meta_table(path, model.heading or path.stem)} | builder.tables
    return ForeignModel(builder.shells.imported(), tables, model.unmapped, builder.unused_elements,
                        builder.shells.id_map())


class _Builder:
    """Maps a flattened :class:`AbaqusModel` piece by piece; the pieces share the mesh and
    the set names made so far."""

    def __init__(self, model: AbaqusModel, user_law: UserLaw | None = None):
        self.model = model
        self.user_law = user_law
        self.tables: dict = {}
        self.unused_elements: list[str] = []
        self.curve_of: dict[str, str] = {}  # amplitude key -> curve name
        self.density: float | None = None

    # -- mesh -------------------------------------------------------------------------------
    def mesh(self) -> None:
        m = self.model
        by_kind: dict[str, list] = defaultdict(list)
        for e in m.elements:
            by_kind[e.kind].append(e)
        shells = {size: [e for kind in kinds for e in by_kind.get(kind, [])] for size, kinds in SHELLS.items()}
        for kind, elements in sorted(by_kind.items()):
            if kind in LINES and kind.startswith("B"):
                m.unmapped.append(f"{len(elements)} {kind} beam element(s) (first at {elements[0].where}): brought over "
                                  "as cables, which carry tension only (no bending, no compression)")
            elif kind not in LINES and not any(kind in kinds for kinds in SHELLS.values()):
                why = next((text for prefix, text in NOT_SHELLS.items() if kind.startswith(prefix)),
                           "not a shell element shellsim has")
                self.unused_elements.append(f"{len(elements)} {kind} element(s) (first at {elements[0].where}): {why}")
        m.unmapped.extend(self.unused_elements)
        orders = [size for size, elements in shells.items() if elements]
        if not orders:
            raise MeshError(f"model file '{m.path}' has no shell elements shellsim reads "
                            f"({', '.join(sorted(set().union(*SHELLS.values())))}); found "
                            f"{', '.join(sorted(by_kind)) or 'no elements'}")
        elements = [e for size in orders for e in shells[size]]
        for e in elements:
            size = next(size for size, kinds in SHELLS.items() if e.kind in kinds)
            if len(e.nodes) != size:
                raise MeshError(f"model file '{m.path}', element {e.label} ({e.where}): a {e.kind} has "
                                f"{size} nodes; got {', '.join(e.nodes)}")
        positions = {label: m.coords[i] for label, i in m.nodes.items()}
        self.shells = ShellMesh(m.path, positions, [(e.label, e.nodes, e.where) for e in elements])
        lines = [e for kind in sorted(LINES) for e in by_kind.get(kind, [])]
        for e in lines:
            if len(e.nodes) != 2:
                raise MeshError(f"model file '{m.path}', element {e.label} ({e.where}): a {e.kind} has 2 nodes; "
                                f"got {', '.join(e.nodes)}")
        if lines:
            self.shells.add_lines(positions, [(e.label, e.nodes, e.where) for e in lines])
        m.unmapped.extend(self.shells.notes)
        self._named_sets()

    def _named_sets(self) -> None:
        m = self.model
        for key, named in m.elsets.items():
            elements = self.shells.elements_of(named.items)
            if len(elements):
                self.shells.add_set(("elset", key), named.name, self.shells.surface_set(elements))
            lines = self.shells.line_set(named.items)
            if lines is not None:  # beside the shells' surface set, if the set has both
                self.shells.add_set(("lines", key), named.name + ("_cables" if len(elements) else ""), lines)
        for key, named in m.nsets.items():
            nodes = self.shells.nodes_of(named.items)
            if not len(nodes):
                continue
            twin = self.shells.set_of.get(("elset", key))
            if twin is not None and np.array_equal(self.shells.sets[twin].nodes, nodes):
                self.shells.set_of[("nset", key)] = twin  # CAE writes a region as an nset and an elset alike
            else:
                self.shells.add_set(("nset", key), named.name + ("_nodes" if twin else ""), self.shells.node_set(nodes))
        for key, named in m.surfaces.items():
            if named.kind == "node":
                nodes = self.shells.nodes_of([label for label, _ in named.items])
                if len(nodes):
                    self.shells.add_set(("surface", key), named.name, self.shells.node_set(nodes))
                continue
            elements = self.shells.elements_of([label for label, _ in named.items])
            if len(elements):
                self.shells.add_set(("surface", key), named.name, self.shells.surface_set(elements))

    def node_set_for(self, k: Keyword, tokens: list[str], wanted: str) -> str:
        """The deck set of the nodes a data line's fields name: the named set itself when
        only one is named, else a new set ``wanted``."""
        if len(tokens) == 1 and qualified("", tokens[0]) is None:
            for what, table in (("nset", self.model.nsets), ("surface", self.model.surfaces)):
                try:
                    key = self.model.key_of(table, tokens[0], "", k, "node set")
                except MeshError:
                    continue
                if (what, key) in self.shells.set_of:
                    return self.shells.set_of[(what, key)]
        return self.shells.new_node_set([label for token in dict.fromkeys(tokens)
                                         for label in self.model.node_labels(token, "", k)], wanted, k.label())

    # -- material and section ---------------------------------------------------------------
    def material_and_section(self) -> None:
        m = self.model
        covered = np.zeros(len(self.shells.conn), dtype=bool)
        thickness = np.full(len(self.shells.conn), np.nan)
        parts: dict[tuple[str, str], tuple[Keyword, str, list[str]]] = {}  # (material, orientation) -> section, prefix, sets
        section_points: list[tuple[int, Keyword]] = []
        cables = []
        for k, elset, prefix in m.sections:
            elements = self.shells.elements_of(m.elsets[elset].items)
            if ("lines", elset) in self.shells.set_of:
                cable = self._cable(k, self.shells.set_of[("lines", elset)])
                cables += [cable] if cable is not None else []
                if not len(elements):
                    continue
            if k.name != "shell section":
                m.unmapped.append(f"{k.label()}: a {k.name} is not a shellsim section; its elements are left without one")
                continue
            if not k.rows or not k.rows[0] or not _is_number(k.rows[0][0]):
                m.unmapped.append(f"{k.label()}: the thickness is not a number (a distribution or nodal thickness); "
                                  "give [section] thickness")
                continue
            covered[elements] = True
            thickness[elements] = float(k.rows[0][0])
            if len(k.rows[0]) > 1 and k.rows[0][1].strip().isdigit():
                section_points.append((int(k.rows[0][1]), k))
            part = ((k.param("material") or "").lower(), (k.param("orientation") or "").lower())
            parts.setdefault(part, (k, prefix, []))[2].append(self.shells.set_of[("elset", elset)])
            offset = (k.param("offset") or "0").upper()
            if offset not in ("MIDDLE", "SMID") and not (_is_number(offset) and float(offset) == 0.0):
                m.unmapped.append(f"{k.label()}: OFFSET={k.param('offset')} is not read (shellsim's reference surface "
                                  "is the mid-surface)")
            for option in ("nodal thickness", "shell thickness"):
                if option in k.params:
                    m.unmapped.append(f"{k.label()}: {option.upper()} is not read (shellsim's reference surface is "
                                      "the mid-surface; thickness is [section] thickness)")
        if not covered.all():
            raise MeshError(f"model file '{m.path}': shell elements without a shell section: "
                            f"{listed(self.shells.labels_of(~covered))}")
        if not parts:
            raise MeshError(f"model file '{m.path}' has no *SHELL SECTION")
        values, counts = np.unique(thickness, return_counts=True)
        section: dict = {"thickness": float(values[counts.argmax()])}  # the mesh file's nodal values rule where they differ
        if len(values) > 1:  # nodal thickness, each node the mean of its elements' thicknesses
            total = np.zeros(len(self.shells.x))
            count = np.zeros(len(self.shells.x))
            np.add.at(total, self.shells.conn, thickness[:, None])
            np.add.at(count, self.shells.conn, 1.0)
            self.shells.thickness = total / np.maximum(count, 1.0)  # a cable's own node: 0
        if section_points:
            section["points_through_thickness"] = self._points_through_thickness(section_points)
        materials = self._materials(parts)
        if materials:
            if any(t["model"] != "linear_elastic" for t in materials) or "nlgeom" in self._step_params():
                section["technique"] = 1
            self.tables["material"] = materials[0] if len(parts) == 1 else materials
        self.tables["section"] = section
        if cables:
            self.tables["cable"] = cables

    def _cable(self, k: Keyword, lines: str) -> dict | None:
        """The cable table of the section ``k`` on the line set ``lines``: its area (a solid
        section's, or a circular beam section's pi r^2) and its material's 1D law and
        density; None (listed) where either does not map."""
        m = self.model
        row = [float(v) for v in k.rows[0] if _is_number(v)] if k.rows else []
        if k.name == "solid section":
            area = row[0] if row else 1.0  # Abaqus' default cross-section of a truss
        elif k.name == "beam section" and (k.param("section") or "").lower() == "circ" and row:
            area = float(np.pi * row[0] ** 2)
        else:
            m.unmapped.append(f"{k.label()}: a {k.name} of section type {k.param('section')} gives no cross-section "
                              f"shellsim reads (a *SOLID SECTION's area, a circular *BEAM SECTION's radius); the "
                              f"cables of '{lines}' are left out")
            return None
        key = (k.param("material") or "").lower()
        if key not in m.materials:
            raise MeshError(f"{k.label()}: unknown material '{k.param('material')}'")
        material, options = m.materials[key]
        by_name = {o.name: o for o in options}
        law = self._cable_law(by_name)
        if law is None:
            m.unmapped.append(f"{material.label()}: material '{material.param('name')}' of the cables of '{lines}' has "
                              "no 1D law shellsim maps (*ELASTIC, *HYPERELASTIC NEO HOOKE or OGDEN of N <= 6 terms "
                              "each with mu alpha > 0); they are "
                              "left out")
            return None
        density = by_name.get("density")
        if density is None:
            m.unmapped.append(f"{material.label()}: material '{material.param('name')}' of the cables of '{lines}' has "
                              "no *DENSITY; the cable's density 1.0 is a placeholder (only an explicit run uses it)")
        return {"name": deck_name(f"{lines}_cable", "cable"), "set": lines, "area": area,
                "density": float(density.rows[0][0]) if density is not None else 1.0, "law": law}

    @staticmethod
    def _cable_law(by_name: dict[str, Keyword]) -> dict | None:
        """The 1D law of a material's options (by name), None where none maps."""
        if "hyperelastic" in by_name:
            k = by_name["hyperelastic"]
            row = [float(v) for v in k.rows[0]] if k.rows else []
            if "neo hooke" in k.params and row:
                return {"model": "neo_hookean", "mu": 2.0 * row[0]}
            if "ogden" in k.params:
                return ogden_law(k)
            return None
        if "elastic" in by_name and by_name["elastic"].rows:
            return {"model": "linear", "E": float(by_name["elastic"].rows[0][0])}
        return None

    def _step_params(self) -> dict[str, str]:
        step = self.model.steps[0][0].params if self.model.steps else {}
        return {k: v for k, v in step.items() if not (k == "nlgeom" and v.upper() in ("NO", "OFF"))}

    def _points_through_thickness(self, section_points: list[tuple[int, Keyword]]) -> int:
        """The Gauss points through the thickness for the sections' own section points: as
        many up to 3; more (Abaqus' Simpson points, 5 by default) become 3, listed: the 3
        Gauss points integrate a polynomial of degree 5 through the thickness exactly, 5
        Simpson points one of degree 3."""
        count, k = max(section_points, key=lambda pk: pk[0])
        if count > 3:
            self.model.unmapped.append(f"{k.label()}: {count} section points become points_through_thickness = 3 "
                                       "(Gauss: exact through the thickness to degree 5, Simpson's 5 points to 3)")
        return min(count, 3)

    def _materials(self, parts: dict[tuple[str, str], tuple[Keyword, str, list[str]]]) -> list[dict]:
        """A material table for each (material, orientation) of the shell sections, naming
        the sets of its sections' elements where there are several; the density the file's
        gravity loads take is the first material's."""
        tables, first_density = [], None
        for (key, _), (section, prefix, sets) in parts.items():
            table = self._material(key, section, prefix)
            first_density = self.density if first_density is None else first_density
            if table is not None:
                tables.append(({"sets": sets} if len(parts) > 1 else {}) | table)
        unmapped = len(parts) - len(tables)
        if unmapped and tables:
            self.model.unmapped.append(f"{unmapped} of the {len(parts)} shell sections' materials map to no law "
                                       "(listed above): their elements have no [[material]] table; add one for them")
        self.density = first_density
        return tables

    def _material(self, key: str, section: Keyword, prefix: str) -> dict | None:
        m = self.model
        if key not in m.materials:
            raise MeshError(f"{section.label()}: unknown material '{section.param('material')}'")
        k, options = m.materials[key]
        name = k.param("name")
        by_name = {o.name: o for o in options}
        density = by_name.pop("density", None)
        self.density = float(density.rows[0][0]) if density is not None else None
        user = by_name.pop("user material", None)
        by_name.pop("depvar", None)
        table: dict | None = None
        if user is not None:
            constants = [v for row in user.rows for v in row if v.strip()]
            table = self.user_law.table([float(v) for v in constants]) if self.user_law is not None else None
            if table is None:
                m.unmapped.append(
                    f"{user.label()}: user material '{name}' (constants {', '.join(constants)}): "
                    + ("the --user-material mapping names more constants than it has" if self.user_law is not None
                       else "map its law with shellsim import --user-material 'MODEL: KEY = $n, ...' (e.g. "
                            "'lee_sacks: c0 = $1, c1 = $2, c2 = $3, c3 = 0, delta = 1'), or name it in [material]; "
                            "docs/import.md"))
        elif "anisotropic hyperelastic" in by_name:
            table = self._holzapfel(by_name.pop("anisotropic hyperelastic"), section, prefix)
        elif "hyperelastic" in by_name:
            table = self._hyperelastic(by_name.pop("hyperelastic"))
        elif "elastic" in by_name:
            e = by_name.pop("elastic")
            if (e.param("type") or "isotropic").lower() != "isotropic":
                m.unmapped.append(f"{e.label()}: only isotropic elasticity maps (TYPE={e.param('type')})")
            else:
                table = {"model": "linear_elastic", "E": float(e.rows[0][0]), "nu": float(e.rows[0][1])}
        else:
            m.unmapped.append(f"{k.label()}: material '{name}' has no law shellsim maps; name one in [material]")
        for option in by_name.values():
            m.unmapped.append(f"{option.label()}: *{option.name.upper()} of material '{name}' is not read")
        if table is None:
            return None
        table = self._with_axes(table, section, prefix)
        if self.density is None:
            m.unmapped.append(f"{k.label()}: material '{name}' has no *DENSITY; the deck's density 1.0 is a "
                              "placeholder (only an explicit run uses it)")
        return table | {"density": self.density if self.density is not None else 1.0}

    def _with_axes(self, table: dict, section: Keyword, prefix: str) -> dict:
        """``table`` with the section's orientation as its ``axes`` where its law takes axes
        and has none yet (Abaqus' default, x projected on the shell, where the section names
        none); a law without axes leaves an orientation out, listed. An axis of no length
        is listed and left out."""
        orientation = section.param("orientation")
        if "axes" in table:
            return table
        if "axes" not in MATERIALS[table["model"]].model_fields:
            if orientation is not None:
                self.model.unmapped.append(f"{section.label()}: ORIENTATION={orientation} is not carried: the "
                                           f"{table['model']} law has no material axes")
            return table
        axes, _ = self._axes(section, prefix)
        if axes["kind"] == "fixed" and not np.linalg.norm(axes["direction"]) > 0.0:
            self.model.unmapped.append(f"{section.label()}: the direction of ORIENTATION={orientation} is (0, 0, 0), "
                                       f"which points nowhere; the {table['model']} law's axes are left to its "
                                       "default (cylindrical): give material.axes")
            return table
        return table | {"axes": axes}

    def _hyperelastic(self, k: Keyword) -> dict | None:
        forms = [f for f in ("neo hooke", "mooney-rivlin", "polynomial", "reduced polynomial", "ogden", "yeoh",
                             "arruda-boyce", "van der waals", "marlow") if f in k.params]
        form = forms[0] if forms else "polynomial"
        order = int(k.param("n") or 1)
        row = [float(v) for v in k.rows[0]] if k.rows else []
        if form in ("neo hooke", "reduced polynomial") and order == 1:
            table, d1 = {"model": "neo_hookean", "C1": row[0]}, row[1:2]
        elif form in ("mooney-rivlin", "polynomial") and order == 1:
            table, d1 = {"model": "mooney_rivlin", "C1": row[0], "C2": row[1]}, row[2:3]
        else:
            self.model.unmapped.append(f"{k.label()}: the {form.upper()} form (N={order}) has no shellsim law; name "
                                       "one in [material]")
            return None
        if d1 and d1[0] != 0.0:
            self.model.unmapped.append(f"{k.label()}: D1 = {d1[0]:g} (compressibility) is dropped: shellsim's "
                                       "hyperelastic laws are incompressible")
        return table

    def _holzapfel(self, k: Keyword, section: Keyword, prefix: str) -> dict | None:
        if "holzapfel" not in k.params:
            self.model.unmapped.append(f"{k.label()}: only the HOLZAPFEL form of *ANISOTROPIC HYPERELASTIC maps")
            return None
        c10, d, k1, k2, kappa = ([float(v) for v in k.rows[0]] + [0.0] * 5)[:5]
        axes, families = self._axes(section, prefix)
        if families is not None and any(np.hypot(*family[:2]) == 0.0 for family in families):
            self.model.unmapped.append(f"{k.label()}: a LOCAL DIRECTION of the orientation has no length in the "
                                       "shell's plane, so no fibre angle; the law is left out")
            return None
        if families is None or len(families) != 2 or not np.isclose(families[0][1], -families[1][1]) \
                or not np.isclose(families[0][0], families[1][0]):
            self.model.unmapped.append(f"{k.label()}: shellsim's HGO has two fibre families at +-beta from material "
                                       "axis 1; give them as the orientation's two LOCAL DIRECTIONS (cos b, +-sin b, 0)")
            return None
        if d != 0.0:
            self.model.unmapped.append(f"{k.label()}: D = {d:g} (compressibility) is dropped: shellsim's HGO is "
                                       "incompressible")
        beta = float(np.degrees(np.arctan2(families[0][1], families[0][0])))
        return {"model": "hgo", "mu": 2.0 * c10, "k1": k1, "k2": k2, "kappa": kappa, "beta_deg": abs(beta),
                "axes": axes}

    def _axes(self, section: Keyword, prefix: str) -> tuple[dict, list | None]:
        """The material axes of a section's orientation and its local directions (rows)."""
        name = section.param("orientation")
        if name is None:  # Abaqus' default on a shell: global x projected on it
            return {"kind": "fixed", "direction": [1.0, 0.0, 0.0]}, None
        k, own = self.model.orientations[self.model.key_of(self.model.orientations, name, prefix, section, "orientation")]
        if (k.param("system") or "rectangular").lower() != "rectangular":
            self.model.unmapped.append(f"{k.label()}: SYSTEM={k.param('system')} is not read; axis 1 taken along x")
            return {"kind": "fixed", "direction": [1.0, 0.0, 0.0]}, None
        angle = 0.0
        if len(k.rows) > 1 and k.rows[1]:
            axis, angle = int(float(k.rows[1][0])), float(k.rows[1][1]) if len(k.rows[1]) > 1 else 0.0
            if axis != 3 and angle != 0.0:
                self.model.unmapped.append(f"{k.label()}: a rotation about local axis {axis} does not keep a shell's "
                                           "axes in its surface; not read")
                angle = 0.0
        n = int(k.param("local directions") or 0)
        families = [[float(v) for v in row[:3]] for row in k.rows[2:2 + n]] or None
        first = k.rows[0]
        if len(first) == 1 and not _is_number(first[0]):
            field = self._distribution(first[0], own, k)
            axes = {"kind": "mesh", "field": field}
        else:
            axes = {"kind": "fixed", "direction": [float(v) for v in first[:3]]}
        return axes | ({"angle_deg": angle} if angle else {}), families

    def _distribution(self, name: str, prefix: str, where: Keyword) -> str:
        """Per-element directions from a ``*DISTRIBUTION`` (first column: the element, the
        default row blank) as the cell vectors named after it."""
        k, own = self.model.distributions[self.model.key_of(self.model.distributions, name, prefix, where,
                                                               "distribution")]
        default = None
        vectors = np.full((len(self.shells.conn), 3), np.nan)
        for row in k.rows:
            values = np.asarray([float(v) for v in row[1:4]])
            if row[0] == "":
                default = values
                continue
            for label in self.model.element_labels(row[0], own, k):
                if label in self.shells.pieces_of:
                    vectors[self.shells.pieces_of[label]] = values
        if default is not None:
            vectors[np.isnan(vectors).any(axis=1)] = default
        if np.isnan(vectors).any():
            missing = self.shells.labels_of(np.isnan(vectors).any(axis=1))
            raise MeshError(f"{k.label()}: no direction for elements {listed(missing)} (and no default row)")
        if not np.all(np.linalg.norm(vectors, axis=1) > 0.0):
            zero = self.shells.labels_of(~(np.linalg.norm(vectors, axis=1) > 0.0))
            raise MeshError(f"{k.label()}: the direction of elements {listed(zero)} is (0, 0, 0), which points "
                            "nowhere; give each element a direction")
        field = deck_name(k.param("name") or "orientation", "axis")
        self.shells.cell_vectors[field] = vectors
        return field

    # -- curves -----------------------------------------------------------------------------
    def curves_of_amplitudes(self) -> None:
        curves = {}
        for key, k in self.model.amplitudes.items():
            definition = (k.param("definition") or "tabular").lower()
            values = [float(v) for row in k.rows for v in row if v != ""]
            if definition == "equally spaced":
                step, begin = float(k.param("fixed interval")), float(k.param("begin") or 0.0)
                t, a = [begin + i * step for i in range(len(values))], values
            elif definition in ("tabular", "smooth step"):
                t, a = values[0::2], values[1::2]
            else:
                self.model.unmapped.append(f"{k.label()}: DEFINITION={k.param('definition')} has no shellsim curve; "
                                           "tabulate it")
                continue
            if (k.param("value") or "relative").lower() == "absolute":
                self.model.unmapped.append(f"{k.label()}: VALUE=ABSOLUTE: in shellsim a curve scales the load's value")
            name = deck_name(k.param("name") or "amplitude", "curve")
            curve = {"t": t, "value": a}
            if definition == "smooth step":
                curve["interpolate"] = "smooth_step"
            curves[name] = curve
            self.curve_of[key] = name
        self.used_curves: set[str] = set()
        self.all_curves = curves

    def _curve(self, k: Keyword) -> dict:
        name = k.param("amplitude")
        if name is None:
            return {}
        key = name.lower()
        if key not in self.curve_of:
            raise MeshError(f"{k.label()}: unknown amplitude '{name}'")
        self.used_curves.add(self.curve_of[key])
        return {"curve": self.curve_of[key]}

    # -- supports and loads -----------------------------------------------------------------
    def supports_and_loads(self) -> None:
        step = self.model.steps[0][1] if self.model.steps else []
        keywords = self.model.model_data + step
        boundary, loads = [], []
        held: dict[str, tuple[Keyword, list[str], set[int]]] = {}  # token -> (first keyword, tokens, dofs)
        moved: dict[tuple[int, str], dict] = {}
        for k in keywords:
            if k.name == "boundary":
                self._boundary(k, held, moved)
            elif k.name == "cload":
                loads += self._cload(k)
            elif k.name in ("dload", "dsload"):
                loads += self._distributed(k)
        for k, tokens, dofs in _one_per_kind(held):
            entry = self._support(k, tokens, dofs)
            if entry is not None:
                boundary.append(entry)
        for (dof, _), entry in moved.items():
            boundary.append(self._prescribed(dof, entry))
        if boundary:
            self.tables["boundary"] = boundary
        if loads:
            self.tables["load"] = loads
        curves = {name: c for name, c in self.all_curves.items() if name in self.used_curves}
        if curves:
            self.tables["curves"] = curves

    def _boundary(self, k: Keyword, held: dict, moved: dict) -> None:
        kind = (k.param("type") or "displacement").lower()
        if kind != "displacement":
            self.model.unmapped.append(f"{k.label()}: TYPE={k.param('type')} is not read (shellsim prescribes "
                                       "displacements)")
            return
        if (k.param("op") or "").lower() == "new":
            self.model.unmapped.append(f"{k.label()}: OP=NEW: shellsim keeps the model's boundaries as well")
        for row, line in zip(k.rows, k.row_lines):
            token = row[0]
            if len(row) > 1 and row[1].lower() in BOUNDARY_TYPES:
                dofs, value = BOUNDARY_TYPES[row[1].lower()], 0.0
            else:
                try:
                    first = int(row[1])
                    last = int(row[2]) if len(row) > 2 and row[2] else first
                    value = float(row[3]) if len(row) > 3 and row[3] else 0.0
                except (ValueError, IndexError):
                    raise MeshError(f"{k.at(line)}: expected 'node or set, first dof[, last dof[, value]]' "
                                    f"or a boundary type ({', '.join(t.upper() for t in BOUNDARY_TYPES)}); got "
                                    f"'{', '.join(row)}'") from None
                dofs = set(range(max(first, 1), min(last, 6) + 1))
                if first < 1 or last > 6:
                    self.model.unmapped.append(f"{k.at(line)}: degrees of freedom {first} to {last} of '{token}': a "
                                               "shell node has 1-6 (translations 1-3, rotations 4-6); "
                                               + ("none is" if not dofs else "the others are") + " read")
                if not dofs:
                    continue
            if value == 0.0:
                entry = held.setdefault(token.lower() if qualified("", token) is None else f"node {token.lower()}",
                                        (k, [token], set()))
                entry[2].update(dofs)
                continue
            for dof in dofs:
                if dof > 3:
                    self.model.unmapped.append(f"{k.at(line)}: a rotation prescribed to {value:g} is not "
                                               "read (shellsim prescribes translations)")
                    continue
                entry = moved.setdefault((dof, k.param("amplitude") or ""), {"keyword": k, "values": {}, "tokens": []})
                entry["tokens"].append(token)
                for label in self.model.node_labels(token, "", k):
                    entry["values"][label] = value

    def _support(self, k: Keyword, tokens: list[str], dofs: set[int]) -> dict | None:
        wanted = f"support_{tokens[0]}" if len(tokens) == 1 else "held_" + "".join(map(str, sorted(dofs)))
        name = self.node_set_for(k, tokens, wanted)
        entry, problem = support_table(name, {d for d in dofs if d <= 3}, {d for d in dofs if d > 3})
        if problem:
            self.model.unmapped.append(f"{k.label()}: {problem}")
        return entry

    def _prescribed(self, dof: int, entry: dict) -> dict:
        k, values = entry["keyword"], entry["values"]
        distinct = sorted(set(values.values()))
        name = self.node_set_for(k, entry["tokens"], f"moved_{AXES[dof - 1]}")
        table = {"type": "prescribed", "set": name, "translation": AXES[dof - 1]} | self._curve(k)
        if len(distinct) == 1:
            return table | {"value": distinct[0]}
        field = np.zeros(len(self.shells.x))
        given = {self.shells.index_of_label[label]: v for label, v in values.items() if label in self.shells.index_of_label}
        field[list(given)] = list(given.values())
        # a new mid-edge node moves as the mean of its corners (its corners are both given)
        nodes = self.shells.sets[name].nodes
        known = np.zeros(len(self.shells.x), dtype=bool)
        known[list(given)] = True
        for node in nodes[~known[nodes]]:
            corners = self.shells.corners_of(node)
            field[node] = field[corners].mean()
        self.shells.point_fields[name] = field
        return table | {"value": 1.0, "field": name}

    def _cload(self, k: Keyword) -> list[dict]:
        vectors: dict[str, np.ndarray] = defaultdict(lambda: np.zeros(6))
        for row, line in zip(k.rows, k.row_lines):
            try:
                dof, magnitude = int(row[1]), float(row[2])
            except (ValueError, IndexError):
                raise MeshError(f"{k.at(line)}: expected 'node or set, dof, magnitude'; got "
                                f"'{', '.join(row)}'") from None
            for label in self.model.node_labels(row[0], "", k):
                vectors[label][dof - 1] += magnitude
        groups: dict[tuple, list[str]] = defaultdict(list)
        for label, vector in vectors.items():
            groups[tuple(vector)].append(label)
        loads = []
        tokens = [row[0] for row in k.rows]
        # a concentrated load acts on the nodes the file names, not on the new ones between them
        wanted = f"{tokens[0]}_loaded" if len(groups) == 1 and len(set(tokens)) == 1 else f"cload_{k.where.split(':')[-1]}"
        for vector, labels in groups.items():
            name = self.shells.new_node_set(labels, wanted, k.label(), lift=False)
            for kind, part in (("point_force", vector[:3]), ("point_moment", vector[3:])):
                if any(part):
                    loads.append({"type": kind, "set": name, "value": list(part)} | self._curve(k))
        return loads

    def _distributed(self, k: Keyword) -> list[dict]:
        loads = []
        for row, line in zip(k.rows, k.row_lines):
            kind = row[1].upper() if len(row) > 1 else ""
            try:
                values = [float(v) for v in row[2:]]
            except ValueError:
                raise MeshError(f"{k.at(line)}: the magnitude is not a number: '{', '.join(row)}'") from None
            if kind == "P":
                loads += self._pressure(k, row[0], values[0])
            elif kind == "GRAV" and k.name == "dload":
                if self.density is None:
                    self.model.unmapped.append(f"{k.at(line)}: gravity needs the material's *DENSITY")
                    continue
                direction = np.asarray(values[1:4])
                loads.append({"type": "body_force", "set": self._elements_set(k, row[0]),
                              "value": list(self.density * values[0] * direction)} | self._curve(k))
            elif kind in ("BX", "BY", "BZ") and k.name == "dload":
                value = [values[0] * (kind[1] == axis.upper()) for axis in AXES]
                loads.append({"type": "body_force", "set": self._elements_set(k, row[0]), "value": value}
                             | self._curve(k))
            else:
                self.model.unmapped.append(f"{k.at(line)}: load type {kind} is not read")
        return loads

    def _elements_set(self, k: Keyword, token: str) -> str:
        if qualified("", token) is None:
            key = self.model.key_of(self.model.elsets, token, "", k, "element set")
            if ("elset", key) in self.shells.set_of:
                return self.shells.set_of[("elset", key)]
        elements = self.shells.elements_of(self.model.element_labels(token, "", k))
        return self.shells.add_set(None, f"load_{k.where.split(':')[-1]}", self.shells.surface_set(elements))

    def _pressure(self, k: Keyword, token: str, magnitude: float) -> list[dict]:
        """Pressure loads on the mid-surface pushing where Abaqus pushes: against a face's
        outward normal (SPOS: the element's normal; SNEG: its opposite)."""
        if k.name == "dsload":
            surface = self.model.surface(token, k)
            if surface.kind == "node":
                self.model.unmapped.append(f"{k.label()}: pressure on the node-based surface '{token}' is not read")
                return []
            faces = [(piece, side) for label, side in surface.items for piece in self.shells.pieces_of.get(label, [])]
            if any(side not in ("SPOS", "SNEG") for _, side in faces):
                self.model.unmapped.append(f"{k.label()}: surface '{token}' has faces that are neither SPOS nor SNEG; "
                                           "read as SPOS")
            sign = np.asarray([-1.0 if side != "SNEG" else 1.0 for _, side in faces])
            elements = np.asarray([e for e, _ in faces], dtype=np.int64)
            whole = ("surface", self.model.key_of(self.model.surfaces, token, "", k, "surface"))
        else:
            elements = self.shells.elements_of(self.model.element_labels(token, "", k))
            sign = -np.ones(len(elements))
            whole = ("elset", self.model.key_of(self.model.elsets, token, "", k, "element set")) \
                if qualified("", token) is None else None
        return pressure_loads(self.shells, elements, sign, magnitude, whole, f"pressure_{k.where.split(':')[-1]}",
                              self._curve(k))

    # -- contact and solver -----------------------------------------------------------------
    def contact(self) -> None:
        m = self.model
        keywords = m.model_data + (m.steps[0][1] if m.steps else [])
        contacts = []
        general = any(k.name == "contact" for k in keywords)
        friction_of = {key: self._friction(options) for key, options in m.interactions.items()}
        assigned = [k for k in keywords if k.name == "contact property assignment"]
        general_friction = next((friction_of.get(row[2].lower(), 0.0) for k in assigned for row in k.rows
                                 if len(row) > 2), 0.0)
        for k in keywords:
            if k.name == "contact pair":
                friction = friction_of.get((k.param("interaction") or "").lower(), 0.0)
                pairs = k.rows
            elif k.name == "contact inclusions" and general:
                friction = general_friction
                pairs = [["all", "all"]] if "all exterior" in k.params else k.rows
            else:
                continue
            for row in pairs:
                names = [n if n.lower() == "all" else self.shells.set_of.get(("surface", m.key_of(m.surfaces, n, "", k, "surface")))
                         for n in (row + row[:1])[:2]]
                if None in names:
                    m.unmapped.append(f"{k.label()}: a contact of node-based surfaces is not read")
                    continue
                entry = {"type": "shells", "name": f"contact_{len(contacts) + 1}", "set": names[0]}
                if names[1] != names[0]:
                    entry["against"] = names[1]
                contacts.append(entry | ({"friction": friction} if friction else {}))
        if contacts:
            self.tables["contact"] = contacts
            for options in m.interactions.values():
                self._interaction_notes(options)

    def _interaction_notes(self, options: list[Keyword]) -> None:
        """List what a surface interaction says beyond its friction: a softened pressure-
        overclosure (with its constants) and contact damping."""
        for k in options:
            overclosure = (k.param("pressure-overclosure") or "hard").lower()
            if k.name == "surface behavior" and overclosure != "hard":
                constants = ", ".join(v for row in k.rows for v in row)
                self.model.unmapped.append(
                    f"{k.label()}: PRESSURE-OVERCLOSURE={overclosure.upper()} ({constants or 'no constants'}) is not "
                    "carried: shellsim's contact is a penalty scaled to each node's critical-step spring "
                    "(contact.penalty, 0.1 by default); soft leaflets pressed by a full pressure sink into "
                    "each other at 0.1, and closed with 1 to 3 (docs/start-import.md)")
            elif k.name == "contact damping":
                self.model.unmapped.append(f"{k.label()}: *CONTACT DAMPING is not carried (shellsim's contact has no "
                                           "damping of its own)")

    @staticmethod
    def _friction(options: list[Keyword]) -> float:
        for k in options:
            if k.name == "friction" and k.rows and k.rows[0] and _is_number(k.rows[0][0]):
                return float(k.rows[0][0])
        return 0.0

    def solver(self) -> None:
        m = self.model
        if not m.steps:
            m.unmapped.append(f"model file '{m.path.name}' has no *STEP: a static solve to pseudo-time 1 is assumed")
            self.tables["solver"] = {"method": "static", "end_time": 1.0}
            return
        for k, _ in m.steps[1:]:
            m.unmapped.append(f"{k.label()}: only the first step is brought over")
        step, items = m.steps[0]
        procedures = [k for k in items if k.name in ("static", "dynamic")]
        known = {"static", "dynamic", "boundary", "cload", "dload", "dsload", "contact pair", "contact",
                 "contact inclusions", "contact property assignment", *MASS_SCALING}
        for k in items:
            if k.name not in known and k.name not in OUTPUT_REQUESTS:
                m.unmapped.append(f"{k.label()}: not read by shellsim")
        if not procedures:
            m.unmapped.append(f"{step.label()}: a step without *STATIC or *DYNAMIC: a static solve to pseudo-time 1 "
                              "is assumed")
            self.tables["solver"] = {"method": "static", "end_time": 1.0}
            return
        k = procedures[0]
        row = [float(v) if _is_number(v) else None for v in (k.rows[0] if k.rows else [])] + [None] * 4
        if k.name == "static":
            period = row[1] or 1.0
            solver: dict = {"method": "static", "end_time": period}
            if row[0]:
                solver["static"] = {"increments": max(1, round(period / row[0]))}
        else:
            if "explicit" not in k.params:
                m.unmapped.append(f"{k.label()}: implicit dynamics: shellsim integrates the step explicitly")
            solver = {"method": "explicit", "end_time": row[1] or 1.0}
        self.tables["solver"] = solver

    def mass_scaling(self) -> None:
        """``*VARIABLE`` or ``*FIXED MASS SCALING`` of the first step to a time step DT: on a
        set of line elements, its cables' ``min_step`` (each element made heavier until its
        own step is DT, as TYPE=BELOW MIN does); on shells or the whole model, the explicit
        solve's uniform ``[solver.mass_scaling]``, held ``throughout`` the run for a variable
        one (listed: every mass scaled by one factor, not each element's by its own)."""
        m = self.model
        for k in (k for k in (m.steps[0][1] if m.steps else []) if k.name in MASS_SCALING):
            step, elset, kind = k.param("dt"), k.param("elset"), (k.param("type") or "uniform").lower()
            if step is None or not _is_number(step) or kind not in ("below min", "uniform", "set equal dt"):
                m.unmapped.append(f"{k.label()}: only mass scaling to a time step (DT=, TYPE=BELOW MIN, UNIFORM or "
                                  "SET EQUAL DT) is read; a FACTOR= or target steps are not")
                continue
            lines = self.shells.set_of.get(("lines", m.key_of(m.elsets, elset, "", k, "element set"))) if elset else None
            inside = set(self.shells.sets[lines].elements) if lines else set()
            cables = [c for c in self.tables.get("cable", []) if set(self.shells.sets[c["set"]].elements) <= inside]
            if cables:
                for cable in cables:
                    cable["min_step"] = float(step)
                if kind == "set equal dt":
                    m.unmapped.append(f"{k.label()}: TYPE=SET EQUAL DT also makes the stiffer elements lighter; the "
                                      f"cables of '{lines}' are only made heavier (cable.min_step)")
                continue
            if self.tables["solver"].get("method") != "explicit":
                m.unmapped.append(f"{k.label()}: mass scaling is for an explicit solve; not read")
                continue
            variable = k.name == "variable mass scaling"
            self.tables["solver"]["mass_scaling"] = {"step": float(step), **({"throughout": True} if variable else {})}
            m.unmapped.append(f"{k.label()}: {'ELSET=' + elset if elset else 'the whole model'}, TYPE="
                              f"{kind.upper()}: brought over as [solver.mass_scaling] step = {float(step):g}"
                              f"{', throughout = true' if variable else ''}, which scales every mass by one factor "
                              f"when the stable step is shorter{' (again as it falls)' if variable else ''}")


#: Keywords that scale masses for a longer explicit step.
MASS_SCALING = ("variable mass scaling", "fixed mass scaling")


def _one_per_kind(held: dict[str, tuple[Keyword, list[str], set[int]]]) -> list[tuple[Keyword, list[str], set[int]]]:
    """The supports of ``held`` (token -> first keyword, tokens, dofs) with the nodes named
    one by one that hold the same dofs made one support: 32 papillary tips, each held by
    its own line, are one set and one [[boundary]] table; named sets stay their own."""
    supports, by_dofs = [], {}
    for token, (k, tokens, dofs) in held.items():
        if not token.startswith("node "):
            supports.append((k, tokens, dofs))
        elif frozenset(dofs) in by_dofs:
            by_dofs[frozenset(dofs)][1].extend(tokens)
        else:
            by_dofs[frozenset(dofs)] = (k, list(tokens), dofs)
            supports.append(by_dofs[frozenset(dofs)])
    return supports


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def ogden_law(k: Keyword) -> dict | None:
    """An ``*HYPERELASTIC, OGDEN, N=n`` law (n <= 6): its data lines hold mu_1, alpha_1,
    ..., mu_n, alpha_n, then the compressibilities D_i (an incompressible chord takes
    none); None where it does not fit :class:`~shellsim.loads.cable_laws.Ogden`."""
    try:
        terms = int(k.param("n") or 1)
        values = [float(v) for row in k.rows for v in row if str(v).strip()]
    except ValueError:
        return None
    if not 1 <= terms <= OGDEN_TERMS or len(values) < 2 * terms:
        return None
    mu, alpha = values[0:2 * terms:2], values[1:2 * terms:2]
    if not all(m * a > 0.0 for m, a in zip(mu, alpha)):
        return None
    return {"model": "ogden", "mu": mu[0], "alpha": alpha[0]} if terms == 1 else {"model": "ogden", "mu": mu,
                                                                                    "alpha": alpha}
