"""Velocity governor: the safety gate between an AI agent's wishes and the wheels.

Tier A: simulation.

Learning objectives: validate parameters in an on-set callback and refuse bad values
with a reason; check -p overrides at startup and refuse to run; clamp an untrusted
velocity command to limits that can change while the node runs.

Prerequisites: publishers, subscribers and declare_parameter in one Node.

Expected output: an agent asking for 3.0 m/s on agent/cmd_vel yields 0.5 m/s on
cmd_vel. Started with `-p max_linear_speed:=3.0` the node logs
"[ERROR] [...] [velocity_governor]: max_linear_speed must be within [0.0, 1.5], got 3.0"
and exits with status 1.
"""
import sys

import rclpy
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


class VelocityGovernor(Node):

    def __init__(self):
        super().__init__('velocity_governor')
        # Accepted values: max_linear_speed 0.0 to 1.5, max_angular_speed 0.0 to 2.5,
        # robot_name not empty.
        self.declare_parameter('max_linear_speed', 0.5)
        self.declare_parameter('max_angular_speed', 1.0)
        self.declare_parameter('robot_name', 'tb3')
        # TODO: declare_parameter has already applied any -p override, and the on-set
        # callback below will never see it. Check the three starting values here and
        # make main() log an error naming the parameter and return a non-zero status.
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.subscription = self.create_subscription(
            Twist, 'agent/cmd_vel', self.on_agent_command, 10)

    def on_set_parameters(self, params):
        # TODO: refuse an out-of-range speed or an empty robot_name with
        # SetParametersResult(successful=False, reason=...), a reason that names the
        # parameter, e.g. 'max_linear_speed must be within [0.0, 1.5], got 3.0'.
        # Refusing keeps the old value; accepting must change the limits used from
        # the next message on.
        return SetParametersResult(successful=True)

    def on_agent_command(self, wish):
        # A fresh Twist zeroes every field a differential-drive base cannot follow.
        command = Twist()
        # TODO: clamp linear.x to [-max_linear_speed, max_linear_speed] and angular.z
        # to [-max_angular_speed, max_angular_speed]. Right now the agent's wish
        # reaches the wheels untouched: 3.0 m/s in, 3.0 m/s out.
        command.linear.x = wish.linear.x
        command.angular.z = wish.angular.z
        self.publisher.publish(command)


def main(args=None):
    rclpy.init(args=args)
    node = VelocityGovernor()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    # TODO: return 1 when the node refused to start, so launch files see the failure.
    return 0


if __name__ == '__main__':
    sys.exit(main())
