"""A synthetic atrioventricular (tricuspid) valve as an Abaqus input file and a FEBio file,
with every feature a patient-specific valve model for Abaqus/Explicit carries: the shapes
and numbers are made up, the features are those of such a model.

Geometry (mm): three separate leaflets of S4R shells in a near-closed position, each the
aortic valve builder's leaflet (:func:`shellsim.geometry.builders.valve_points`) turned
upside down and hung from an arc of the annulus ring (radius 15, z = 0): a belly from the
annulus down to a vertical coaptation band 3 mm tall, whose lower edge is the free edge,
at z = -12, along the two lines from the commissures (radius 12.5) to the axis, 0.5 mm from
its neighbours'. Only the annulus holds a leaflet: its sides are free, 0.5 mm from its
neighbours' down to the free edge, as an atrioventricular valve's commissures are (the
aortic root's posts, clamped down to the free edge, fold such soft leaflets where they
meet the annulus). ``circumferential`` elements across each leaflet, ``belly`` + ``band``
from the annulus to the free edge (90 x (24 + 6) x 3 = 8,100 by default: 0.27 mm columns
along the free edge, 0.34 mm at the annulus; the belly's rows 0.41 mm beside the
commissures, 0.81 mm mid-leaflet, the band's 0.5 mm). A chord of ``segments`` T3D2 elements from each free-edge node down to one
of ``tips`` papillary tips (z = -25) in three groups, one under each leaflet (273 chords
of 15 elements, 4,095, by default). Under the ventricle's pressure the bellies rise and
the bands press together, as the aortic valve's do under the aorta's; the chordae keep
the free edges from turning up.

Abaqus file (mm-tonne-s, MPa):
- each leaflet its own ``*SHELL SECTION`` (0.4 mm, 5 section points) and material of one
  user law, W = C0/2 (I1 - 3) + C1/2 (exp(C2 (I1 - 3)^2) - 1), C2 = 4.57, 14.86 and 17.75
  (the valve model's spread; C0 = 0.001 and C1 = 0.0005 MPa are illustrative);
- a per-element ``*ORIENTATION`` (``*DISTRIBUTION``) along the free edge;
- each chord group its own ``*HYPERELASTIC, OGDEN, N=3`` law: two write one term as three
  of equal exponent, the third has two distinct terms (illustrative constants);
- per-node annulus motion (each node its own displacement, on an amplitude), papillary
  tips held node by node, 23 mmHg on the leaflets' SPOS faces by a SMOOTH STEP
  amplitude, general contact with friction 0.01 and a linear pressure-overclosure, and
  ``*VARIABLE MASS SCALING`` on the chordae.

FEBio file (format 4.0, the same mesh): three shell domains of their own
Holzapfel-Gasser-Ogden constants with a per-element ``mat_axis``, three beam domains of
linear trusses, the tips held, the annulus moved, a pressure on a load controller,
sliding contact of the leaflets with friction, a dynamic step.

    python -m shellsim.verify.synthetic_valve valve.inp [--circumferential 90 --belly 24 ...]
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from ..deck.geometry import AorticValve
from ..geometry.builders import along_free_edge, valve_points

#: The leaflets' shape: the aortic valve builder's, turned upside down [mm].
SHAPE = AorticValve(builder="aortic_valve", commissure_radius=12.5, base_radius=15.0, height=12.0,
                    coaptation_height=3.0, gap=0.5)
TIP_DEPTH, TIP_INWARD = 25.0, 0.6
THICKNESS, SECTION_POINTS, CHORD_AREA, DENSITY = 0.4, 5, 0.4, 1.1e-9
#: The leaflets' user-law constants (C0, C1, C2) [MPa, MPa, -].
LEAFLET_LAWS = ((0.001, 0.0005, 4.57), (0.001, 0.0005, 14.86), (0.001, 0.0005, 17.75))
#: Each chord group's Ogden terms (mu_i [MPa], alpha_i): one term written three times, twice;
#: two distinct exponents once.
CHORD_LAWS = (((0.02, 20.0),) * 3, ((0.03, 16.0),) * 3, ((0.02, 20.0), (0.02, 20.0), (0.01, 28.0)))
PRESSURE = 23.0 * 133.322387415e-6  # 23 mmHg [MPa]
FRICTION, OVERCLOSURE_STIFFNESS, MASS_SCALING_STEP = 0.01, 10.0, 5e-5
LEAFLETS = ("Anterior", "Posterior", "Septal")


def _leaflet_points(g: int, u: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(n, 3) leaflet g's points at u (n,) from commissure to commissure and y (n,) from
    the annulus (0) to the free edge (1): the builder's hung from the ring, z turned over."""
    return valve_points(SHAPE, np.full(len(u), g), u, y, ring=True) * [1.0, 1.0, -1.0]


