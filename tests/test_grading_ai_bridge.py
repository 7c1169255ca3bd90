"""The ai_bridge exercise proves its tests: every submission graded end to end.

The reference agent scores 100% in all three worlds (five times, with other gradings
running beside it), the starter scores below the pass mark, an agent built another way
(an occupancy grid and A*) scores 100%, and each known-bad agent loses exactly the tests
its expect.yaml names, all or nothing (the message says the share of the way covered).
"""

from __future__ import annotations

import pytest
from proving import Proof, without_both_types

pytestmark = pytest.mark.slow

# The submissions and what each must lose: tests/submissions/ai_bridge/*/.
PROOF = Proof("ai_bridge", jobs=4)


def test_falling_short_earns_nothing_and_says_how_far(graded):
    """Stopping 0.6 m short earns none of an arrival's points (all or nothing: the same
    program, the same score), and the message says how much of the way it covered."""
    by_name = {t.name: t for t in graded["stops_short"].tests}
    for name in ("test_open_room_reaches_goal", "test_obstacles_reaches_goal",
                 "test_corridor_reaches_goal"):
        test = by_name[name]
        assert test.status == "failed" and test.score == 0
        assert "of the way" in test.message


def test_a_collision_is_named(graded):
    by_name = {t.name: t for t in graded["ignores_obstacles"].tests}
    message = by_name["test_corridor_reaches_goal"].message
    assert "hit wall" in message
    assert by_name["test_corridor_reaches_goal"].score == 0


def test_a_twist_stamped_node_is_told_both_types(graded):
    """The reference solution publishing TwistStamped, as for Jazzy's TurtleBot3: every test
    it loses says what it sent and what this exercise's robot takes."""
    assert without_both_types(graded["twist_stamped"]) == {}
