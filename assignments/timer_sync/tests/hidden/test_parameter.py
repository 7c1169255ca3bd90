"""Hidden test: cruise_speed set on the command line reaches cmd_vel."""

import pytest
from geometry_msgs.msg import Twist

from autograder.core.errors import StudentFailure
from autograder.i18n import _

SPEED = 0.35


@pytest.mark.points(1)
def test_cruise_speed_override(start_node, probe):
    """Started with -p cruise_speed:=0.35, cmd_vel carries linear.x 0.35"""
    commands = probe.subscribe(Twist, "/cmd_vel")
    start_node({"cruise_speed": SPEED})
    if not probe.wait_for(lambda: len(commands) >= 5, 5.0):
        raise StudentFailure(
            _("Nothing came on cmd_vel within 5 s of simulation time."),
            _("Create a 10 Hz timer whose callback publishes a Twist on cmd_vel."))
    wrong = [m.linear.x for m in commands.messages if abs(m.linear.x - SPEED) > 1e-6]
    if wrong:
        raise StudentFailure(
            _("Started with -p cruise_speed:=0.35, cmd_vel had linear.x={got}.").format(
                got=wrong[0]),
            _("Read the cruise_speed parameter (declare_parameter returns it) instead of a "
              "constant."))
