"""A FEBio model (``.feb``, formats 3.0 and 4.0) as a shellsim mesh and deck tables.

Shell domains (quad4, quad8, quad9, tri3) become 9-node quads with their node sets,
element sets and surfaces as named sets, shell thickness and material axes from the mesh
data; 2-node trusses in beam domains become cables (chordae), each domain a line set and
a [[cable]] table; the materials that map, zero and prescribed displacements, pressures,
nodal forces, contact pairs, load controllers and the first step's control become deck
tables. What has no counterpart is listed with its line.

Signs: a facet's normal follows its nodes by the right-hand rule, and a positive pressure
pushes against it (FEBio's convention), on the mid-surface, as a shell's reference surface.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
import xml.parsers.expat
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..errors import MeshError
from . import ForeignModel, meta_table
from .deck_tables import AXES, pressure_loads, support_table
from .shell_mesh import ShellMesh, deck_name

#: The attribute under which each XML element keeps its line.
LINE = "{shellsim}line"
SHELL_TYPES = {"tri3": 3, "quad4": 4, "quad8": 8, "quad9": 9}
#: FEBio's 2-node truss, in a <BeamDomain> ("linear-truss", "elastic-truss"): a cable.
TRUSS = "truss2"
#: Sections the reader does not need: their content is not part of the mechanics.
QUIET = {"Module", "Globals"}


def read_febio(path: Path) -> ForeignModel:
    """The model of the FEBio file ``path``; MeshError for one without usable shells."""
    root = _parse(path)
    version = root.get("version", "")
    if root.tag != "febio_spec" or version.split(".")[0] not in ("3", "4"):
        raise MeshError(f"'{path}' is not a FEBio model of format 3.0 or 4.0 (root <{root.tag}> version "
                        f"'{version}'); FEBio Studio saves one with File > Save As")
    reader = _Reader(path, root)
    return ForeignModel(reader.shells.imported(), reader.tables, reader.unmapped, reader.unused_elements,
                        reader.shells.id_map())


def _parse(path: Path) -> ET.Element:
    """The XML tree of ``path``, each element's line kept in its attributes under LINE."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise MeshError(f"model file '{path}' cannot be read: {error.strerror or error}") from None
    builder = ET.TreeBuilder()
    parser = xml.parsers.expat.ParserCreate()

    def start(tag: str, attrs: dict) -> None:
        builder.start(tag, attrs | {LINE: str(parser.CurrentLineNumber)})

    parser.StartElementHandler, parser.EndElementHandler, parser.CharacterDataHandler = start, builder.end, builder.data
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as error:
        raise MeshError(f"model file '{path}' is not well-formed XML: {error}") from None
    return builder.close()


