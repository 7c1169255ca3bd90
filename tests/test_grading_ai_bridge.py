"""The ai_bridge exercise proves its tests: every submission graded end to end.

The reference agent scores 100% in all three worlds (five times, with other gradings
running beside it), the starter scores below the pass mark, an agent built another way
(an occupancy grid and A*) scores 100%, and each known-bad agent loses the tests aimed at
it, with partial credit for the share of the way it covered.
"""

from __future__ import annotations

from fractions import Fraction

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
    "ai_bridge",
    correct=('grid_planner',),
    # Each known-bad variant, and the tests aimed at what it gets wrong.
    mutants={
        "ignores_obstacles": frozenset({"test_obstacles_reaches_goal",
                                        "test_corridor_reaches_goal"}),
        "never_reports": frozenset({"test_open_room_reports_arrival"}),
        "stops_short": frozenset({"test_open_room_reaches_goal", "test_obstacles_reaches_goal",
                                  "test_corridor_reaches_goal"}),
        "wanders": frozenset({"test_open_room_efficient_path"}),
    },
    jobs=4,
)


def test_progress_earns_partial_credit(graded):
    """Stopping 0.6 m short earns the share of the way covered, and says so."""
    by_name = {t.name: t for t in graded["stops_short"].tests}
    for name in ("test_open_room_reaches_goal", "test_obstacles_reaches_goal",
                 "test_corridor_reaches_goal"):
        test = by_name[name]
        assert test.status == "failed"
        assert Fraction(1, 2) * test.max_score < test.score < test.max_score
        assert "of the way" in test.message


def test_a_collision_is_named(graded):
    by_name = {t.name: t for t in graded["ignores_obstacles"].tests}
    message = by_name["test_corridor_reaches_goal"].message
    assert "hit wall" in message
    assert by_name["test_corridor_reaches_goal"].score < 1
