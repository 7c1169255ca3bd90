"""Hidden test: along a 1 m corridor and round a right-angle turn to the goal."""

import pytest
from helpers import goal_parameters, judge_reached

from autograder.i18n import _

WORLD = "corridor"
LIMIT = 80.0
pytestmark = [pytest.mark.world(WORLD),
              pytest.mark.parameters(goal_parameters(WORLD))]


@pytest.mark.points(4)
def test_corridor_reaches_goal(mission):
    """Corridor: round the turn, the robot stops within 0.3 m of the goal, touching nothing"""
    judge_reached(mission, _("corridor"))
