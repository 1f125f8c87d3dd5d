"""The syntax of an Abaqus input file: keyword lines with their parameters and data lines,
comments dropped, ``*INCLUDE`` files read in place, each keyword remembering where it was
written (for messages that name the line)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import MeshError

#: Keywords whose data lines continue onto the next line when they end with a comma.
CONTINUED = {"element"}


@dataclass
class Keyword:
    """One keyword and its data.

    name : the keyword, lower case with single spaces ('shell section').
    params : parameter (lower case) -> value as written ('' for a flag).
    rows : the data lines, each a list of stripped fields.
    where : 'file:line' of the keyword line.
    row_lines : the line number of each data row.
    """

    name: str
    params: dict[str, str]
    where: str
    rows: list[list[str]] = field(default_factory=list)
    row_lines: list[int] = field(default_factory=list)

    def param(self, key: str, default: str | None = None) -> str | None:
        return self.params.get(key, default)

    def label(self) -> str:
        """The keyword as a message names it: '*SHELL SECTION (model.inp:12)'."""
        return f"*{self.name.upper()} ({self.where})"

    def at(self, line: int) -> str:
        """One of its data lines as a message names it: '*NODE (model.inp:14)'."""
        return f"*{self.name.upper()} ({self.where.rsplit(':', 1)[0]}:{line})"


def read_keywords(path: Path) -> list[Keyword]:
    """Every keyword of the input file ``path`` in order, ``*INCLUDE`` files spliced in.

    Raises MeshError for a file that cannot be read or holds data before its first
    keyword, and for an included file outside ``path``'s folder (links followed): a model
    from someone else must not read the user's other files, nor quote them in a message.
    """
    path = Path(path)
    return _read(path, seen=(), root=path.parent.resolve())


def _read(path: Path, seen: tuple[Path, ...], root: Path) -> list[Keyword]:
    from . import check_model_file

    check_model_file(path)
    resolved = path.resolve()
    if resolved in seen:
        raise MeshError(f"input file '{path}' includes itself (through {' -> '.join(str(p) for p in seen)})")
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        raise MeshError(f"input file '{path}' cannot be read: {error.strerror or error}") from None
    keywords: list[Keyword] = []
    pending = ""  # a data line ending with a comma that continues
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            pending = ""
            keyword = _keyword(line, f"{path.name}:{number}")
            if keyword.name == "include":
                included = keyword.param("input")
                if not included:
                    raise MeshError(f"{keyword.label()}: INPUT= names no file")
                target = path.parent / included.strip('"')
                if not target.resolve().is_relative_to(root):
                    raise MeshError(f"{keyword.label()}: the included file '{included}' lies outside the model's "
                                    f"folder '{root}'; shellsim reads included files only there (copy it in)")
                try:
                    keywords.extend(_read(target, seen + (resolved,), root))
                except MeshError as error:
                    raise MeshError(f"{keyword.label()}: {error}") from None
            else:
                keywords.append(keyword)
            continue
        if not keywords:
            raise MeshError(f"input file '{path}', line {number}: data before the first keyword (is it an input "
                            "file?)")
        current = keywords[-1]
        if pending:
            line, pending = pending + line, ""
            current.rows.pop()
            number = current.row_lines.pop()
        if current.name in CONTINUED and line.endswith(","):
            pending = line
        fields = [f.strip() for f in line.split(",")]
        while fields and fields[-1] == "":  # a trailing comma ends many generated lines
            fields.pop()
        current.rows.append(fields)
        current.row_lines.append(number)
    return keywords


def _keyword(line: str, where: str) -> Keyword:
    """A keyword line ('*Shell Section, elset=A, material=M') as a Keyword without data."""
    parts = [p.strip() for p in line[1:].split(",")]
    name = " ".join(parts[0].lower().split())
    params = {}
    for part in parts[1:]:
        if not part:
            continue
        key, _, value = part.partition("=")
        params[" ".join(key.lower().split())] = value.strip().strip('"')  # a name with spaces is quoted
    return Keyword(name, params, where)
