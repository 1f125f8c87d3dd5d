"""Property tests of the inputs users bring from other tools: waveform CSV files in every
dialect spreadsheets write read back to their numbers, any other file refused with a
ValueError naming it; triangulated surfaces as segmentation leaves them (repeated and
collapsed facets, merged points, fins) cleaned into what gmsh can take or refused with a
MeshError, and remeshed or refused the same way."""

from __future__ import annotations


import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shellsim.deck.curves import read_table
from shellsim.errors import MeshError
from shellsim.geometry.surfaces import clean_facets, remesh
from shellsim.verify.surfaces import tube_facets, write_facets

#: Ordered, distinct times and finite values, as a waveform table holds them.
TABLES = st.lists(st.tuples(st.floats(-1e6, 1e6, allow_nan=False), st.floats(-1e6, 1e6, allow_nan=False)),
                  min_size=1, max_size=30).map(lambda rows: sorted({round(t, 6): round(v, 6) for t, v in rows}.items()))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(table=TABLES, separator=st.sampled_from([";", "\t", ",", " ", "  "]), decimal_comma=st.booleans(),
       mark=st.booleans(), header=st.booleans(), comment=st.booleans(), crlf=st.booleans())
def test_a_waveform_in_any_spreadsheet_dialect_reads_back_its_numbers(tmp_path, table, separator, decimal_comma,
                                                                      mark, header, comment, crlf):
    """Times and values written with ';', tabs, ',' or spaces between them, decimal
    commas where the separator is not a comma, a byte-order mark (Excel's CSV UTF-8), a
    header, comments and Windows line ends: read back to the same numbers."""
    decimal_comma = decimal_comma and separator.strip() in (";", "\t")

    def number(x: float) -> str:
        text = repr(float(x))
        return text.replace(".", ",") if decimal_comma else text

    lines = (["time;value" if separator == ";" else "time value"] if header else [])
    lines += [f"{number(t)}{separator}{number(v)}" + ("  # sample" if comment else "") for t, v in table]
    path = tmp_path / "wave.csv"
    path.write_bytes(("\ufeff" if mark else "").encode() + ("\r\n" if crlf else "\n").join(lines).encode())
    t, value = read_table(path)
    np.testing.assert_array_equal(t, [row[0] for row in table])
    np.testing.assert_array_equal(value, [row[1] for row in table])


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(content=st.one_of(st.binary(max_size=300), st.text(max_size=300).map(str.encode)))
def test_any_other_file_is_read_or_refused_with_a_value_error_naming_it(tmp_path, content):
    """Random bytes and text as a waveform: a table of increasing finite times, or a
    ValueError naming the file; never another exception."""
    path = tmp_path / "random.csv"
    path.write_bytes(content)
    try:
        t, value = read_table(path)
    except ValueError as error:
        assert str(path) in str(error)
    else:
        assert len(t) == len(value) >= 1 and np.all(np.diff(t) > 0) and np.all(np.isfinite(t + value))


#: What segmentation leaves in a surface: (kind, which facet or point, the other).
DEFECTS = st.lists(st.tuples(st.sampled_from(["repeat", "corner twice", "to a point", "fin", "merge"]),
                             st.integers(0, 127), st.integers(0, 79)), max_size=6)


def _damaged(defects) -> tuple[np.ndarray, np.ndarray, bool]:
    """The cylinder with ``defects``; whether a fin (an edge of three facets) is among them."""
    points, triangles = tube_facets(1.0, 1.0, 2.0, 16, 4)
    extra, finned = [], False
    for kind, facet, point in defects:
        a, b, c = triangles[facet]
        if kind == "repeat":
            extra.append([a, b, c])
        elif kind == "corner twice":
            extra.append([a, a, b])
        elif kind == "to a point":
            extra.append([point, point, point])
        elif kind == "fin":  # a third facet on the edge a-b, to a point off the surface
            points = np.vstack([points, points[a] * 1.5])
            extra.append([a, b, len(points) - 1])
            finned = True
        else:  # a point moved onto another: facets collapse or repeat
            points = points.copy()
            points[point] = points[(point + 1) % len(points)]
    return points, np.vstack([triangles, *(np.array([row]) for row in extra)]), finned


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(defects=DEFECTS)
def test_segmentation_defects_are_cleaned_or_a_non_manifold_edge_is_named(tmp_path, defects):
    """Written to STL and read back (coincident points merged): repeated, collapsed and
    point facets are dropped; what is left has three distinct corners per facet, no facet
    twice and no edge on more than two facets. A fin is refused with a MeshError naming
    where."""
    from shellsim.mesh_reading import read_triangles

    path = write_facets(tmp_path / "damaged.stl", *_damaged(defects)[:2])
    points, triangles = read_triangles(path)
    finned = _damaged(defects)[2]
    try:
        cleaned = clean_facets(points, triangles, path)
    except MeshError as error:
        assert finned and "shared by more than two facets, e.g. near (" in str(error)
        return
    assert np.all((cleaned[:, 0] != cleaned[:, 1]) & (cleaned[:, 1] != cleaned[:, 2]) & (cleaned[:, 0] != cleaned[:, 2]))
    assert len(np.unique(np.sort(cleaned, axis=1), axis=0)) == len(cleaned)
    edges = np.sort(cleaned[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)
    assert np.unique(edges, axis=0, return_counts=True)[1].max() <= 2


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(defects=DEFECTS, size=st.sampled_from([0.25, 0.4, 0.6]))
def test_a_damaged_surface_is_remeshed_or_refused_with_a_mesh_error(tmp_path, defects, size):
    """The damaged cylinder through the whole remesher (gmsh in its child process): quad9
    elements, or a MeshError naming the file; never a traceback or a hang."""
    path = write_facets(tmp_path / "damaged.stl", *_damaged(defects)[:2])
    try:
        x, conn = remesh(path, size)
    except MeshError as error:
        assert str(path) in str(error)
    else:
        assert conn.shape[1] == 9 and np.all(np.isfinite(x))
