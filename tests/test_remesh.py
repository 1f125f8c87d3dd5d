"""The surface remesher under the sizes and stops users give it: bad elements gmsh
leaves are found and mended, clean tubes and the shipped carotid mesh at sizes where gmsh
alone folded them, a size in the wrong units is refused before any meshing with an
estimate and a size to use, and Ctrl-C or SIGTERM stops gmsh at once."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from shellsim.deck import parse_deck
from shellsim.errors import MeshError
from shellsim.geometry import build_mesh
from shellsim.geometry.untangle import bad_elements, untangled
from shellsim.mesh import mid_surface_area
from shellsim.mesh_reading import facet_normals, read_triangles

from .conftest import ROOT, cylinder_stl
from .test_mesh import build


DECK = """[meta]
title = "a surface meshed far too finely"
units = "SI"

[geometry]
builder = "file"
path = "{path}"
element_size = 6.0e-5

[material]
model = "neo_hookean"
C1 = 1.0e4
density = 1000.0

[section]
thickness = 0.0006

[solver]
end_time = 1.0
"""


def _flat_grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A flat n x n grid of quad9 elements on the unit square, z = 0: nodes (., 3), conn (n^2, 9)."""
    side = np.linspace(0.0, 1.0, 2 * n + 1)
    x = np.array([[u, v, 0.0] for v in side for u in side])
    row = 2 * n + 1
    conn = []
    for j in range(n):
        for i in range(n):
            a = 2 * j * row + 2 * i
            conn.append([a, a + 2, a + 2 * row + 2, a + 2 * row, a + 1, a + row + 2, a + 2 * row + 1, a + row,
                         a + row + 1])
    return x, np.array(conn)


def test_a_fold_is_found_and_smoothed_out_with_the_boundary_kept():
    """A flat 4 x 4 grid with an interior corner pushed across its neighbours (the
    elements around it turned over or darts): those are found bad; mending leaves none,
    every node on the plane, the boundary nodes where they were, and the mid-side nodes
    halfway between their corners."""
    x, conn = _flat_grid(4)
    assert not len(bad_elements(x, conn))
    corner = conn[5, 0]  # an interior corner shared by four elements
    folded = x.copy()
    folded[corner, :2] += [0.4, 0.3]
    assert len(bad_elements(folded, conn)) >= 2
    mended = untangled(folded, conn, lambda nodes: nodes * [1.0, 1.0, 0.0])
    assert not len(bad_elements(mended, conn))
    np.testing.assert_allclose(mended[:, 2], 0.0)
    edge = np.isclose(x[:, 0], 0.0) | np.isclose(x[:, 0], 1.0) | np.isclose(x[:, 1], 0.0) | np.isclose(x[:, 1], 1.0)
    np.testing.assert_allclose(mended[edge], x[edge])
    np.testing.assert_allclose(mended[conn[:, 4]], 0.5 * (mended[conn[:, 0]] + mended[conn[:, 1]]), atol=1e-12)


