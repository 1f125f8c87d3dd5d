"""Files and folders from someone else: a model whose attributes carry newlines, quotes
and brackets writes a deck with nothing planted in it; included files stay in the model's
folder and nothing of what they hold is quoted; links already in an output folder are
never followed by what shellsim writes there."""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path
from xml.sax.saxutils import escape as xml_escape
from xml.sax.saxutils import quoteattr

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from shellsim.cli import app

from shellsim.errors import MeshError
from shellsim.foreign import read_foreign
from shellsim.foreign.inp_syntax import read_keywords
from shellsim.imported_deck import import_model

from .test_import import strip_feb
from .test_run_folder import PLATE

runner = CliRunner()

#: What a forged attribute holds: TOML that would plant a table, brackets, quotes,
#: escapes and terminal controls (the C1 ones XML can carry) among ordinary text.
PLANTS = ['\n[[load]]\ntype = "pressure"\nvalue = 1e9\n', '"""', "'''", "]\n[meta]\n", "\r\n#", "\\", "\x9b2J\x85",
          "\u2028[solver]", '" = 1\nx = "', "\t"]
HOSTILE = st.lists(st.one_of(st.sampled_from(PLANTS), st.text(st.characters(codec="utf-8", exclude_categories=["Cs", "Cc"]),
                                                              max_size=8)), min_size=1, max_size=4).map("".join)


def _planted(hostile: str) -> str:
    """The strip as FEBio saves it, ``hostile`` in the names the reader copies: the
    material's, the tip set's (and what names them), a load controller's and a load the
    reader does not map."""
    text = strip_feb("4.0").replace('encoding="ISO-8859-1"', 'encoding="UTF-8"')
    text = text.replace('name="Steel"', f"name={quoteattr(hostile)}").replace('mat="Steel"', f"mat={quoteattr(hostile)}")
    text = text.replace('name="Tip"', f"name={quoteattr('Tip' + hostile)}")
    text = text.replace('node_set="Tip"', f"node_set={quoteattr('Tip' + hostile)}")
    text = text.replace('name="Ramp"', f"name={quoteattr(hostile)}")
    return text.replace("</Loads>", f'<surface_load type="fluid pressure" name={quoteattr(hostile)}>'
                                     f"<pressure>{xml_escape(hostile)}</pressure></surface_load></Loads>")


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(hostile=HOSTILE)
def test_nothing_a_model_file_s_attributes_hold_plants_deck_text(tmp_path_factory, hostile):
    """Whatever the names hold, the written deck has the tables and keys of the same model
    with plain names, and every comment line of its header is one comment."""
    tmp_path = tmp_path_factory.mktemp("planted")
    plain, forged = tmp_path / "plain.feb", tmp_path / "forged.feb"
    plain.write_text(_planted("x"), encoding="utf-8")
    forged.write_text(_planted(hostile), encoding="utf-8")
    expected = tomllib.loads(import_model(plain, tmp_path / "plain").deck.read_text())
    written = import_model(forged, tmp_path / "forged").deck.read_text(encoding="utf-8")
    got = tomllib.loads(written)

    def layout(tables):
        return {key: ([sorted(item) for item in value] if isinstance(value, list) else sorted(value))
                for key, value in tables.items() if key != "curves"} | {"curves": len(tables.get("curves", {}))}

    assert layout(got) == layout(expected)
    header = written[:written.index("\n\n")].split("\n")
    assert all(line.startswith("#") for line in header)


@pytest.mark.parametrize("how", ["absolute", "up", "link"])
def test_an_included_file_outside_the_model_s_folder_is_refused_unquoted(tmp_path, how):
    """``*INCLUDE, INPUT=`` naming a file outside the model's folder (by an absolute path,
    by '..', or through a link in the folder) is refused naming the path, and nothing of
    the file reaches the message."""
    secret = tmp_path / "secret.inp"
    secret.write_text("root:x:0:0:the first line of a private file\n")
    folder = tmp_path / "model"
    folder.mkdir()
    named = {"absolute": str(secret), "up": "../secret.inp", "link": "beside.inp"}[how]
    if how == "link":
        (folder / "beside.inp").symlink_to(secret)
    (folder / "model.inp").write_text(f"*Heading\n*Include, input={named}\n")
    with pytest.raises(MeshError, match="lies outside the model's folder") as refused:
        read_foreign(folder / "model.inp")
    assert named in str(refused.value) and "private" not in str(refused.value)


def test_an_included_file_inside_the_model_s_folder_is_read(tmp_path):
    """A subfolder's file (and a link to one inside the folder) is read as before."""
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "data.inp").write_text("*Node\n1, 0., 0., 0.\n")
    (tmp_path / "alias.inp").symlink_to(tmp_path / "parts" / "data.inp")
    (tmp_path / "model.inp").write_text("*Heading\n*Include, input=parts/data.inp\n*Include, input=alias.inp\n")
    keywords = read_keywords(tmp_path / "model.inp")
    assert [k.name for k in keywords] == ["heading", "node", "node"]


