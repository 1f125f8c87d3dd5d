"""Mesh files with defects end in exit code 2 and a message naming each defect, with ids
and places, never a traceback: written alone, combined, in .vtu and .msh, and as truncated
or garbage files."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from shellsim.cli import app
from shellsim.errors import MeshError
from shellsim.geometry import build_mesh
from shellsim.geometry.importing import read_mesh

from .conftest import BASE

runner = CliRunner()
N_ELEMENTS = 4

#: defect -> (the stage at which it is found, a pattern of its message). Defects of one stage are
#: all named together; a later stage is only reached when the earlier ones are clean.
DEFECTS = {
    # meshio's .msh reader finds this one itself: "index 43 is out of bounds"
    "node outside the file": (0, "name nodes the file does not have|out of bounds"),
    "repeated node": (1, "repeat a node"),
    "NaN coordinate": (1, "coordinate that is not a finite number"),
    "NaN thickness": (1, "'thickness' that is not a finite number"),
    "zero thickness": (1, "'thickness' that is not positive"),
    "NaN director": (1, "'director' that is not a finite vector"),
    "long director": (1, "'director' that is not a unit vector"),
    "zero area": (2, "zero area"),
    "inverted element": (3, "non-positive Jacobian"),
}


def separate_elements() -> tuple[np.ndarray, np.ndarray]:
    """Four unit-square quad9 elements side by side, each with its own 9 nodes, so a defect
    put on one element touches no other: points (36, 3), conn (4, 9)."""
    corner_rs = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0], [1, 0.5], [0.5, 1], [0, 0.5], [0.5, 0.5]])
    points = np.concatenate([np.column_stack([corner_rs[:, 0] + 2 * e, corner_rs[:, 1], np.zeros(9)])
                             for e in range(N_ELEMENTS)])
    return points, np.arange(9 * N_ELEMENTS).reshape(N_ELEMENTS, 9)


def write_mesh(path, defects: list[str]) -> None:
    """The four-element file with ``defects``, each on an element or node of its own."""
    import meshio

    points, conn = separate_elements()
    thickness = np.full(len(points), 0.01)
    director = np.tile([0.0, 0.0, 1.0], (len(points), 1))
    for defect in defects:
        if defect == "node outside the file":
            conn[0, 3] = len(points) + 7
        elif defect == "repeated node":
            conn[0, 5] = conn[0, 1]
        elif defect == "NaN coordinate":
            points[conn[1, 2], 1] = np.nan
        elif defect == "NaN thickness":
            thickness[conn[1, 4]] = np.nan
        elif defect == "zero thickness":
            thickness[conn[1, 6]] = 0.0
        elif defect == "NaN director":
            director[conn[1, 7]] = np.nan
        elif defect == "long director":
            director[conn[1, 8]] *= 1.5
        elif defect == "zero area":
            points[conn[2]] = points[conn[2, 0]]
        elif defect == "inverted element":
            points[conn[3, 8], 0] -= 3.0  # the centre node far outside its element
    file_format = "gmsh22" if path.suffix == ".msh" else None  # .msh is also ANSYS' suffix
    meshio.write(path, meshio.Mesh(points, [("quad9", conn)], point_data={"thickness": thickness, "director": director}),
                 file_format=file_format)


def deck_for(tmp_path, mesh_name: str):
    deck = tmp_path / "scene.toml"
    deck.write_text(BASE + f'[geometry]\nbuilder = "file"\npath = "{mesh_name}"\n')
    return deck


def check(deck):
    result = runner.invoke(app, ["check", str(deck)])
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output
    return result


def test_the_clean_file_is_accepted(tmp_path):
    """The control: without defects the same file builds, so every refusal below is the defect's."""
    from shellsim.deck import load_deck

    write_mesh(tmp_path / "m.vtu", [])
    mesh = build_mesh(load_deck(deck_for(tmp_path, "m.vtu")), tmp_path)
    assert mesh.n_elements == N_ELEMENTS and np.allclose(mesh.director, [0, 0, 1])


