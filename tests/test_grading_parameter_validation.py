"""The parameter_validation exercise proves its tests: every submission graded end to end.

The reference solution scores 100% (five times, with other gradings running beside it),
the starter scores below the pass mark, every other correct design scores 100%, each
known-bad variant loses the test aimed at it, and broken programs get a score and a plain
message.
"""

from __future__ import annotations

import pytest
from proving import (  # noqa: F401 - the standard checks, collected here
    Proof,
    failed_tests,
    test_known_bad_variant_loses_the_test_aimed_at_it,
    test_other_correct_designs_score_full_marks,
    test_reference_scores_full_marks_every_time,
    test_starter_is_below_the_pass_mark,
)

pytestmark = pytest.mark.slow

PROOF = Proof(
    "parameter_validation",
    correct=("descriptor_ranges", "pre_post_callbacks", "read_each_message", "multithreaded"),
    mutants={
        "no_linear_clamp": frozenset({"test_clamps_linear", "test_speed_stays_under_limit"}),
        "no_angular_clamp": frozenset({"test_clamps_angular"}),
        "accepts_out_of_range": frozenset({"test_refuses_out_of_range"}),
        "accepts_empty_name": frozenset({"test_refuses_empty_robot_name"}),
        "silent_refusal": frozenset({"test_refuses_out_of_range",
                                     "test_refuses_empty_robot_name"}),
        "ignores_invalid_override": frozenset({"test_invalid_override_exits"}),
        "stale_limits": frozenset({"test_accepted_value_applies"}),
        "double_publish": frozenset({"test_one_output_per_input"}),
        "keeps_other_fields": frozenset({"test_other_fields_zero"}),
    },
    broken=("syntax_error", "crash_at_start", "never_spins", "wrong_node_name"),
    jobs=3,
)


def test_reference_max_score_is_the_exercise_points(graded):
    assert graded["reference#0"].max_score == 13


def test_syntax_error_is_named_with_its_line(graded):
    result = graded["syntax_error"]
    assert result.grader_error is None
    assert result.score == 0
    assert all("velocity_governor.py, line" in t.message for t in result.tests)


def test_crash_at_start_scores_zero_with_its_traceback(graded):
    result = graded["crash_at_start"]
    assert result.grader_error is None
    assert result.score == 0
    message = result.tests[0].message
    # The same words whether or not discovery showed the node before the crash (it is
    # created, then the constructor raises): that race once changed this message.
    assert ("exited with status 1 during start-up, before its node 'velocity_governor' was "
            "up and spinning") in message
    assert "Traceback" in message


def test_wrong_node_name_is_reported_with_the_names_seen(graded):
    result = graded["wrong_node_name"]
    # Only the invalid-override test, which needs no node name, can pass.
    assert failed_tests(result) >= {t.name for t in result.tests} - {
        "test_invalid_override_exits"}
    assert "No node named 'velocity_governor'" in result.tests[0].message
    assert "governor" in result.tests[0].message


def test_node_that_never_spins_fails_what_needs_spinning(graded):
    result = graded["never_spins"]
    assert result.grader_error is None
    assert not result.passed
    by_name = {t.name: t for t in result.tests}
    for name in ("test_clamps_linear", "test_refuses_out_of_range"):
        assert by_name[name].score == 0
        assert "spinning" in by_name[name].hint + by_name[name].message
