"""Find the student's file in what they submitted, and give the grader a copy to run."""

from __future__ import annotations

import shutil
from pathlib import Path

from autograder.i18n import _


class SubmissionNotFound(Exception):
    """SUBMISSION names no file the exercise can grade."""


def locate(submission: Path, filename: str) -> Path:
    """The student's ``filename``: SUBMISSION itself, or the file of that name inside it."""
    if submission.is_dir():
        candidate = submission / filename
        if candidate.is_file():
            return candidate
        matches = sorted(submission.rglob(filename))
        if len(matches) == 1:
            return matches[0]
        raise SubmissionNotFound(_("{folder} holds no {file}").format(
            folder=submission, file=filename))
    if submission.is_file():
        return submission
    raise SubmissionNotFound(_("{path} does not exist").format(path=submission))


def stage(source: Path, filename: str, dest: Path) -> Path:
    """Copy the student's file (and its sibling ``.py`` modules) into ``dest``.

    The student's process runs from this copy, so nothing it does touches the original.
    """
    dest.mkdir(parents=True, exist_ok=True)
    for sibling in source.parent.glob("*.py"):
        if sibling.is_file() and sibling.stat().st_size < 1_000_000:
            shutil.copy2(sibling, dest / sibling.name)
    target = dest / filename
    shutil.copy2(source, target)
    return target
