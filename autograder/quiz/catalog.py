"""The course's quizzes: every ``quizzes/*.yaml`` file, found by id."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from autograder.core.errors import ContentError
from autograder.core.names import unknown_quiz
from autograder.i18n import content_text
from autograder.quiz.model import QuizFile, context, load_quiz
from content import load_document
from content.course import course_root


@dataclasses.dataclass(frozen=True)
class QuizEntry:
    """What ``autograder list`` shows of a quiz."""

    id: str
    title: str
    languages: tuple[str, ...]
    path: Path
    kind: str = "quiz"
    # A file that does not load: its ContentError (``file:line: field: message``); the
    # others list, serve and score all the same.
    error: str = ""


def quizzes_dir(root: Path | None = None) -> Path:
    return (root or course_root()) / "quizzes"


def quiz_paths(root: Path | None = None) -> list[Path]:
    folder = quizzes_dir(root)
    return sorted([*folder.glob("*.yaml"), *folder.glob("*.yml")])


def load_all(root: Path | None = None) -> list[QuizFile]:
    """Every quiz; the first malformed file raises its ContentError."""
    return [load_quiz(p) for p in quiz_paths(root)]


def load_each(root: Path | None = None) -> tuple[list[QuizFile], list[ContentError]]:
    """Every quiz that loads, and the error of each file that does not: one bad file is
    one problem, not every quiz's."""
    files, errors = [], []
    for path in quiz_paths(root):
        try:
            files.append(load_quiz(path))
        except ContentError as exc:
            errors.append(exc)
    return files, errors


def find_quiz(name: str, root: Path | None = None) -> QuizFile:
    """A quiz by id, or by the path of its file. Another quiz's broken file is no
    obstacle; the asked-for quiz's own (its file named ``<name>.yaml``) is its error."""
    path = Path(name)
    if path.suffix in (".yaml", ".yml") and path.exists():
        return load_quiz(path)
    files, errors = load_each(root)
    for qf in files:
        if qf.quiz.id == name:
            return qf
    for exc in errors:
        if name in (exc.path.stem, _stated_id(exc.path)):
            raise exc
    raise unknown_quiz(name, [qf.quiz.id for qf in files], quizzes_dir(root))


def list_quizzes(root: Path | None = None) -> list[QuizEntry]:
    """Quizzes for ``autograder list``: id, title (in the active language), languages; a
    file that does not load is listed by its name, with its error."""
    files, errors = load_each(root)
    return sorted([QuizEntry(qf.quiz.id, content_text(context(qf.quiz.id, "title"),
                                                      qf.quiz.title), qf.quiz.languages, qf.path)
                   for qf in files] + [QuizEntry(_stated_id(exc.path) or exc.path.stem, "", (),
                                                 exc.path, error=str(exc))
                                       for exc in errors], key=lambda e: e.path)


def _stated_id(path: Path) -> str | None:
    """The ``id`` a quiz file that does not load states, if it reads as YAML at all."""
    try:
        data = load_document(path).data
    except ContentError:
        return None
    stated = data.get("id") if isinstance(data, dict) else None
    return stated if isinstance(stated, str) else None
