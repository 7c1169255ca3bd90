"""Hidden test: in the simulated world the robot never goes faster than the limit."""

import pytest
from geometry_msgs.msg import Twist
from helpers import ready, twist
from nav_msgs.msg import Odometry

from autograder.core.errors import StudentFailure
from autograder.i18n import _

pytestmark = pytest.mark.world("empty_room")

LIMIT = 0.5
# Physics settles a step after a command changes: the speed may pass the limit by this much.
TOLERANCE = 0.03


@pytest.mark.points(2)
def test_speed_stays_under_limit(student, probe, commands):
    """Driven at 3.0 m/s by the agent, the robot's measured speed reaches the limit, never more"""
    ready(probe, commands)
    odom = probe.subscribe(Odometry, "/odom")
    start = probe.now
    while probe.now - start < 3.0:  # the agent insists at 10 Hz for 3 s of sim time
        probe.publish(Twist, "agent/cmd_vel", twist(linear_x=3.0))
        probe.wait_sim(0.1)
    probe.publish(Twist, "agent/cmd_vel", twist())
    speeds = [abs(m.twist.twist.linear.x) for m in odom.messages]
    if not speeds:
        raise StudentFailure(_("No odometry came from the world."))
    top = max(speeds)
    if top > LIMIT + TOLERANCE:
        raise StudentFailure(
            _("The robot reached {top:.2f} m/s; max_linear_speed is {limit} m/s.").format(
                top=top, limit=LIMIT),
            _("Clamp linear.x before publishing cmd_vel."))
    if top < LIMIT - 0.1:
        raise StudentFailure(
            _("The robot only reached {top:.2f} m/s while the agent asked for 3.0 m/s; it "
              "should drive at the limit, {limit} m/s.").format(top=top, limit=LIMIT),
            _("Forward the clamped command on cmd_vel; the world listens on /cmd_vel."))
