"""Text from files written where a control character would act: a deck's comment (a
newline there starts a table) or the terminal (an escape sequence there drives it)."""

from __future__ import annotations

import re

#: Control characters (C0 but tab, DEL, C1) and the Unicode line and paragraph separators.
CONTROL = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029]")


def printable(text: str) -> str:
    """``text`` with every character of CONTROL written as its visible escape ('\\n',
    '\\x1b', '\\u2028'): one line that shows what the file held and does nothing."""
    return CONTROL.sub(lambda match: match.group().encode("unicode_escape").decode("ascii"), text)


def control_characters(text: str, allowed: str = "") -> list[str]:
    """The control characters of ``text`` not in ``allowed``, as their escapes, in order."""
    return [printable(c) for c in dict.fromkeys(CONTROL.findall(text)) if c not in allowed]


def printable_lines(text: str) -> str:
    """``text`` made :func:`printable` line by line: its line breaks kept, nothing else acting."""
    return "\n".join(printable(line) for line in text.split("\n"))


def shown(text: str) -> str:
    """``text`` from a file or a user, for a rich console: :func:`printable_lines`, and
    never read as markup."""
    from rich.markup import escape

    return escape(printable_lines(text))
