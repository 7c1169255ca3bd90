"""The grader's child pytest runs the exercise's tests as written, whoever grades: nothing
of the caller's pytest settings reaches it (autograder/grading/children.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from autograder.core.exercise import find_exercise
from autograder.grading.children import pytest_env
from autograder.grading.run import grade

STARTER = (Path(__file__).resolve().parent.parent / "assignments" / "parameter_validation"
           / "starter")


def test_the_child_gets_none_of_the_callers_pytest_variables() -> None:
    env = pytest_env({"PATH": "/usr/bin", "PYTEST_ADDOPTS": "-x", "PYTEST_PLUGINS": "mine",
                      "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "", "PYTEST_CURRENT_TEST": "t"})
    assert env == {"PATH": "/usr/bin", "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1"}


@pytest.mark.slow
def test_a_callers_pytest_options_change_no_grade(monkeypatch: pytest.MonkeyPatch) -> None:
    """A CI job's ``PYTEST_ADDOPTS=-x`` stopped the grading at the starter's first failed
    test (1/13 where it scores 4/13); a ``PYTEST_PLUGINS`` naming a missing module would
    stop every grading."""
    monkeypatch.setenv("PYTEST_ADDOPTS", "-x")
    monkeypatch.setenv("PYTEST_PLUGINS", "no_such_plugin_of_the_callers")
    result = grade(find_exercise("parameter_validation"), STARTER)
    assert result.grader_error is None, result.grader_error
    statuses = [t.status for t in result.tests]
    assert statuses.count("failed") >= 2, statuses  # -x would leave one failure at most
    assert set(statuses) <= {"passed", "failed"}, statuses
