"""Pydantic validation errors turned into one line per problem a user can act on:
``key.path (line N): got VALUE; expected ...``, with did-you-mean for unknown keys and
unknown model/builder/type names."""

from __future__ import annotations

import re
import types
import typing
from typing import Any

from pydantic import BaseModel, ValidationError

from .references import did_you_mean
from ..table_types import tag_of

#: Keys users bring from other codes, with why shellsim does not take them.
HINTS = {
    "k": "incompressibility is imposed exactly (thesis Technique 1); no bulk modulus is needed",
    "bulk_modulus": "incompressibility is imposed exactly (thesis Technique 1); no bulk modulus is needed",
    "nu": "incompressible models take no Poisson ratio",
    "dt": "the time step is computed from the critical step; set solver.dt_safety_factor",
}

_MISSING = object()


def format_errors(error: ValidationError, data: dict, text: str, root: type[BaseModel]) -> list[str]:
    """One message per error in ``error``.

    Parameters
    ----------
    error : the exception from validating ``data`` against ``root``.
    data : the parsed TOML (to show the value given and to drop union tags from paths).
    text : the TOML source (to give line numbers).
    root : the model validated (to list the keys a table accepts).
    """
    messages = []
    for item in error.errors(include_url=False):
        keys = _data_path(data, item["loc"])
        path = _dotted(keys)
        kind, ctx = item["type"], item.get("ctx", {})
        where = _where(path, _line_of(text, keys))
        if kind == "extra_forbidden":
            key = str(keys[-1])
            allowed = _allowed_keys(root, data, keys[:-1])
            hint = HINTS.get(key, "")
            suggestion = did_you_mean(key, allowed) if not hint else f" ({hint})"
            listing = f"; keys here: {', '.join(allowed)}" if allowed and not hint else ""
            messages.append(f"{where}: unknown key '{key}'{suggestion}{listing}")
        elif kind in ("union_tag_invalid", "union_tag_not_found"):
            tag_key = ctx.get("discriminator", "").strip("'")
            expected = [t.strip(" '") for t in str(ctx.get("expected_tags", "")).split(",")]
            tag_path = _where(_dotted(keys + [tag_key]), _line_of(text, keys + [tag_key]))
            if kind == "union_tag_not_found":
                messages.append(f"{tag_path}: missing; expected one of {', '.join(expected)}")
            else:
                tag = str(ctx.get("tag"))
                messages.append(
                    f"{tag_path}: got '{tag}'{did_you_mean(tag, expected)}; "
                    f"expected one of {', '.join(expected)}"
                )
        elif kind == "missing":
            messages.append(f"{where}: missing required value")
        elif kind == "value_error":
            value = _value_at(data, keys)
            text_ = _value_error_text(item["msg"])
            if not path:
                messages.extend(text_.splitlines())
            elif isinstance(value, (dict, list)) or value is _MISSING:
                messages.append(f"{where}: {text_}")
            else:
                messages.append(f"{where}: got {_show(value)}: {text_}")
        else:
            value = _value_at(data, keys)
            got = "" if value is _MISSING else f"got {_show(value)}; "
            messages.append(f"{where}: {got}expected {_expectation(item)}")
    return messages


def _value_error_text(msg: str) -> str:
    return msg.removeprefix("Value error, ").removeprefix("Assertion failed, ")


def _expectation(item: dict) -> str:
    """pydantic's 'Input should be ...' as 'expected ...'."""
    msg = _value_error_text(item["msg"])
    msg = re.sub(r"^Input should be ", "", msg)
    msg = re.sub(r"^Value should have ", "", msg)
    return msg[0].lower() + msg[1:] if msg else msg


