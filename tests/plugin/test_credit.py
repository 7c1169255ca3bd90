"""Partial credit and evidence: what a test attaches to its own entry in the report. An
award is clamped to [0, 1] and the last one counts; message intervals become a chart's
points, rounded as they are drawn; each fixture is the running test's own. (How the reporter
turns an award into a verdict: tests/plugin/test_reporter.py.)"""

from __future__ import annotations

import pytest

from autograder.core.results import IntervalChart
from autograder.plugin.credit import Credit, Evidence


def test_an_award_is_clamped_and_the_last_one_counts():
    given = Credit()
    assert (given.fraction, given.message, given.hint) == (None, "", "")  # no award yet
    given.award(0.25, "a quarter of the way", "drive on")
    assert (given.fraction, given.message, given.hint) == (0.25, "a quarter of the way",
                                                           "drive on")
    given.award(1.7)
    assert (given.fraction, given.message, given.hint) == (1.0, "", "")
    given.award(-0.5, "backwards")
    assert (given.fraction, given.message) == (0.0, "backwards")


def test_intervals_are_the_gaps_at_each_messages_time():
    shown = Evidence()
    shown.intervals("cmd_vel", [1.0, 1.1, 1.3000004, 1.35], limit=0.15 + 1e-6)
    shown.intervals("odom", [2.0])  # one message: no gap yet
    first, second = shown.charts
    assert first == IntervalChart("cmd_vel", ((1.1, 0.1), (1.3, 0.2), (1.35, 0.05)), 0.15)
    assert second == IntervalChart("odom", (), None)


def test_each_fixture_is_the_running_tests_own(pytester: pytest.Pytester) -> None:
    pytester.makepyfile('''
        from autograder.plugin.stash import credit_key, evidence_key

        seen = []

        def test_first(request, credit, evidence):
            assert request.node.stash[credit_key] is credit
            assert request.node.stash[evidence_key] is evidence
            credit.award(0.5)
            evidence.intervals("t", [0.0, 1.0])
            seen.append((credit, evidence))

        def test_second(request, credit, evidence):
            assert request.node.stash[credit_key] is credit
            assert credit.fraction is None and evidence.charts == []
            assert credit is not seen[0][0] and evidence is not seen[0][1]

        def test_without(request):
            assert credit_key not in request.node.stash
    ''')
    pytester.runpytest("-p", "no:cacheprovider").assert_outcomes(passed=3)
