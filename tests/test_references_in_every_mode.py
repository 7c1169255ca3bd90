"""Every exercise's reference keeps full marks in isolation by user (root without
namespaces: Gradescope's container, a pod) and in basic isolation, as it does in strict
isolation; only isolation by user's grade is official (issue 29)."""

from __future__ import annotations

import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import pytest
from conftest import modes_kept

from autograder.core.course import course_root
from autograder.core.exercise import list_exercises
from autograder.core.results import RunResult
from autograder.grading.run import grade
from autograder.sandbox import isolation

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="isolation by user needs root")]


@pytest.fixture(scope="module", params=["user", "basic"])
def mode(request: pytest.FixtureRequest) -> Iterator[str]:
    old = os.environ.get("AUTOGRADER_ISOLATION")
    os.environ["AUTOGRADER_ISOLATION"] = request.param
    isolation.detect.cache_clear()
    with modes_kept(isolation.protected_paths(course_root())):
        yield request.param
    if old is None:
        os.environ.pop("AUTOGRADER_ISOLATION", None)
    else:
        os.environ["AUTOGRADER_ISOLATION"] = old
    isolation.detect.cache_clear()


@pytest.fixture(scope="module")
def graded(mode: str) -> dict[str, RunResult]:
    """Every reference graded in ``mode``, two at a time (as the corpus is)."""
    with ThreadPoolExecutor(max_workers=2) as pool:
        return dict(pool.map(lambda e: (e.id, grade(e, None)), list_exercises()))


@pytest.mark.parametrize("exercise", list_exercises(), ids=lambda e: e.id)
def test_the_reference_keeps_full_marks(exercise, graded, mode):
    result = graded[exercise.id]
    assert result.data["isolation"]["mode"] == mode
    assert result.data["isolation"]["official"] is (mode == "user")
    assert result.grader_error is None, result.grader_details
    assert result.score == result.max_score, [(t.name, t.message) for t in result.tests
                                              if not t.passed]