def _data_path(data: Any, loc: tuple) -> list:
    """``loc`` without the union tags and validator names pydantic inserts: keep only the
    steps that exist in the data (and the last step, which may be a missing key)."""
    path, node = [], data
    for i, step in enumerate(loc):
        if isinstance(node, dict) and step in node:
            path.append(step)
            node = node[step]
        elif isinstance(node, list) and isinstance(step, int) and step < len(node):
            path.append(step)
            node = node[step]
        elif i == len(loc) - 1 and isinstance(step, str) and isinstance(node, dict):
            path.append(step)  # a missing key
    return path


def _dotted(keys: list) -> str:
    out = ""
    for k in keys:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else str(k))
    return out


def _where(path: str, line: int | None) -> str:
    path = path or "deck"
    return f"{path} (line {line})" if line else path


def _value_at(data: Any, keys: list) -> Any:
    node = data
    for k in keys:
        try:
            node = node[k]
        except (KeyError, IndexError, TypeError):
            return _MISSING
    return node


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _allowed_keys(root: type[BaseModel], data: Any, keys: list) -> list[str]:
    """Field names of the model that validates the table at ``keys``."""
    model: Any = root
    node = data
    for k in keys:
        if isinstance(k, int):  # an entry of a list of tables: the list's member model
            node = node[k]
            listed = typing.get_args(model) if typing.get_origin(model) is list else (None,)
            model = _pick_member(listed[0], node)
            continue
        model = _field_model(model, k, node)
        node = node.get(k) if isinstance(node, dict) else None
        model = _pick_member(model, node)
        if model is None:
            return []
    return list(model.model_fields) if isinstance(model, type) and issubclass(model, BaseModel) else []


def _field_model(model: Any, key: str, node: Any) -> Any:
    if not (isinstance(model, type) and issubclass(model, BaseModel)) or key not in model.model_fields:
        return None
    return model.model_fields[key].annotation


def _pick_member(annotation: Any, node: Any) -> Any:
    """The model class a value is validated by: unwraps Optional, list, dict, Annotated and
    discriminated unions (by the tag found in ``node``)."""
    while True:
        origin = typing.get_origin(annotation)
        args = typing.get_args(annotation)
        if origin is typing.Annotated:
            annotation = args[0]
        elif origin is list and isinstance(node, dict):
            annotation = args[0]  # one table where a list of them is taken ([reference], [material])
        elif origin in (list, dict):
            return annotation  # the next key is an index or a name; resolved on the next step
        elif origin in (typing.Union, types.UnionType):
            members = [a for a in args if a is not type(None)]
            if isinstance(node, dict):
                for m in members:
                    tag = tag_of(m) if isinstance(m, type) and issubclass(m, BaseModel) else None
                    if tag and node.get(tag[0]) == tag[1]:
                        return m
            models = [m for m in members if isinstance(m, type) and issubclass(m, BaseModel)]
            return models[0] if len(models) == 1 else None
        else:
            return annotation


def _line_of(text: str, keys: list) -> int | None:
    """1-based line in the TOML source where ``keys`` (or its longest present prefix) is set."""
    target = tuple(keys)
    best, best_len = None, 0
    table: tuple = ()
    array_counts: dict[tuple, int] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        header = re.match(r"^\[\[\s*([^\]]+?)\s*\]\]$", line) or re.match(r"^\[\s*([^\]]+?)\s*\]$", line)
        if header:
            parts = tuple(p.strip().strip('"') for p in header.group(1).split("."))
            if line.startswith("[["):
                index = array_counts.get(parts, 0)
                array_counts[parts] = index + 1
                table = parts + (index,)
            else:
                table = parts
            candidate = table
        else:
            key = re.match(r"^([A-Za-z0-9_\-\.\"]+)\s*=", line)
            if not key:
                continue
            candidate = table + tuple(p.strip().strip('"') for p in key.group(1).split("."))
        n = _common_prefix(candidate, target)
        if n == len(candidate) and n > best_len:
            best, best_len = number, n
    return best


def _common_prefix(a: tuple, b: tuple) -> int:
    n = 0
    for x, y in zip(a, b):
        if x != y:
            break
        n += 1
    return n
