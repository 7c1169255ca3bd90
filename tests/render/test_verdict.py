"""What every format says of core tests (autograder.render.verdict): the label marked, and
the core tests that kept a grading from passing, with one heading for a whole grading and
another for a partial run."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

from autograder.core.results import NotRun, RunResult, TestResult
from autograder.render.verdict import core_heading, core_label, core_lines


def graded(*tests: TestResult) -> RunResult:
    return RunResult("exercise", "x", "X", tests)


def a_test(name: str, passed: bool, core: bool = True) -> TestResult:
    return TestResult(name, name.capitalize(), Fraction(passed), Fraction(1),
                      "passed" if passed else "failed", core=core)


def test_a_core_tests_label_is_marked() -> None:
    assert core_label(a_test("starts", True)) == "Starts (core)"
    assert core_label(a_test("starts", True, core=False)) == "Starts"


def test_the_missed_core_tests_are_listed_under_one_heading() -> None:
    result = graded(a_test("starts", False), a_test("stops", False), a_test("extra", True, False))
    lines = core_lines(result)
    assert lines[0].startswith("Not passed: these 2 core tests failed")
    assert lines[1:] == ["- Starts", "- Stops"]
    one = graded(a_test("starts", False), a_test("stops", True))
    assert core_lines(one) == [
        "Not passed: this core test failed, and every core test must pass, whatever the "
        "points:", "- Starts"]


def test_a_partial_run_says_the_grade_cannot_pass_yet() -> None:
    partial = dataclasses.replace(graded(a_test("starts", False)), not_run=NotRun(3))
    assert core_heading(partial) == \
        "This core test failed; the grade cannot pass until it passes:"


def test_nothing_is_said_when_every_core_test_passed_or_the_grader_failed() -> None:
    assert core_lines(graded(a_test("starts", True), a_test("extra", False, core=False))) == []
    failed = dataclasses.replace(graded(a_test("starts", False)), grader_error="boom")
    assert core_heading(failed) is None
