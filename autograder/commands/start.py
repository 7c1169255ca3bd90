"""``autograder start``: a student's folder for an exercise, from its starter code."""

from __future__ import annotations

import shutil
from pathlib import Path

from autograder.commands.grade import exercise
from autograder.core.errors import UsageError
from autograder.core.exercise import Exercise
from autograder.i18n import _


def start(exercise_id: str, directory: Path | None) -> tuple[Exercise, Path, list[Path]]:
    """Copy the exercise's starter code, its READMEs and its own world file into
    ``directory`` (default: the exercise id); the exercise, the folder and each file
    written. A file already there is never overwritten: a UsageError names it."""
    found = exercise(exercise_id)
    target = directory or Path(found.id)
    target.mkdir(parents=True, exist_ok=True)
    copied = []
    # A world kept in the exercise's folder goes too: the README's hand run names it there.
    world = found.folder / found.world
    own_world = [world] if world.suffix in (".yaml", ".yml") and world.is_file() else []
    for source in (found.starter, *sorted(found.folder.glob("README*.md")), *own_world):
        dest = target / source.name
        if dest.exists():
            raise UsageError(_("{path} already exists; not overwriting your work").format(
                path=dest))
        shutil.copy2(source, dest)
        copied.append(dest)
    return found, target, copied
