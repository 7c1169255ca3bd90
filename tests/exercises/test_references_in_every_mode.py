"""Every exercise's reference keeps full marks in isolation by user (root without
namespaces: Gradescope's container, a pod) and in basic isolation, as it does in strict
isolation; only isolation by user's grade is official (issue 29). Where grades are
official, a known-bad variant per exercise (the first, by name, that loses a core test)
loses there exactly the tests its proof names in strict isolation: the verdicts come from
the graph, whatever the isolation."""

from __future__ import annotations

import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import pytest
from conftest import modes_kept
from proving import Variant, failed_tests, failures, load_variants

from autograder.core.exercise import Exercise, list_exercises
from autograder.core.results import RunResult
from autograder.grading.run import grade
from autograder.sandbox import isolation
from content.course import course_root

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="isolation by user needs root")]


@pytest.fixture(scope="module", params=["user", "basic"])
def mode(request: pytest.FixtureRequest) -> Iterator[str]:
    old = os.environ.get("AUTOGRADER_ISOLATION")
    os.environ["AUTOGRADER_ISOLATION"] = request.param
    isolation.forget()
    with modes_kept(isolation.protected_paths(course_root())):
        yield request.param
    if old is None:
        os.environ.pop("AUTOGRADER_ISOLATION", None)
    else:
        os.environ["AUTOGRADER_ISOLATION"] = old
    isolation.forget()


def _known_bad(exercise: Exercise) -> Variant:
    core = set(exercise.core)
    return next(v for _name, v in sorted(load_variants(exercise).items())
                if v.kind == "mutant" and v.loses & core)


@pytest.fixture(scope="module")
def graded(mode: str, tmp_path_factory: pytest.TempPathFactory) -> dict[str, RunResult]:
    """Every reference graded in ``mode``, and where grades are official a known-bad
    variant per exercise, two at a time (as the corpus is)."""
    workdir = tmp_path_factory.mktemp("variants")
    workdir.chmod(0o755)  # the students' users read their copies
    jobs = {e.id: (e, None) for e in list_exercises()}
    if mode == "user":
        for e in list_exercises():
            jobs[f"{e.id}/bad"] = (e, _known_bad(e).submission(e, workdir))
    for path in [workdir, *workdir.rglob("*")]:
        path.chmod(0o755 if path.is_dir() else 0o644)
    with ThreadPoolExecutor(max_workers=2) as pool:
        return dict(pool.map(lambda item: (item[0], grade(*item[1])), jobs.items()))


@pytest.mark.parametrize("exercise", list_exercises(), ids=lambda e: e.id)
def test_the_reference_keeps_full_marks(exercise, graded, mode):
    result = graded[exercise.id]
    assert result.isolation.mode == mode
    assert result.isolation.official is (mode == "user")
    assert result.grader_error is None, result.grader_details
    assert result.score == result.max_score, [(t.name, t.message) for t in result.tests
                                              if not t.passed]


@pytest.mark.parametrize("exercise", list_exercises(), ids=lambda e: e.id)
def test_a_known_bad_variant_loses_the_same_tests_where_grades_are_official(exercise, graded,
                                                                            mode):
    if mode != "user":
        pytest.skip("basic isolation's grades are not official")
    result, variant = graded[f"{exercise.id}/bad"], _known_bad(exercise)
    assert result.isolation.mode == "user"
    assert result.grader_error is None, result.grader_details
    assert failed_tests(result) == variant.loses, (variant.name, failures(result))
    assert not result.passed
