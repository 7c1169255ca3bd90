"""A grading of five tests that every output format is tested on (tests/render/):
a pass, a failure with a hint and a chart, a hidden failure whose message is secret,
a hidden pass and a partial credit."""

from __future__ import annotations

from fractions import Fraction

from autograder.core.results import (
    IntervalChart,
    RunResult,
    TestResult,
)

SECRET = "internal detail of a hidden test"


def graded_result(lang: str = "en", grader_error: str | None = None) -> RunResult:
    tests = (
        TestResult("test_starts", "The node starts", Fraction(1), Fraction(1), "passed"),
        TestResult("test_rate", "cmd_vel keeps 10 Hz", Fraction(0), Fraction(2), "failed",
                   message="`cmd_vel` came at 3.1 Hz <script>alert(1)</script>",
                   hint="Is the planner in its own callback group?",
                   charts=(IntervalChart("cmd_vel", ((0.1, 0.1), (0.2, 0.1), (0.9, 0.7)),
                                         0.15),)),
        TestResult("test_hidden", "Refuses bad values", Fraction(0), Fraction(2), "failed",
                   message=SECRET, hint=SECRET, visibility="after_published",
                   reveal="status"),
        TestResult("test_hidden2", "Exits on a bad override", Fraction(1), Fraction(1),
                   "passed", visibility="hidden", reveal="status"),
        TestResult("test_partial", "Reaches the goal", Fraction(1, 2), Fraction(1), "failed",
                   message="covered half the way"),
    )
    return RunResult("exercise", "timer_sync", "A multi-rate controller", tests, lang=lang,
                     grader_error=grader_error, execution_time=12.5, log_tail="[INFO] hi")
