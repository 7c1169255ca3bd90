"""Check a whole course tree before a release: every exercise file loads, its files exist,
its worlds load, its core tests exist, its reference solution scores 100% (every core test
passed), its starter does not pass (and fails a core test), every quiz lints, and the
catalogs pass ``i18n check``.  Each problem is a ``file:line: message``."""

from __future__ import annotations

import functools
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from autograder.commands.exercise_checks import check_exercise
from autograder.core.errors import ContentError
from autograder.core.exercise import Exercise, assignments_dir, load_exercise, test_names
from autograder.core.results import RunResult, number
from autograder.i18n import _
from autograder.i18n.tools import Problem
from content import load_document


def _from(exc: ContentError) -> Problem:
    return Problem(exc.path, exc.line, f"{exc.field}: {exc.message}" if exc.field
                   else exc.message)


def _files(exercise: Exercise) -> list[Problem]:
    problems = []
    where = exercise.folder / "exercise.yaml"
    for path, what in ((exercise.starter, _("starter file")),
                       (exercise.solution, _("reference solution")),
                       (exercise.folder / "README.md", _("README")),
                       (exercise.public_tests, _("public tests folder"))):
        if not path.exists():
            problems.append(Problem(where, None, _("{what} {path} is missing").format(
                what=what, path=path)))
    return problems


def _core(exercise: Exercise) -> list[Problem]:
    """The exercise names core tests, and each is one of its tests."""
    doc = load_document(exercise.folder / "exercise.yaml")
    if not exercise.core:
        return [Problem(doc.path, None, _(
            "core names no test: name the tests without which the exercise is not passed "
            "(the chapter's central idea, the robot's safety)"))]
    known = test_names(exercise)
    return [_from(doc.error(_("no test named {name!r} in {folder}").format(
                name=name, folder=exercise.folder / "tests"), "core", index))
            for index, name in enumerate(exercise.core) if name not in known]


def _worlds(exercise: Exercise) -> list[Problem]:
    from sim.worldfile import load_world

    problems = []
    local = exercise.folder / exercise.world
    names = [local if local.suffix in (".yaml", ".yml") and local.exists() else exercise.world]
    names += sorted(exercise.folder.glob("worlds/*.yaml"))
    for name in names:
        try:
            load_world(name)
        except ContentError as exc:
            if name == exercise.world and not exc.path.exists():
                # No such world: the mistake is in the exercise file's `world` field.
                doc = load_document(exercise.folder / "exercise.yaml")
                exc = doc.error(exc.message, "world")
            problems.append(_from(exc))
    return problems


def _gradings(exercise: Exercise, grade: Callable[..., RunResult]) -> list[Problem]:
    where = exercise.folder / "exercise.yaml"
    problems = []
    reference = grade(exercise, exercise.solution)
    if reference.grader_error:
        last = (reference.grader_details.strip().splitlines() or [reference.grader_error])[-1]
        problems.append(Problem(where, None, _(
            "grading the reference solution failed: {details}").format(details=last)))
    elif reference.score != reference.max_score:
        failed = ", ".join(t.name for t in reference.tests if not t.passed)
        problems.append(Problem(where, None, _(
            "the reference solution scores {score}/{max_score}, not full marks (failed: "
            "{failed})").format(score=number(reference.score),
                                max_score=number(reference.max_score), failed=failed)))
    if reference.grader_error is None and reference.core_missed:
        problems.append(Problem(where, None, _(
            "the reference solution fails core tests: {failed}").format(
            failed=", ".join(t.name for t in reference.core_missed))))
    starter = grade(exercise, exercise.starter)
    if starter.grader_error is None and starter.passed:
        problems.append(Problem(where, None, _(
            "the starter scores {score}/{max_score}, at or above the pass mark").format(
            score=number(starter.score), max_score=number(starter.max_score))))
    if starter.grader_error is None and exercise.core and not starter.core_missed:
        problems.append(Problem(where, None, _(
            "the starter passes every core test ({tests}): a core test should need the "
            "student's work").format(tests=", ".join(exercise.core))))
    return problems


def validate(root: Path | None = None, *, run_gradings: bool = True, jobs: int = 2,
             progress: Callable[[str], None] | None = None) -> list[Problem]:
    """Every problem in the course tree (``root`` defaults to the course in use)."""
    from autograder.grading.run import grade
    from autograder.i18n import locales_dir
    from autograder.i18n.glossary import check_all
    from autograder.quiz.lint import lint
    from content.course import course_root

    folder = root / "assignments" if root else assignments_dir()
    problems: list[Problem] = []
    exercises = []
    for path in sorted(p for p in folder.iterdir() if p.is_dir()) if folder.is_dir() else []:
        if not (path / "exercise.yaml").exists():
            problems.append(Problem(path, None, _("no exercise.yaml in this folder")))
            continue
        try:
            exercise = load_exercise(path)
        except ContentError as exc:
            problems.append(_from(exc))
            continue
        found = _files(exercise) + _worlds(exercise) + _core(exercise)
        # READMEs, grading table, translations, proof: the exercise still grades without.
        problems += found + check_exercise(exercise, folder.parent)
        if not found:
            exercises.append(exercise)
    if run_gradings:
        def check(exercise: Exercise) -> list[Problem]:
            if progress:
                progress(exercise.id)
            # Several gradings at once already share the cores: one child each.
            return _gradings(exercise, functools.partial(
                grade, module_jobs=1 if jobs > 1 else "auto"))

        with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            for found in pool.map(check, exercises):
                problems += found
    problems += lint(root, root / "locales" if root else None)
    problems += check_all(root / "locales" if root else locales_dir(), root=root or course_root())
    return problems
