"""Public tests: in an open room, the agent turns, drives to its goal, stops and says so."""

import pytest
from helpers import (
    REACHED,
    STATUS_WITHIN,
    STILL,
    goal_parameters,
    judge_efficiency,
    judge_reached,
)

from autograder.core.errors import StudentFailure
from autograder.i18n import _

WORLD = "open_room"
LIMIT = 40.0  # simulation seconds to arrive
pytestmark = [pytest.mark.world(WORLD),
              pytest.mark.parameters(goal_parameters(WORLD))]


@pytest.mark.points(3)
def test_open_room_reaches_goal(mission):
    """Open room: the robot stops within 0.3 m of the goal, touching nothing"""
    judge_reached(mission, _("open room"))


@pytest.mark.points(2)
def test_open_room_reports_arrival(mission):
    """Once stopped within 0.3 m of the goal, the agent publishes on agent_status, not before"""
    if mission.arrived_at is None:
        raise StudentFailure(
            _("The robot never stopped at the goal, so its report could not be judged."),
            _("Reach the goal first (see the test above)."))
    if not mission.statuses:
        raise StudentFailure(
            _("The robot stopped {left:.2f} m from the goal, and nothing came on agent_status "
              "within {within:.0f} s.").format(
                left=mission.to_goal(mission.samples[-1]), within=STATUS_WITHIN),
            _("Publish a std_msgs/String such as 'goal reached' on agent_status once, when "
              "you stop at the goal."))
    stamp, text = mission.statuses[0]
    state = mission.state_at(stamp)
    if state is not None and mission.stopped_at_goal(state):
        return
    away = mission.to_goal(state) if state is not None else mission.distance
    if away > REACHED:
        raise StudentFailure(
            _("agent_status said {text!r} while the robot was still {away:.2f} m from the "
              "goal.").format(text=text, away=away),
            _("Report arrival when you are within 0.3 m of the goal, not before."))
    if abs(state.v) < STILL:  # slow enough, but still turning
        raise StudentFailure(
            _("agent_status said {text!r} while the robot, {away:.2f} m from the goal, was "
              "still turning at {turn:.2f} rad/s.").format(text=text, away=away,
                                                           turn=abs(state.w)),
            _("Report once the robot has stopped turning too (slower than {turn} rad/s): the "
              "odometry's twist.twist.angular.z says how fast it turns.").format(
                turn=5 * STILL))
    later = mission.arrived_at - stamp
    moving = _("agent_status said {text!r} while the robot, {away:.2f} m from the goal, was "
               "still moving at {speed:.2f} m/s; it stopped {later:.2f} s later.") if later > 0 \
        else _("agent_status said {text!r} while the robot, {away:.2f} m from the goal, was "
               "moving at {speed:.2f} m/s.")
    raise StudentFailure(
        moving.format(text=text, away=away, speed=abs(state.v), later=later),
        _("Report once the robot has stopped within 0.3 m of the goal (slower than {still} "
          "m/s): a stop you have sent still takes the robot a moment. The odometry's "
          "twist.twist.linear.x says how fast it goes.").format(still=STILL))


@pytest.mark.points(1)
def test_open_room_efficient_path(mission):
    """Open room: the path is not much longer than the straight line (bonus)"""
    judge_efficiency(mission, _("open room"))