@pytest.mark.parametrize("divisor", [7, 9, 10])
def test_a_coarse_cylinder_meshes_at_sizes_where_gmsh_alone_folded_it(tmp_path, divisor):
    """The 32 x 8 facet cylinder (R = 1, L = 3) at R/7, R/9 and R/10, where one gmsh mesh
    at the size had folded elements (benchmarks/remesh_sizes.py): the mesh passes every
    check (build_mesh raises on a folded element) and its area is the facets' within 0.5%."""
    stl = cylinder_stl(tmp_path / "coarse.stl", 1.0, 3.0, around=32, along=8)
    _, mesh = build(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = {1.0 / divisor}')
    facets = 0.5 * np.linalg.norm(facet_normals(*read_triangles(stl)), axis=1).sum()
    assert mid_surface_area(mesh) == pytest.approx(facets, rel=0.005)
    assert not len(bad_elements(mesh.x, mesh.conn))


def test_the_shipped_carotid_meshes_at_a_tenth_of_its_radius():
    """The shipped carotid (radius about 4 mm, its scene's 0.6 mm wall) at 0.4 mm, where
    one gmsh mesh at the size had elements with three corners on an open end: the mesh
    passes every check."""
    stl = ROOT / "decks" / "tissue" / "carotid_segment.stl"
    text = DECK.format(path=stl.as_posix()).replace("element_size = 6.0e-5", "element_size = 0.0004")
    mesh = build_mesh(parse_deck(text))
    assert mesh.n_elements > 5000 and not len(bad_elements(mesh.x, mesh.conn))


def test_a_size_in_the_wrong_units_is_refused_before_meshing_with_a_size_to_use(tmp_path):
    """A cylinder in metres (R = 1, L = 3) with element_size = 1e-5 (a size meant in other
    units) would be about 2.45e11 elements: refused at once, naming the key, the file, the
    estimate and a size that gives 10,000 elements; 3000 (mm meant) is larger than the
    whole surface, and refused so."""
    stl = cylinder_stl(tmp_path / "cylinder.stl", 1.0, 3.0, around=32, along=8)
    with pytest.raises(MeshError, match=r"geometry.element_size = 1e-05 would remesh surface file '.*cylinder.stl' "
                                        r"\(area 18.8., 3 across\) into about 2.4.e\+11 elements, more than 1,000,000: "
                                        r"is the size in the surface's units\? About 0.049. gives 10,000"):
        build(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = 1e-5')
    with pytest.raises(MeshError, match=r"geometry.element_size = 3000 is larger than surface file '.*cylinder.stl' "
                                        r"\(3 across\): is the size in the surface's units\?"):
        build(f'builder = "file"\npath = "{stl.as_posix()}"\nelement_size = 3000.0')


@pytest.mark.parametrize(("stop", "code", "word"), [(signal.SIGINT, 130, "interrupted"),
                                                     (signal.SIGTERM, 143, "terminated")])
def test_a_stop_ends_gmsh_meshing_at_once(tmp_path, stop, code, word, ctrl_c_delivered):
    """`shellsim mesh` of the carotid at 0.06 mm (about 400,000 elements: minutes of gmsh)
    stopped by Ctrl-C or SIGTERM a second after it says it is meshing: it exits with 130
    or 143 and says so, within a minute (gmsh ran on, deaf to both, until it was done)."""
    deck = tmp_path / "fine.toml"
    deck.write_text(DECK.format(path=(ROOT / "decks" / "tissue" / "carotid_segment.stl").as_posix()))
    process = subprocess.Popen([sys.executable, "-m", "shellsim", "mesh", str(deck), "--out", str(tmp_path / "out")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=os.environ | {"COLUMNS": "200"}, preexec_fn=ctrl_c_delivered)
    said = ""
    while "meshing" not in said and select.select([process.stderr], [], [], 120.0)[0]:
        said = process.stderr.readline()
        assert said, "the command ended before it said it was meshing"
    time.sleep(1.0)
    process.send_signal(stop)
    try:
        _, stderr = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        pytest.fail("the meshing went on for a minute after the stop")
    assert process.returncode == code and word in stderr


def _children(pid: int) -> list[int]:
    """The processes ``pid`` started that are still its children (Linux's /proc)."""
    return [int(c) for c in (Path("/proc") / str(pid) / "task" / str(pid) / "children").read_text().split()]


def _gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (gone, or a zombie nobody has reaped yet)."""
    try:
        return (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0] in "ZX"
    except (FileNotFoundError, ProcessLookupError):
        return True


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="reads processes from Linux's /proc")
def test_a_killed_shellsim_takes_its_gmsh_child_with_it(tmp_path):
    """`shellsim mesh` of the carotid at 0.06 mm killed outright (SIGKILL, which it cannot
    handle) while gmsh meshes in its child: the child is killed with it, not left meshing
    on for minutes holding a core, its memory and its caller's pipes."""
    deck = tmp_path / "fine.toml"
    deck.write_text(DECK.format(path=(ROOT / "decks" / "tissue" / "carotid_segment.stl").as_posix()))
    process = subprocess.Popen([sys.executable, "-m", "shellsim", "mesh", str(deck), "--out", str(tmp_path / "out")],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               env=os.environ | {"COLUMNS": "200"})
    said, children = "", []
    while "meshing" not in said and select.select([process.stderr], [], [], 120.0)[0]:
        said = process.stderr.readline()
        assert said, "the command ended before it said it was meshing"
    for _ in range(600):  # the child is forked just after the line
        children = _children(process.pid)
        if children:
            break
        time.sleep(0.1)
    assert children, "no meshing child was started"
    process.kill()
    process.wait()
    for _ in range(600):
        if all(map(_gone, children)):
            break
        time.sleep(0.1)
    survivors = [pid for pid in children if not _gone(pid)]
    for pid in survivors:
        os.kill(pid, signal.SIGKILL)
    assert not survivors, "the meshing child ran on after its parent was killed"
