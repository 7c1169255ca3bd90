"""The parameter_validation exercise proves its tests: every submission graded end to end.

The reference solution scores 100% (five times, with other gradings running beside it),
the starter scores below the pass mark, every other correct design scores 100%, each
known-bad variant loses exactly the tests its expect.yaml names, and broken programs get a
score and a plain message.
"""

from __future__ import annotations

import pytest
from proving import Proof, diagnosis, explain, failed_tests, without_both_types

pytestmark = pytest.mark.slow

# The submissions and what each must lose: tests/submissions/parameter_validation/*/.
PROOF = Proof("parameter_validation", jobs=3)


def test_reference_max_score_is_the_exercise_points(graded):
    assert graded["reference#0"].max_score == 13


# A syntax error is refused before any world starts: tests/core/test_source.py.


def test_crash_at_start_scores_zero_with_its_traceback(graded):
    result = graded["crash_at_start"]
    assert result.grader_error is None, explain(**diagnosis(result))
    assert result.score == 0
    message = result.tests[0].message
    # The same words whether or not discovery showed the node before the crash (it is
    # created, then the constructor raises): that race once changed this message.
    assert ("exited with status 1 during start-up, before its node 'velocity_governor' was "
            "up and spinning") in message
    assert "Traceback" in message


def test_wrong_node_name_is_reported_with_the_names_seen(graded):
    result = graded["wrong_node_name"]
    # Every test loses, the invalid-override one too: it first waits for the node named
    # velocity_governor, started with a valid override.
    assert failed_tests(result) == {t.name for t in result.tests}
    assert "No node named 'velocity_governor'" in result.tests[0].message
    assert "governor" in result.tests[0].message


def test_a_crash_that_names_the_parameters_earns_nothing(graded):
    """A program that crashes at import exits non-zero, and its traceback names both speed
    limits: the invalid-override test still gives it nothing, as it never read them."""
    result = graded["crashes_naming_parameters"]
    assert result.grader_error is None, explain(**diagnosis(result))
    assert result.score == 0
    test = {t.name: t for t in result.tests}["test_invalid_override_exits"]
    assert "max_linear_speed" in test.message and "max_angular_speed" in test.message
    assert "did not come up" in test.message


def test_node_that_never_spins_fails_what_needs_spinning(graded):
    result = graded["never_spins"]
    assert result.grader_error is None, explain(**diagnosis(result))
    assert not result.passed
    by_name = {t.name: t for t in result.tests}
    for name in ("test_clamps_linear", "test_refuses_out_of_range"):
        assert by_name[name].score == 0
        assert "spinning" in by_name[name].hint + by_name[name].message


def test_a_twist_stamped_node_is_told_both_types(graded):
    """The reference solution publishing TwistStamped, as for Jazzy's TurtleBot3: every test
    it loses says what it sent and what this exercise's robot takes."""
    assert without_both_types(graded["twist_stamped"]) == {}
