"""Declarative content files (worlds, exercises, quizzes): YAML read with line numbers.

A malformed file is a :class:`ContentError` that names the file, the line and the field,
so an instructor can go straight to the mistake.  Dataclasses describe each kind of file;
every field has a default and a ``doc`` in its metadata.

This is the one content layer of the project: world, exercise and quiz files all read
through it.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

import yaml

from content.i18n import _

T = TypeVar("T")


class ContentError(Exception):
    """A content file an instructor wrote is malformed: ``path:line: field: message``."""

    def __init__(self, path: Path | str, message: str, line: int | None = None,
                 field: str | None = None) -> None:
        self.path = Path(path)
        self.line = line
        self.field = field
        self.message = message
        super().__init__(str(self))

    def __str__(self) -> str:
        where = f"{self.path}:{self.line}" if self.line else f"{self.path}"
        if self.field:
            return f"{where}: {self.field}: {self.message}"
        return f"{where}: {self.message}"


class FieldValueError(ValueError):
    """A dataclass's own check (its ``__post_init__``) that one field broke: :func:`build`
    names that field's line, as it does for a wrong type."""

    def __init__(self, message: str, field: str) -> None:
        super().__init__(message)
        self.field = field


@dataclasses.dataclass(frozen=True)
class Document:
    """A parsed YAML file: plain Python data plus the line of every key and item."""

    path: Path
    data: Any
    lines: Mapping[tuple[str | int, ...], int]

    def line(self, *where: str | int) -> int | None:
        """Line (1-based) of the value at ``where``, or of its nearest parent."""
        key = tuple(where)
        while key:
            if key in self.lines:
                return self.lines[key]
            key = key[:-1]
        return self.lines.get((), 1)

    def error(self, message: str, *where: str | int) -> ContentError:
        return ContentError(self.path, message, self.line(*where), self.field(*where))

    def field(self, *where: str | int) -> str | None:
        """``where`` as an author reads it: an item of a list by its ``id`` where it has
        one (``questions[sim-time].answer``), by its index otherwise (``obstacles.2``).
        Indices shift when an item is added above; ids stay."""
        parts: list[str] = []
        node = self.data
        for step in where:
            item = node[step] if isinstance(step, int) and isinstance(node, list) \
                and 0 <= step < len(node) else None
            if isinstance(item, dict) and isinstance(item.get("id"), str) and parts:
                parts[-1] += f"[{item['id']}]"
            else:
                parts.append(str(step))
            node = item if item is not None else (
                node.get(step) if isinstance(node, dict) and isinstance(step, str) else None)
        return ".".join(parts) or None


def _to_python(node: yaml.Node, where: tuple[str | int, ...],
               lines: dict[tuple[str | int, ...], int], path: Path) -> Any:
    lines[where] = node.start_mark.line + 1
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            key = yaml.safe_load(yaml.serialize(key_node))
            if not isinstance(key, str):
                raise ContentError(path, _("keys must be text, found {key!r}").format(key=key),
                                   key_node.start_mark.line + 1)
            if key in out:
                raise ContentError(path, _("duplicate key {key!r}").format(key=key),
                                   key_node.start_mark.line + 1)
            out[key] = _to_python(value_node, (*where, key), lines, path)
            lines[(*where, key)] = key_node.start_mark.line + 1
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_to_python(item, (*where, i), lines, path) for i, item in enumerate(node.value)]
    return yaml.safe_load(yaml.serialize(node))