@dataclass(frozen=True)
class SyntheticValve:
    """The valve's mesh: node labels from 1, leaflet by leaflet and row by row from the
    attachment, then the tips and the chords' own nodes; shell labels from 1, chord
    labels after."""

    circumferential: int = 90
    belly: int = 24
    band: int = 6
    segments: int = 15
    tips: int = 32

    @property
    def rows(self) -> int:
        """Rows of shells from the attachment to the free edge."""
        return self.belly + self.band

    def node(self, g: int, i: int, j: int) -> int:
        """The label of leaflet ``g``'s node on row ``i`` (0: the attachment) and column
        ``j`` (0 to ``circumferential``, commissure to commissure)."""
        return 1 + (g * (self.rows + 1) + i) * (self.circumferential + 1) + j

    def _parameters(self, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """u and y of rows i and columns j: the belly's rows over y < 1/2, the band's over
        the rest."""
        y = np.where(i <= self.belly, 0.5 * i / self.belly, 0.5 + 0.5 * (i - self.belly) / self.band)
        return j / self.circumferential, y

    @cached_property
    def points(self) -> dict[int, np.ndarray]:
        """{label: position (3,)} of the leaflets' nodes."""
        i, j = (a.ravel() for a in np.mgrid[0:self.rows + 1, 0:self.circumferential + 1])
        u, y = self._parameters(i, j)
        return {self.node(g, a, b): p for g in range(3)
                for a, b, p in zip(i, j, _leaflet_points(g, u, y))}

    @cached_property
    def shells(self) -> list[tuple[int, int, list[int]]]:
        """(label, leaflet, corners) of each shell, its corners turning so that its normal
        points to the ventricle (down and out, toward its own leaflet's side): a pressure
        on SPOS pushes the bellies up and the bands together, to close."""
        out = []
        for g in range(3):
            side = [np.cos(np.radians(90.0 + 120.0 * g)), np.sin(np.radians(90.0 + 120.0 * g)), -1.0]
            for i in range(self.rows):
                for j in range(self.circumferential):
                    corners = [self.node(g, i, j), self.node(g, i, j + 1), self.node(g, i + 1, j + 1),
                               self.node(g, i + 1, j)]
                    a, b, _, d = (self.points[n] for n in corners)
                    if np.dot(np.cross(b - a, d - a), side) < 0.0:
                        corners.reverse()
                    out.append((len(out) + 1, g, corners))
        return out

    @cached_property
    def tip_positions(self) -> list[tuple[int, int, np.ndarray]]:
        """(label, group, position) of each papillary tip: spread under its leaflet's free
        edge, drawn in toward the axis."""
        out, label = [], max(self.points) + 1
        for g in range(3):
            count = self.tips // 3 + (g < self.tips % 3)
            u = (np.arange(count) + 0.5) / count
            edge = _leaflet_points(g, u, np.ones(count))
            for p in edge:
                out.append((label, g, np.array([TIP_INWARD * p[0], TIP_INWARD * p[1], -TIP_DEPTH])))
                label += 1
        return out

    @cached_property
    def chords(self) -> tuple[list[tuple[int, np.ndarray]], list[tuple[int, int, int, int]]]:
        """(label, position) of the chords' own nodes and (label, group, end, end) of
        their elements: a chord from each free-edge node to the nearest tip along its
        leaflet's edge."""
        nodes, elements = [], []
        label = self.tip_positions[-1][0] + 1
        element = len(self.shells) + 1
        tips = [[t for t in self.tip_positions if t[1] == g] for g in range(3)]
        edge = self.circumferential + 1
        for g in range(3):
            for k in range(edge):
                tip_label, _, tip = tips[g][min(k * len(tips[g]) // edge, len(tips[g]) - 1)]
                end = self.node(g, self.rows, k)
                start = self.points[end]
                chain = [end]
                for m in range(1, self.segments):
                    nodes.append((label, start + m / self.segments * (tip - start)))
                    chain.append(label)
                    label += 1
                chain.append(tip_label)
                for a, b in zip(chain, chain[1:]):
                    elements.append((element, g, a, b))
                    element += 1
        return nodes, elements

    def circumferential_axes(self) -> np.ndarray:
        """(shells, 3) each shell's unit direction along its leaflet's free edge (growing
        u) at its centre, where the collagen runs."""
        i, j = (a.ravel() for a in np.mgrid[0:self.rows, 0:self.circumferential])
        u, y = self._parameters(i + 0.5, j + 0.5)
        return np.concatenate([along_free_edge(SHAPE, np.full(len(u), g), u, y, ring=True)
                               for g in range(3)]) * [1.0, 1.0, -1.0]

    def annulus_motion(self) -> list[tuple[int, np.ndarray]]:
        """(label, displacement) of each annulus node: 5% inward and a saddle of 0.5 mm."""
        out = []
        for label in (self.node(g, 0, j) for g in range(3) for j in range(self.circumferential + 1)):
            x, y, _ = self.points[label]
            t = np.arctan2(y, x)
            out.append((label, np.array([-0.05 * x, -0.05 * y, 0.5 * np.cos(2 * t)])))
        return out


def _lines(values, per_line: int = 8) -> list[str]:
    """Numbers as Abaqus data lines of at most ``per_line`` values."""
    values = list(values)
    return [", ".join(f"{v!r}" for v in values[i:i + per_line]) for i in range(0, len(values), per_line)]


def _labels(labels: list[int]) -> list[str]:
    return [", ".join(map(str, labels[i:i + 16])) for i in range(0, len(labels), 16)]


def abaqus_text(valve: SyntheticValve) -> str:
    """The valve as an Abaqus/Explicit input file."""
    out = ["*Heading", " Synthetic tricuspid valve: three leaflets, chordae, annulus motion, 23 mmHg",
           "** Units: mm, tonne, s, N, MPa", "*Node"]
    out += [f"{label}, {x:.12g}, {y:.12g}, {z:.12g}" for label, (x, y, z) in valve.points.items()]
    out += [f"{label}, {x:.12g}, {y:.12g}, {z:.12g}" for label, _, (x, y, z) in valve.tip_positions]
    chord_nodes, chord_elements = valve.chords
    out += [f"{label}, {x:.12g}, {y:.12g}, {z:.12g}" for label, (x, y, z) in chord_nodes]
    for g, name in enumerate(LEAFLETS):
        out += [f"*Element, type=S4R, elset=Leaflet{name}"]
        out += [", ".join(map(str, [label, *corners])) for label, leaflet, corners in valve.shells if leaflet == g]
        out += [f"*Element, type=T3D2, elset=Chordae{name}"]
        out += [f"{label}, {a}, {b}" for label, group, a, b in chord_elements if group == g]
    out += ["*Elset, elset=Leaflets"] + [f"Leaflet{name}," for name in LEAFLETS]
    out += ["*Elset, elset=Chordae"] + [f"Chordae{name}," for name in LEAFLETS]
    out += ["*Surface, type=ELEMENT, name=Ventricular", "Leaflets, SPOS"]
    out += ["*Orientation, name=LeafletAxes, system=RECTANGULAR", "LeafletAxesDist", "3, 0.",
            "*Distribution Table, name=LeafletAxesTable", "coord3d, coord3d",
            "*Distribution, name=LeafletAxesDist, location=ELEMENT, table=LeafletAxesTable",
            ", 1., 0., 0., 0., 1., 0."]
    out += [f"{label}, {a:.12g}, {b:.12g}, {c:.12g}, 0., 0., 1." for (label, _, _), (a, b, c)
            in zip(valve.shells, valve.circumferential_axes())]
    for name, (c0, c1, c2), chord in zip(LEAFLETS, LEAFLET_LAWS, CHORD_LAWS):
        out += [f"*Shell Section, elset=Leaflet{name}, material=Leaflet{name}, orientation=LeafletAxes",
                f"{THICKNESS}, {SECTION_POINTS}",
                f"*Solid Section, elset=Chordae{name}, material=Chord{name}", f"{CHORD_AREA},",
                f"*Material, name=Leaflet{name}", "*Density", f"{DENSITY},", "*Depvar", "1,",
                "*User Material, constants=3", f"{c0!r}, {c1!r}, {c2!r}",
                f"*Material, name=Chord{name}", "*Density", f"{DENSITY},", "*Hyperelastic, ogden, n=3"]
        out += _lines([v for term in chord for v in term] + [0.0, 0.0, 0.0])
    out += ["*Amplitude, name=AnnulusMotion", "0., 0., 0.1, 1.",
            "*Amplitude, name=Closing, definition=SMOOTH STEP", "0., 0., 0.1, 1.",
            "*Surface Interaction, name=LeafletContact", "*Friction", f"{FRICTION},",
            "*Surface Behavior, pressure-overclosure=LINEAR", f"{OVERCLOSURE_STIFFNESS},",
            "*Boundary"]
    out += [f"{label}, 1, 3" for label, _, _ in valve.tip_positions]  # each tip on its own line
    out += ["*Step, name=Closing, nlgeom=YES", "*Dynamic, Explicit", ", 0.1",
            f"*Variable Mass Scaling, dt={MASS_SCALING_STEP}, elset=Chordae, type=below min, frequency=100",
            "*Boundary, amplitude=AnnulusMotion"]
    out += [f"{label}, {dof + 1}, {dof + 1}, {u[dof]:.12g}" for label, u in valve.annulus_motion() for dof in range(3)]
    out += ["*Dsload, amplitude=Closing", f"Ventricular, P, {PRESSURE!r}",
            "*Contact", "*Contact Inclusions, ALL EXTERIOR", "*Contact Property Assignment", " ,  , LeafletContact",
            "*Output, field, variable=PRESELECT", "*End Step"]
    return "\n".join(out) + "\n"


def febio_text(valve: SyntheticValve) -> str:
    """The valve as a FEBio 4.0 file: HGO leaflets, linear-truss chordae."""
    chord_nodes, chord_elements = valve.chords
    nodes = list(valve.points.items())
    nodes += [(label, p) for label, _, p in valve.tip_positions] + chord_nodes
    xyz = "".join(f'<node id="{label}">{x:.12g},{y:.12g},{z:.12g}</node>' for label, (x, y, z) in nodes)
    materials, domains, elements = [], [], []
    for g, name in enumerate(LEAFLETS):
        c0, _, c2 = LEAFLET_LAWS[g]
        materials.append(f'<material id="{2 * g + 1}" name="Leaflet{name}" type="Holzapfel-Gasser-Ogden">'
                         f"<density>{DENSITY}</density><c>{c0}</c><k1>{c0 * c2}</k1><k2>{c2}</k2><kappa>0.1</kappa>"
                         "<gamma>0</gamma><k>1</k></material>")
        materials.append(f'<material id="{2 * g + 2}" name="Chord{name}" type="linear truss">'
                         f"<density>{DENSITY}</density><E>{3 * sum(mu for mu, _ in CHORD_LAWS[g])}</E><v>0.49</v></material>")
        elements.append(f'<Elements type="quad4" name="Leaflet{name}">' + "".join(
            f'<elem id="{label}">{",".join(map(str, corners))}</elem>' for label, leaflet, corners in valve.shells
            if leaflet == g) + "</Elements>")
        elements.append(f'<Elements type="truss2" name="Chordae{name}">' + "".join(
            f'<elem id="{label}">{a},{b}</elem>' for label, group, a, b in chord_elements if group == g) + "</Elements>")
        domains.append(f'<ShellDomain name="Leaflet{name}" mat="Leaflet{name}"><shell_thickness>{THICKNESS}'
                       "</shell_thickness></ShellDomain>")
        domains.append(f'<BeamDomain name="Chordae{name}" mat="Chord{name}" type="linear-truss">'
                       f"<cross_sectional_area>{CHORD_AREA}</cross_sectional_area></BeamDomain>")
    facets = "".join(f'<quad4 id="{label}">{",".join(map(str, corners))}</quad4>' for label, _, corners in valve.shells)
    axes = "".join(f'<e lid="{k + 1}"><a>{a:.12g},{b:.12g},{c:.12g}</a><d>0,0,1</d></e>'
                   for k, (a, b, c) in enumerate(valve.circumferential_axes()))
    annulus = ",".join(str(label) for label, _ in valve.annulus_motion())
    tips = ",".join(str(label) for label, _, _ in valve.tip_positions)
    shells = ",".join(str(label) for label, _, _ in valve.shells)
    return f'''<?xml version="1.0" encoding="ISO-8859-1"?>
<febio_spec version="4.0">
  <Module type="solid"/>
  <Control><analysis>DYNAMIC</analysis><time_steps>1000</time_steps><step_size>0.0001</step_size></Control>
  <Material>{"".join(materials)}</Material>
  <Mesh>
    <Nodes name="Valve">{xyz}</Nodes>
    {"".join(elements)}
    <NodeSet name="Annulus">{annulus}</NodeSet>
    <NodeSet name="Tips">{tips}</NodeSet>
    <ElementSet name="Leaflets">{shells}</ElementSet>
    <Surface name="Ventricular">{facets}</Surface>
    <SurfacePair name="Coaptation"><primary>Ventricular</primary><secondary>Ventricular</secondary></SurfacePair>
  </Mesh>
  <MeshDomains>{"".join(domains)}</MeshDomains>
  <MeshData><ElementData name="LeafletAxes" type="mat_axis" elem_set="Leaflets">{axes}</ElementData></MeshData>
  <Boundary>
    <bc name="Tips" type="zero displacement" node_set="Tips"><x_dof>1</x_dof><y_dof>1</y_dof><z_dof>1</z_dof></bc>
    <bc name="AnnulusIn" type="prescribed displacement" node_set="Annulus"><dof>z</dof><value lc="1">0.5</value>
      <relative>0</relative></bc>
  </Boundary>
  <Loads><surface_load name="Ventricle" type="pressure" surface="Ventricular"><pressure lc="2">{PRESSURE!r}</pressure>
    </surface_load></Loads>
  <Contact><contact type="sliding-elastic" surface_pair="Coaptation"><fric_coeff>{FRICTION}</fric_coeff></contact>
  </Contact>
  <LoadData>
    <load_controller id="1" name="AnnulusMotion" type="loadcurve"><interpolate>LINEAR</interpolate>
      <points><pt>0,0</pt><pt>0.1,1</pt></points></load_controller>
    <load_controller id="2" name="Closing" type="loadcurve"><interpolate>SMOOTH</interpolate>
      <points><pt>0,0</pt><pt>0.1,1</pt></points></load_controller>
  </LoadData>
</febio_spec>
'''


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("path", type=Path, help="the file to write: .inp (Abaqus) or .feb (FEBio)")
    defaults = SyntheticValve()
    for key in ("circumferential", "belly", "band", "segments", "tips"):
        parser.add_argument(f"--{key}", type=int, default=getattr(defaults, key))
    options = parser.parse_args()
    valve = SyntheticValve(options.circumferential, options.belly, options.band, options.segments, options.tips)
    writer = febio_text if options.path.suffix.lower() == ".feb" else abaqus_text
    options.path.write_text(writer(valve))
    print(f"wrote {options.path}: {len(valve.shells)} shells, {len(valve.chords[1])} chord elements")


if __name__ == "__main__":
    main()
