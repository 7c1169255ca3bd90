"""Where the course tree (``assignments/``, ``quizzes/``, ``locales/``) lives."""

from __future__ import annotations

import os
from pathlib import Path

_PACKAGE_PARENT = Path(__file__).resolve().parents[1]


def _is_course(path: Path) -> bool:
    return (path / "assignments").is_dir()


def course_root() -> Path:
    """The course tree: ``$AUTOGRADER_COURSE``, else the nearest parent of the working
    directory holding ``assignments/``, else the checkout this package was installed from."""
    env = os.environ.get("AUTOGRADER_COURSE")
    if env:
        return Path(env).resolve()
    here = Path.cwd().resolve()
    for folder in (here, *here.parents):
        if _is_course(folder):
            return folder
    return _PACKAGE_PARENT