def load_document(path: Path | str, text: str | None = None) -> Document:
    """Read a YAML file; a syntax error becomes a ContentError with its line."""
    path = Path(path)
    try:
        source = path.read_text(encoding="utf-8") if text is None else text
    except FileNotFoundError:
        raise ContentError(path, _("file not found")) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ContentError(path, _("cannot read file: {error}").format(error=exc)) from None
    try:
        root = yaml.compose(source, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        raise ContentError(path, _("YAML error: {problem}").format(
            problem=exc.problem or exc.context), line) from None
    except yaml.YAMLError as exc:
        raise ContentError(path, _("YAML error: {problem}").format(problem=exc)) from None
    lines: dict[tuple[str | int, ...], int] = {}
    if root is None:
        raise ContentError(path, _("the file is empty"), 1)
    data = _to_python(root, (), lines, path)
    return Document(path, data, lines)


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", str(tp))


def _check_type(doc: Document, value: Any, tp: Any, where: tuple[str | int, ...]) -> Any:
    """Check ``value`` against a simple annotation; convert lists to tuples."""
    origin = typing.get_origin(tp)
    if tp is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        errors = []
        for arm in typing.get_args(tp):
            if arm is type(None) and value is None:
                return None
            try:
                return _check_type(doc, value, arm, where)
            except ContentError as exc:
                errors.append(exc)
        raise errors[0] if errors else doc.error(_("unexpected value"), *where)
    if origin is typing.Literal:
        allowed = typing.get_args(tp)
        if value not in allowed:
            raise doc.error(_("must be one of {allowed}, found {value!r}").format(
                allowed=", ".join(repr(a) for a in allowed), value=value), *where)
        return value
    if origin in (tuple, list):
        args = typing.get_args(tp)
        if not isinstance(value, list):
            raise doc.error(_("must be a list, found {value!r}").format(value=value), *where)
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(value) != len(args):
                raise doc.error(_("must have {count} items, found {found}").format(
                    count=len(args), found=len(value)), *where)
            return tuple(_check_type(doc, v, a, (*where, i))
                         for i, (v, a) in enumerate(zip(value, args, strict=True)))
        item = args[0] if args else Any
        return tuple(_check_type(doc, v, item, (*where, i)) for i, v in enumerate(value))
    if origin is dict or tp is dict:
        if not isinstance(value, dict):
            raise doc.error(_("must be a mapping, found {value!r}").format(value=value), *where)
        return value
    if dataclasses.is_dataclass(tp):
        return build(tp, doc, value, where)
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise doc.error(_("must be a number, found {value!r}").format(value=value), *where)
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise doc.error(_("must be a whole number, found {value!r}").format(value=value),
                            *where)
        return value
    if isinstance(tp, type) and not isinstance(value, tp):
        raise doc.error(_("must be {kind}, found {value!r}").format(
            kind=_type_name(tp), value=value), *where)
    return value


def build(cls: type[T], doc: Document, data: Any, where: tuple[str | int, ...] = ()) -> T:
    """Build dataclass ``cls`` from mapping ``data``, naming file, line and field on error.

    Unknown keys are errors (a typo must not pass silently); missing keys take the
    field's default, or are an error when the field has none.
    """
    if not isinstance(data, dict):
        raise doc.error(_("must be a mapping, found {value!r}").format(value=data), *where)
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}  # type: ignore[arg-type]
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise doc.error(_("unknown field (expected one of: {known})").format(
            known=", ".join(sorted(fields))), *where, unknown[0])
    kwargs: dict[str, Any] = {}
    for name, f in fields.items():
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise doc.error(_("required field is missing"), *where, name)
            continue
        kwargs[name] = _check_type(doc, data[name], hints[name], (*where, name))
    try:
        return cls(**kwargs)
    except FieldValueError as exc:  # a __post_init__ check of one field
        raise doc.error(str(exc), *where, exc.field) from None
    except ValueError as exc:  # a __post_init__ check of the whole
        raise doc.error(str(exc), *where) from None


def describe(cls: type) -> list[tuple[str, str, str]]:
    """(field, default, description) rows for docs and ``--help`` of a content format."""
    rows = []
    for f in dataclasses.fields(cls):
        default = (repr(f.default) if f.default is not dataclasses.MISSING
                   else "required" if f.default_factory is dataclasses.MISSING else "[]")
        rows.append((f.name, default, f.metadata.get("doc", "")))
    return rows
