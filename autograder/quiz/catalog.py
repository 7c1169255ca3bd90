"""The course's quizzes: every ``quizzes/*.yaml`` file, found by id."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from autograder.core.course import course_root
from autograder.core.names import unknown_quiz
from autograder.i18n import content_text
from autograder.quiz.model import QuizFile, context, load_quiz


@dataclasses.dataclass(frozen=True)
class QuizEntry:
    """What ``autograder list`` shows of a quiz."""

    id: str
    title: str
    languages: tuple[str, ...]
    path: Path
    kind: str = "quiz"


def quizzes_dir(root: Path | None = None) -> Path:
    return (root or course_root()) / "quizzes"


def quiz_paths(root: Path | None = None) -> list[Path]:
    folder = quizzes_dir(root)
    return sorted([*folder.glob("*.yaml"), *folder.glob("*.yml")])


def load_all(root: Path | None = None) -> list[QuizFile]:
    """Every quiz; the first malformed file raises its ContentError."""
    return [load_quiz(p) for p in quiz_paths(root)]


def find_quiz(name: str, root: Path | None = None) -> QuizFile:
    """A quiz by id, or by the path of its file."""
    path = Path(name)
    if path.suffix in (".yaml", ".yml") and path.exists():
        return load_quiz(path)
    for p in quiz_paths(root):
        qf = load_quiz(p)
        if qf.quiz.id == name:
            return qf
    raise unknown_quiz(name, [load_quiz(p).quiz.id for p in quiz_paths(root)],
                       quizzes_dir(root))


def list_quizzes(root: Path | None = None) -> list[QuizEntry]:
    """Quizzes for ``autograder list --json``: id, title (in the active language), languages."""
    return [QuizEntry(qf.quiz.id, content_text(context(qf.quiz.id, "title"), qf.quiz.title),
                      qf.quiz.languages, qf.path)
            for qf in load_all(root)]
