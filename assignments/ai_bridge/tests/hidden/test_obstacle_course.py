"""Hidden tests: corner to corner across a room, with obstacles on the straight line."""

import pytest
from helpers import goal_parameters, judge_efficiency, judge_reached

from autograder.i18n import _

WORLD = "obstacle_course"
LIMIT = 60.0
pytestmark = [pytest.mark.world(WORLD),
              pytest.mark.parameters(goal_parameters(WORLD))]


@pytest.mark.points(3)
def test_obstacles_reaches_goal(mission):
    """Obstacle course: the robot stops within 0.3 m of the goal, touching nothing"""
    judge_reached(mission, _("obstacle course"))


@pytest.mark.points(1)
def test_obstacles_efficient_path(mission):
    """Obstacle course: the path is not much longer than the straight line (bonus)"""
    judge_efficiency(mission, _("obstacle course"))