class _Reader:
    def __init__(self, path: Path, root: ET.Element):
        self.path, self.root = path, root
        self.unmapped: list[str] = []
        self.unused_elements: list[str] = []
        self.tables: dict = {"meta": meta_table(path, path.stem)}
        for section in root:
            if section.tag in QUIET:
                continue
            if section.tag == "Output":
                self.unmapped.append(f"output requests ({self.where(section)}): shellsim writes its own fields; "
                                     "choose them in [output]")
                continue
            if section.tag not in ("Control", "Material", "Mesh", "MeshDomains", "MeshData", "Boundary", "Loads",
                                   "Contact", "LoadData", "Step"):
                self.unmapped.append(f"{self.where(section)}: not read by shellsim")
        self._curves()
        #: the file's materials by name and by id
        self.materials = {key: m for m in root.findall("Material/material") for key in (m.get("name"), m.get("id"))}
        self.used_curves: set[str] = set()
        self._mesh()
        self._material()
        self._cables()
        steps = root.findall("Step/step")
        for step in steps[1:]:
            self.unmapped.append(f"{self.where(step)}: only the first step is brought over")
        first = steps[:1]
        self._boundaries([b for s in [root] + first for b in s.findall("Boundary/bc")])
        self._loads([load for s in [root] + first for load in s.findall("Loads/*")])
        self._contact(root.findall("Contact/contact"))
        self._solver(first[0].find("Control") if first and first[0].find("Control") is not None
                     else root.find("Control"))
        curves = {name: c for name, c in self.curves.items() if name in self.used_curves}
        if curves:
            self.tables["curves"] = curves

    def where(self, element: ET.Element) -> str:
        """An XML element as a message names it: '<material name="Leaflet"> (valve.feb:12)'."""
        name = element.get("name") or element.get("type")
        label = f'<{element.tag} {"name" if element.get("name") else "type"}="{name}">' if name else f"<{element.tag}>"
        return f"{label} ({self.path.name}:{element.get(LINE)})"

    # -- mesh -------------------------------------------------------------------------------
    def _mesh(self) -> None:
        mesh = self.root.find("Mesh")
        if mesh is None:
            raise MeshError(f"model file '{self.path}' has no <Mesh>")
        positions = {}
        for node in mesh.iter("node"):
            try:
                positions[node.get("id")] = np.asarray([float(v) for v in node.text.split(",")], dtype=float)[:3]
            except (ValueError, AttributeError):
                raise MeshError(f"{self.where(node)}: a node is 'x,y,z'; got '{node.text}'") from None
        shell_domains = {d.get("name"): d for d in self.root.findall("MeshDomains/ShellDomain")}
        beam_domains = {d.get("name"): d for d in self.root.findall("MeshDomains/BeamDomain")}
        for domain in self.root.find("MeshDomains") or []:
            if domain.tag not in ("ShellDomain", "BeamDomain"):
                self.unused_elements.append(f"{self.where(domain)}: a {domain.tag}; only shell domains and trusses "
                                            "come over")
        elements, lines, self.corner_labels = [], [], []
        for block in mesh.findall("Elements"):
            kind, name = block.get("type"), block.get("name")
            rows = block.findall("elem")
            if name in shell_domains and kind in SHELL_TYPES:
                for e in rows:
                    nodes = [n.strip() for n in (e.text or "").split(",")]
                    if len(nodes) != SHELL_TYPES[kind]:
                        raise MeshError(f"{self.where(e)}: a {kind} has {SHELL_TYPES[kind]} nodes; got '{e.text}'")
                    elements.append((e.get("id"), nodes, f"{self.path.name}:{e.get(LINE)}"))
                    self.corner_labels.append(nodes[:3 if len(nodes) == 3 else 4])
            elif name in beam_domains and kind == TRUSS:
                for e in rows:
                    nodes = [n.strip() for n in (e.text or "").split(",")]
                    if len(nodes) != 2:
                        raise MeshError(f"{self.where(e)}: a {TRUSS} has 2 nodes; got '{e.text}'")
                    lines.append((e.get("id"), nodes, f"{self.path.name}:{e.get(LINE)}"))
            elif name not in shell_domains and name not in beam_domains:
                self.unused_elements.append(f"{self.where(block)}: {len(rows)} {kind} element(s) in no shell or "
                                            "beam domain")
            else:
                self.unused_elements.append(f"{self.where(block)}: {kind} elements are neither shells nor "
                                            f"{TRUSS} trusses")
        self.unmapped.extend(self.unused_elements)
        if not elements:
            raise MeshError(f"model file '{self.path}' has no shell elements in a <ShellDomain> "
                            f"({', '.join(SHELL_TYPES)})")
        self.shells = ShellMesh(self.path, positions, elements)
        if lines:
            self.shells.add_lines(positions, lines)
        self.unmapped.extend(self.shells.notes)
        self.element_sets = {name: [e.get("id") for e in mesh.findall(f"Elements[@name='{name}']/elem")]
                             for name in shell_domains | beam_domains}
        for es in mesh.findall("ElementSet"):
            self.element_sets[es.get("name")] = _ids(es, "e")
        for name, labels in self.element_sets.items():
            elements = self.shells.elements_of(labels)
            if len(elements):
                self.shells.add_set(("elset", name), name, self.shells.surface_set(elements))
            cables = self.shells.line_set(labels)
            if cables is not None:  # beside the shells' surface set, if the set has both
                self.shells.add_set(("lines", name), name + ("_cables" if len(elements) else ""), cables)
        self.node_sets = {ns.get("name"): _ids(ns, "n") for ns in mesh.findall("NodeSet")}
        for name, labels in self.node_sets.items():
            nodes = self.shells.nodes_of(labels)
            if len(nodes):
                self.shells.add_set(("nset", name), name, self.shells.node_set(nodes))
        by_corners = {frozenset(corners): i for i, corners in enumerate(self.corner_labels)}
        self.faces = {s.get("name"): self._faces(s, by_corners) for s in mesh.findall("Surface")}
        for name, faces in self.faces.items():
            if faces:
                self.shells.add_set(("surface", name), name, self.shells.surface_set(
                    np.unique([e for e, _ in faces]).astype(np.int64)))
        self.pairs = {p.get("name"): [(p.findtext(a) or p.findtext(b) or "").strip()
                                      for a, b in (("primary", "master"), ("secondary", "slave"))]
                      for p in mesh.findall("SurfacePair")}
        self._thickness()

    def _faces(self, surface: ET.Element, by_corners: dict) -> list[tuple[int, float]]:
        """The surface's facets as (mesh element, +1 where the facet's normal is the file
        element's own, -1 where opposite); facets on no shell element are listed.
        ``by_corners``: each file element's index by its set of corner labels."""
        faces, lost = [], 0
        for facet in surface:
            nodes = [n.strip() for n in (facet.text or "").split(",")][:3 if facet.tag == "tri3" else 4]
            index = by_corners.get(frozenset(nodes))
            if index is None:
                lost += 1
                continue
            own = self.corner_labels[index]
            turn = own.index(nodes[0])
            along = 1.0 if own[turn:] + own[:turn] == nodes else -1.0
            faces += [(piece, along) for piece in self.shells.pieces_of[self.shells.labels[index]]]
        if lost:
            self.unmapped.append(f"{self.where(surface)}: {lost} facet(s) are not a shell element's face; left out")
        return faces

    def _thickness(self) -> None:
        """Shell thickness from the domains and the mesh data (per element, or per node of
        each element): one value as [section] thickness, several as nodal thickness."""
        per_element = np.full(len(self.shells.conn), np.nan)
        for domain in self.root.findall("MeshDomains/ShellDomain"):
            text = domain.findtext("shell_thickness")
            if text is not None and float(text) > 0:
                per_element[self.shells.elements_of(self.element_sets.get(domain.get("name"), []))] = float(text)
        for data in self.root.findall("MeshData/ElementData"):
            if (data.get("type") or data.get("var")) != "shell thickness":
                continue
            labels = self.element_sets.get(data.get("elem_set"), [])
            for e in data.findall("e"):
                values = [float(v) for v in e.text.split(",")]
                label = labels[int(e.get("lid")) - 1]
                per_element[self.shells.elements_of([label])] = float(np.mean(values))
        if np.isnan(per_element).any():
            missing = self.shells.labels_of(np.isnan(per_element))
            raise MeshError(f"model file '{self.path}': no shell thickness for elements {', '.join(missing[:5])}")
        values, counts = np.unique(per_element, return_counts=True)
        self.tables["section"] = {"thickness": float(values[counts.argmax()]), "technique": 1}
        if len(values) > 1:
            total, count = np.zeros(len(self.shells.x)), np.zeros(len(self.shells.x))
            np.add.at(total, self.shells.conn, per_element[:, None])
            np.add.at(count, self.shells.conn, 1.0)
            self.shells.thickness = total / np.maximum(count, 1.0)  # a cable's own node: 0

    # -- material ---------------------------------------------------------------------------
    def _material(self) -> None:
        """A material table for each material of the shell domains, naming the sets of its
        domains' elements where there are several; the density the file's gravity takes is
        the first material's."""
        materials, by_material = self.materials, {}
        for domain in self.root.findall("MeshDomains/ShellDomain"):
            if domain.get("mat") not in materials:
                raise MeshError(f"{self.where(domain)}: the shell domain's material '{domain.get('mat') or ''}' is not "
                                "defined")
            by_material.setdefault(materials[domain.get("mat")], []).append(
                self.shells.set_of[("elset", domain.get("name"))])
        if not by_material:
            raise MeshError(f"model file '{self.path}': no shell domain names a material")
        tables, first_density = [], None
        for m, sets in by_material.items():
            table = self._material_table(m)
            first_density = self.density if first_density is None else first_density
            if table is not None:
                tables.append(({"sets": sets} if len(by_material) > 1 else {}) | table)
        if tables and len(tables) < len(by_material):
            self.unmapped.append(f"{len(by_material) - len(tables)} of the shell domains' {len(by_material)} "
                                 "materials map to no law (listed above): their elements have no [[material]] table; "
                                 "add one for them")
        self.density = first_density
        if tables:
            self.tables["material"] = tables[0] if len(by_material) == 1 else tables

    def _material_table(self, m: ET.Element) -> dict | None:
        """The material table of the FEBio material ``m``; None (listed) where it has no law."""
        kind = m.get("type")
        value = {child.tag: child.text for child in m}

        def number(key: str, default: float | None = None) -> float | None:
            return float(value[key]) if key in value else default

        self.density = number("density")
        table = None
        if kind == "neo-Hookean":
            E, nu = number("E"), number("v", 0.0)
            table = {"model": "neo_hookean", "C1": E / (4 * (1 + nu))}
            if nu < 0.49:
                self.unmapped.append(f"{self.where(m)}: compressible (v = {nu:g}); shellsim's neo-Hooke is "
                                     "incompressible: C1 = E / (4 (1 + v)) keeps the shear modulus")
        elif kind in ("Mooney-Rivlin", "coupled Mooney-Rivlin"):
            table = {"model": "mooney_rivlin", "C1": number("c1"), "C2": number("c2", 0.0)}
        elif kind == "isotropic elastic":  # FEBio's is St. Venant-Kirchhoff: technique 1 with a linear elastic material
            table = {"model": "linear_elastic", "E": number("E"), "nu": number("v", 0.0)}
        elif kind == "Holzapfel-Gasser-Ogden":
            table = {"model": "hgo", "mu": number("c"), "k1": number("k1"), "k2": number("k2"),
                     "kappa": number("kappa", 0.0), "beta_deg": number("gamma", 0.0), "axes": self._axes(m)}
        else:
            self.unmapped.append(f"{self.where(m)}: the material type '{kind}' has no shellsim law; name one in "
                                 "[material] (e.g. 'lee_sacks' for leaflets, docs/decks.md)")
        if table is None:
            return None
        if "k" in value and table["model"] != "linear_elastic":
            self.unmapped.append(f"{self.where(m)}: k = {value['k']} (bulk modulus) is dropped: shellsim's "
                                 "hyperelastic laws are incompressible")
        if self.density is None:
            self.unmapped.append(f"{self.where(m)}: no density; the deck's 1.0 is a placeholder (only an explicit "
                                 "run uses it)")
        return table | {"density": self.density if self.density is not None else 1.0}

    def _cables(self) -> None:
        """A [[cable]] table for each beam domain of trusses: its line set, the domain's
        cross_sectional_area, its material's 1D law and density. A domain whose area or
        material does not map is listed and its cables left out."""
        cables = []
        for domain in self.root.findall("MeshDomains/BeamDomain"):
            lines = self.shells.set_of.get(("lines", domain.get("name")))
            if lines is None:  # no trusses in it: its elements are listed already
                continue
            material = self.materials.get(domain.get("mat"))
            if material is None:
                raise MeshError(f"{self.where(domain)}: the material '{domain.get('mat')}' is not defined")
            law = _truss_law(material)
            area = float(domain.findtext("cross_sectional_area") or 0.0)
            if law is None:
                self.unmapped.append(f"{self.where(material)}: a truss of type '{material.get('type')}' has no "
                                     f"shellsim 1D law ('linear truss', 'neo-Hookean' map); the cables of '{lines}' "
                                     "are left out")
            elif not area > 0.0:
                self.unmapped.append(f"{self.where(domain)}: no positive cross_sectional_area; the cables of "
                                     f"'{lines}' are left out")
            else:
                density = material.findtext("density")
                if density is None:
                    self.unmapped.append(f"{self.where(material)}: no density; the cables' 1.0 is a placeholder (only "
                                         "an explicit run uses it)")
                cables.append({"name": deck_name(f"{lines}_cable", "cable"), "set": lines, "area": area,
                               "density": float(density) if density is not None else 1.0, "law": law})
        if cables:
            self.tables["cable"] = cables

    def _axes(self, material: ET.Element) -> dict:
        """Material axis 1: per element from the mesh data's mat_axis or fiber, or the
        material's own."""
        for data in self.root.findall("MeshData/ElementData"):
            kind = data.get("type") or data.get("var")
            if kind in ("mat_axis", "fiber"):  # axis 1 as a frame's a vector, or as the fibre itself
                labels = self.element_sets.get(data.get("elem_set"), [])
                vectors = np.full((len(self.shells.conn), 3), np.nan)
                for e in data.findall("e"):
                    direction = e.findtext("a") if kind == "mat_axis" else e.text
                    vectors[self.shells.elements_of([labels[int(e.get("lid")) - 1]])] = _vector(direction)
                if np.isnan(vectors).any():
                    raise MeshError(f"{self.where(data)}: no axis for elements "
                                    f"{', '.join(self.shells.labels_of(np.isnan(vectors).any(axis=1))[:5])}")
                field = deck_name(data.get("name") or kind, "axis")
                self.shells.cell_vectors[field] = vectors
                return {"kind": "mesh", "field": field}
        axis = material.find("mat_axis")
        if axis is not None and axis.get("type") == "vector":
            return {"kind": "fixed", "direction": list(_vector(axis.findtext("a")))}
        if axis is not None:
            self.unmapped.append(f"{self.where(axis)}: mat_axis type '{axis.get('type')}' is not read; axis 1 along x")
        return {"kind": "fixed", "direction": [1.0, 0.0, 0.0]}

    # -- curves, supports, loads ------------------------------------------------------------
    def _curves(self) -> None:
        """The load curves by deck name (``curves``) and their names by id (``curve_of_id``)."""
        self.curves, self.curve_of_id = {}, {}
        for lc in self.root.findall("LoadData/load_controller"):
            points = [_vector(p.text, 2) for p in lc.iter() if p.tag in ("pt", "point")]
            if lc.get("type") != "loadcurve" or not points:
                self.unmapped.append(f"{self.where(lc)}: only load curves of points are read")
                continue
            interpolate = (lc.findtext("interpolate") or "LINEAR").strip().upper()
            extend = (lc.findtext("extend") or "CONSTANT").strip().upper()
            curve = {"t": [float(p[0]) for p in points], "value": [float(p[1]) for p in points]}
            if interpolate == "SMOOTH":
                curve["interpolate"] = "smooth"
                self.unmapped.append(f"{self.where(lc)}: SMOOTH is brought over as shellsim's smooth curve (a cubic "
                                     "with zero slope at every point)")
            elif interpolate == "STEP":
                curve["interpolate"] = "step"
            if extend == "EXTRAPOLATE":
                curve["extrapolate"] = "linear"
            elif extend != "CONSTANT":
                self.unmapped.append(f"{self.where(lc)}: extend {extend} is read as CONSTANT")
            name = deck_name(lc.get("name") or f"lc{lc.get('id')}", "lc")
            self.curves[name] = curve
            self.curve_of_id[lc.get("id")] = name

    def _curve(self, element: ET.Element | None) -> dict:
        """The deck's curve of a value's load controller (``lc`` attribute), if any."""
        lc = element.get("lc") if element is not None else None
        if lc is None:
            return {}
        if lc not in self.curve_of_id:
            raise MeshError(f"{self.where(element)}: unknown load controller {lc}")
        self.used_curves.add(self.curve_of_id[lc])
        return {"curve": self.curve_of_id[lc]}

    def _boundaries(self, bcs: list[ET.Element]) -> None:
        held: dict[str, set[int]] = defaultdict(set)
        boundary = []
        for bc in bcs:
            kind, node_set = bc.get("type"), bc.get("node_set")
            if ("nset", node_set) not in self.shells.set_of:
                raise MeshError(f"{self.where(bc)}: unknown node set '{node_set}'")
            if kind in ("zero displacement", "fix"):
                dofs = {i + 1 for i, a in enumerate(AXES) if bc.findtext(f"{a}_dof", "0").strip() == "1"}
                listed = [d.strip() for d in (bc.findtext("dofs") or "").split(",")]  # format 3.0: "x,y"
                dofs |= {AXES.index(d) + 1 for d in listed if d in tuple(AXES)}
                held[node_set] |= dofs
            elif kind == "zero shell displacement":  # the shell's back face held: its director kept
                if all(bc.findtext(f"s{a}_dof", "0").strip() == "1" for a in AXES):
                    held[node_set] |= {4, 5, 6}
                else:
                    self.unmapped.append(f"{self.where(bc)}: only all three shell displacements held are read")
            elif kind in ("prescribed displacement", "prescribe"):
                value = bc.find("value") if bc.find("value") is not None else bc.find("scale")
                axis = (bc.findtext("dof") or "").strip()
                if axis not in AXES or value is None:
                    self.unmapped.append(f"{self.where(bc)}: only a displacement along x, y or z is read")
                    continue
                if (bc.findtext("relative") or "0").strip() == "1":
                    self.unmapped.append(f"{self.where(bc)}: relative is read as absolute (the first step starts "
                                         "undeformed)")
                boundary.append({"type": "prescribed", "set": self.shells.set_of[("nset", node_set)],
                                 "translation": axis, "value": float(value.text)} | self._curve(value))
            else:
                self.unmapped.append(f"{self.where(bc)}: not read by shellsim")
        for node_set, dofs in held.items():
            entry, problem = support_table(self.shells.set_of[("nset", node_set)], {d for d in dofs if d <= 3},
                                           {d for d in dofs if d > 3})
            if entry is not None:
                boundary.insert(0, entry)
            if problem:
                self.unmapped.append(f"<bc node_set=\"{node_set}\">: {problem}")
        if boundary:
            self.tables["boundary"] = boundary

    def _loads(self, loads: list[ET.Element]) -> None:
        tables = []
        for load in loads:
            kind = load.get("type")
            if load.tag == "surface_load" and kind == "pressure":
                name = load.get("surface")
                if name not in self.faces:
                    raise MeshError(f"{self.where(load)}: unknown surface '{name}'")
                if (load.findtext("shell_bottom") or "0").strip() == "1":
                    self.unmapped.append(f"{self.where(load)}: shell_bottom: read on the mid-surface")
                value = load.find("pressure")
                faces = self.faces[name]
                elements = np.asarray([e for e, _ in faces], dtype=np.int64)
                along = -np.asarray([a for _, a in faces])  # a positive pressure pushes against the facet's normal
                tables += pressure_loads(self.shells, elements, along, float(value.text), ("surface", name),
                                         f"pressure_{load.get(LINE)}", self._curve(value))
            elif load.tag == "nodal_load":
                node_set = load.get("node_set")
                if ("nset", node_set) not in self.shells.set_of:
                    raise MeshError(f"{self.where(load)}: unknown node set '{node_set}'")
                labels = self.node_sets[node_set]  # the nodes the file names, not the new ones between them
                name = self.shells.new_node_set(labels, f"{node_set}_loaded", self.where(load), lift=False)
                value = load.find("value")
                if value is not None:  # format 4.0: the force vector
                    force = list(_vector(value.text))
                else:  # format 3.0: a dof and a scale
                    value = load.find("scale")
                    force = [float(value.text) * (a == (load.findtext("dof") or "").strip()) for a in AXES]
                tables.append({"type": "point_force", "set": name, "value": force} | self._curve(value))
            else:
                self.unmapped.append(f"{self.where(load)}: not read by shellsim")
        if tables:
            self.tables["load"] = tables

    def _contact(self, contacts: list[ET.Element]) -> None:
        tables = []
        for contact in contacts:
            if contact.get("type", "").startswith("tied") or contact.get("type") == "sticky":
                self.unmapped.append(f"{self.where(contact)}: tied contact is not read")
                continue
            pair = self.pairs.get(contact.get("surface_pair"))
            if pair is None or not all(("surface", s) in self.shells.set_of for s in pair):
                self.unmapped.append(f"{self.where(contact)}: its surface pair is not on shell faces")
                continue
            first, second = (self.shells.set_of[("surface", s)] for s in pair)
            entry = {"type": "shells", "name": f"contact_{len(tables) + 1}", "set": first}
            entry |= {"against": second} if second != first else {}
            friction = float(contact.findtext("fric_coeff") or 0.0)
            tables.append(entry | ({"friction": friction} if friction else {}))
        if tables:
            self.tables["contact"] = tables

    def _solver(self, control: ET.Element | None) -> None:
        if control is None:
            self.unmapped.append(f"model file '{self.path.name}' has no <Control>: a static solve to time 1 is assumed")
            self.tables["solver"] = {"method": "static", "end_time": 1.0}
            return
        steps, size = int(control.findtext("time_steps") or 10), float(control.findtext("step_size") or 0.1)
        analysis = (control.findtext("analysis") or "STATIC").strip().upper()
        if analysis == "STATIC":
            self.tables["solver"] = {"method": "static", "end_time": steps * size, "static": {"increments": steps}}
        else:
            self.tables["solver"] = {"method": "explicit", "end_time": steps * size}
            self.unmapped.append(f"{self.where(control)}: {analysis.lower()} analysis: shellsim integrates it "
                                 "explicitly")


def _truss_law(material: ET.Element) -> dict | None:
    """The cable law of a truss's FEBio material: 'linear truss' (E) as the linear law, a
    'neo-Hookean' (E, v) as the incompressible one of its shear modulus E / (2 (1 + v));
    None for others."""
    kind, E, v = material.get("type"), material.findtext("E"), material.findtext("v") or "0.5"
    if kind == "linear truss" and E is not None:
        return {"model": "linear", "E": float(E)}
    if kind == "neo-Hookean" and E is not None:
        return {"model": "neo_hookean", "mu": float(E) / (2.0 * (1.0 + float(v)))}
    return None


def _ids(element: ET.Element, child: str) -> list[str]:
    """The ids of a set: a comma list (format 4.0) or children with an id (3.0)."""
    listed = [v.strip() for v in (element.text or "").split(",") if v.strip()]
    return listed + [c.get("id") for c in element if c.tag in (child, "node", "elem")]


def _vector(text: str | None, size: int = 3) -> np.ndarray:
    values = [float(v) for v in (text or "").split(",")]
    if len(values) != size:
        raise MeshError(f"expected {size} comma-separated numbers; got '{text}'")
    return np.asarray(values)