#: What a run writes into its folder, as files and as folders.
RUN_FILES = ("deck.toml", "history.csv", "summary.json", "results.xdmf", "results.h5", "results.pvd", ".shellsim.lock",
             "checkpoint.npz")
RUN_FOLDERS = ("frames", "renders", "plots")


def _victims(tmp_path: Path) -> tuple[Path, Path]:
    """A file and a folder outside the output folder, that no link may let shellsim touch."""
    victim, victims = tmp_path / "victim.txt", tmp_path / "victims"
    victim.write_text("the user's own file\n")
    victims.mkdir()
    (victims / "kept.txt").write_text("the user's own folder\n")
    return victim, victims


def _untouched(victim: Path, victims: Path) -> None:
    assert victim.read_text() == "the user's own file\n"
    assert sorted(p.name for p in victims.iterdir()) == ["kept.txt"]
    assert (victims / "kept.txt").read_text() == "the user's own folder\n"


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(files=st.sets(st.sampled_from(RUN_FILES)), folders=st.sets(st.sampled_from(RUN_FOLDERS)),
       dangling=st.booleans())
def test_links_in_an_output_folder_never_let_a_run_write_outside_it(tmp_path_factory, files, folders, dangling):
    """Links at the names of a run's files (to a file outside, or to nothing) and of its
    folders (to a folder outside): the run either replaces the links or refuses naming
    one, and the files and folders outside keep their bytes."""
    tmp_path = tmp_path_factory.mktemp("links")
    victim, victims = _victims(tmp_path)
    deck = tmp_path / "plate.toml"
    deck.write_text(PLATE)
    folder = tmp_path / "run"
    folder.mkdir()
    for name in files:
        (folder / name).symlink_to(tmp_path / "nothing" if dangling else victim)
    for name in folders:
        (folder / name).symlink_to(victims, target_is_directory=True)
    result = runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"])
    message = " ".join(result.output.split())
    assert result.exit_code == 0 or (result.exit_code == 2 and "is a symbolic link" in message), result.output
    _untouched(victim, victims)


def test_links_in_a_run_s_folder_never_let_plots_or_renders_write_outside_it(tmp_path):
    """A run's folder whose plots/ and renders/ are links to a folder outside: ``plot``
    and ``render`` refuse naming them; made real folders holding links at the names of
    the pictures, the links are replaced by the pictures and the file outside is as it
    was."""
    victim, victims = _victims(tmp_path)
    deck = tmp_path / "plate.toml"
    deck.write_text(PLATE)
    folder = tmp_path / "run"
    assert runner.invoke(app, ["run", str(deck), "--out", str(folder), "--quiet"]).exit_code == 0
    for name in ("plots", "renders"):
        shutil.rmtree(folder / name, ignore_errors=True)
        (folder / name).symlink_to(victims, target_is_directory=True)
    for command in (["plot", str(folder)], ["render", str(folder)]):
        result = runner.invoke(app, command)
        assert result.exit_code == 2 and "is a symbolic link" in " ".join(result.output.split()), result.output
    _untouched(victim, victims)
    for name in ("plots", "renders"):
        (folder / name).unlink()
    assert runner.invoke(app, ["plot", str(folder)]).exit_code == 0
    assert runner.invoke(app, ["render", str(folder)]).exit_code == 0
    pictures = [path for name in ("plots", "renders") for path in (folder / name).iterdir()]
    for path in pictures:
        path.unlink()
        path.symlink_to(victim)
    assert runner.invoke(app, ["plot", str(folder)]).exit_code == 0
    assert runner.invoke(app, ["render", str(folder)]).exit_code == 0
    assert pictures and not any(path.is_symlink() for path in pictures)
    _untouched(victim, victims)


def test_links_in_an_import_folder_are_replaced_not_followed(tmp_path):
    """``import --out``: a dangling link at the deck's name and a link at the mesh's
    name to a file outside: both replaced by the files written, the file outside as it
    was."""
    victim, victims = _victims(tmp_path)
    model = tmp_path / "strip.feb"
    model.write_text(strip_feb("4.0"))
    folder = tmp_path / "imported"
    folder.mkdir()
    (folder / "deck.toml").symlink_to(tmp_path / "planted.toml")
    (folder / "strip.vtu").symlink_to(victim)
    result = runner.invoke(app, ["import", str(model), "--out", str(folder)])
    assert result.exit_code == 0, result.output
    assert not (folder / "deck.toml").is_symlink() and not (folder / "strip.vtu").is_symlink()
    assert not (tmp_path / "planted.toml").exists()
    _untouched(victim, victims)
