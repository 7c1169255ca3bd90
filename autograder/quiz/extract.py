"""Babel extractors for course content: quiz files and exercise files.

Each string gets a gettext context made of ids (``quiz:<quiz>:<question>:<field>``,
``exercise:<id>:<field>``), so identical English strings in two questions stay separate,
and the real line of the string in the YAML file.  Registered as Babel extractors
``autograder_quiz`` and ``autograder_exercise``; ``babel.cfg`` names them by module path
too, so they work from a checkout before the package is installed.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

from autograder.quiz.model import load_quiz, strings
from content import load_document

Extracted = tuple[int, str, tuple[str, str], list[str]]
EXERCISE_FIELDS = ("title", "summary")


def _read(fileobj: IO[bytes]) -> tuple[Path, str]:
    name = getattr(fileobj, "name", "<quiz>")
    return Path(name), fileobj.read().decode("utf-8")


def extract_quiz(fileobj: IO[bytes], keywords: Mapping[str, Any],
                 comment_tags: Collection[str], options: Mapping[str, Any]) -> Iterator[Extracted]:
    """Yield ``(line, "pgettext", (context, text), comments)`` for every quiz string."""
    path, text = _read(fileobj)
    for s in strings(load_quiz(path, text)):
        yield s.line, "pgettext", (s.context, s.text), [s.comment]


def extract_exercise(fileobj: IO[bytes], keywords: Mapping[str, Any],
                     comment_tags: Collection[str],
                     options: Mapping[str, Any]) -> Iterator[Extracted]:
    """The ``title`` and ``summary`` of an exercise file, context ``exercise:<id>:<field>``."""
    path, text = _read(fileobj)
    doc = load_document(path, text)
    data = doc.data if isinstance(doc.data, dict) else {}
    exercise_id = data.get("id") or path.parent.name
    for name in EXERCISE_FIELDS:
        value = data.get(name)
        if isinstance(value, str) and value.strip():
            yield (doc.line(name) or 1, "pgettext", (f"exercise:{exercise_id}:{name}", value),
                   [f"exercise {name}"])