@pytest.mark.parametrize("defect", list(DEFECTS))
def test_each_defect_is_named_with_its_element_or_node(tmp_path, defect):
    write_mesh(tmp_path / "m.vtu", [defect])
    result = check(deck_for(tmp_path, "m.vtu"))
    assert result.exit_code == 2, result.output
    assert re.search(DEFECTS[defect][1], result.output) and "m.vtu" in result.output
    named = {"repeated node": "elements 1;", "NaN coordinate": "nodes 12", "zero thickness": "nodes 16",
             "long director": "nodes 18", "zero area": "elements 3", "inverted element": "elements 4;"}
    if defect in named:
        assert named[defect] in result.output, result.output


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(defects=st.sets(st.sampled_from(list(DEFECTS)), min_size=1), suffix=st.sampled_from(["vtu", "msh"]))
def test_any_combination_of_defects_names_those_found_first(tmp_path, defects, suffix):
    write_mesh(tmp_path / f"m.{suffix}", sorted(defects))
    result = check(deck_for(tmp_path, f"m.{suffix}"))
    assert result.exit_code == 2, result.output
    first = min(DEFECTS[d][0] for d in defects)
    for defect in defects:
        if DEFECTS[defect][0] == first:
            assert re.search(DEFECTS[defect][1], result.output), (defect, result.output)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(suffix=st.sampled_from(["vtu", "msh"]), kept=st.floats(0.02, 0.98),
       garbage=st.binary(min_size=0, max_size=200))
def test_truncated_or_garbage_files_are_refused_with_a_message(tmp_path, suffix, kept, garbage):
    write_mesh(tmp_path / f"whole.{suffix}", [])
    whole = (tmp_path / f"whole.{suffix}").read_bytes()
    cut = whole[: int(kept * len(whole))]
    assume(garbage or not ends_a_whole_file(cut, whole))
    (tmp_path / f"m.{suffix}").write_bytes(cut + garbage)
    result = check(deck_for(tmp_path, f"m.{suffix}"))
    assert result.exit_code == 2, result.output
    assert f"mesh file '{tmp_path / ('m.' + suffix)}'" in result.output.replace("\n", "")


def ends_a_whole_file(cut: bytes, whole: bytes) -> bool:
    """Whether ``cut``, the start of ``whole``, is itself a complete mesh file: it stops just
    after a gmsh section (e.g. before the optional node data) or only a line end is missing."""
    return re.search(rb"\n\$End\w+\n?$", cut) is not None or cut.rstrip() == whole.rstrip()


@pytest.mark.parametrize("suffix", ["msh", "vtu"])
def test_every_cut_of_a_mesh_file_is_refused_unless_it_is_complete(tmp_path, suffix):
    """meshio reads on past a gmsh section cut short with only a warning; each of the file's
    byte positions is tried."""
    write_mesh(tmp_path / f"whole.{suffix}", [])
    whole = (tmp_path / f"whole.{suffix}").read_bytes()
    accepted = []
    for end in range(1, len(whole)):
        (tmp_path / f"m.{suffix}").write_bytes(whole[:end])
        try:
            read_mesh(tmp_path / f"m.{suffix}")
            accepted.append(end)
        except MeshError as err:
            assert f"mesh file '{tmp_path / ('m.' + suffix)}'" in str(err)
    assert all(ends_a_whole_file(whole[:end], whole) for end in accepted), accepted


def test_a_triangle_mesh_is_refused_with_how_to_make_quad9(tmp_path):
    import meshio

    points, conn = separate_elements()
    meshio.write(tmp_path / "m.vtu", meshio.Mesh(points, [("quad9", conn), ("triangle", conn[:1, :3])]))
    result = check(deck_for(tmp_path, "m.vtu"))
    assert result.exit_code == 2
    assert "elements other than quad9 (triangle)" in result.output and "Mesh.RecombineAll" in result.output
