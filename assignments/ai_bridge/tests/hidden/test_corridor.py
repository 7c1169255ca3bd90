"""Hidden test: along a 1 m corridor and round a right-angle turn to the goal."""

import pytest
from helpers import judge_reached

from autograder.i18n import _
from sim.worldfile import load_world

WORLD = "corridor"
GOAL = load_world(WORLD).goal
LIMIT = 80.0
pytestmark = [pytest.mark.world(WORLD),
              pytest.mark.parameters({"goal_x": GOAL.x, "goal_y": GOAL.y})]


@pytest.mark.points(4)
def test_corridor_reaches_goal(mission, credit):
    """Corridor: the robot follows it round the turn and stops within 0.3 m of the goal"""
    judge_reached(mission, credit, _("corridor"))
