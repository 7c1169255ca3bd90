"""Correct: ranges live in ParameterDescriptors, so rclpy itself refuses out-of-range values."""
import sys

import rclpy
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


def speed_limit(low, high, what):
    """A descriptor whose range rclpy enforces on every set, overrides included."""
    return ParameterDescriptor(
        description=what,
        floating_point_range=[FloatingPointRange(from_value=low, to_value=high)])


class VelocityGovernor(Node):

    def __init__(self):
        super().__init__('velocity_governor')
        # Registered before declaring, so the -p override of robot_name is checked too.
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.declare_parameter(
            'max_linear_speed', 0.5, speed_limit(0.0, 1.5, 'forward speed limit, m/s'))
        self.declare_parameter(
            'max_angular_speed', 1.0, speed_limit(0.0, 2.5, 'turn rate limit, rad/s'))
        self.declare_parameter('robot_name', 'tb3')
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.subscription = self.create_subscription(
            Twist, 'agent/cmd_vel', self.on_agent_command, 10)

    def on_set_parameters(self, params):
        # A descriptor cannot say "not empty", so robot_name is checked by hand.
        for param in params:
            if param.name == 'robot_name' and not param.value:
                return SetParametersResult(
                    successful=False, reason='robot_name must not be empty')
        return SetParametersResult(successful=True)

    def on_agent_command(self, wish):
        top = self.get_parameter('max_linear_speed').value
        turn = self.get_parameter('max_angular_speed').value
        command = Twist()
        command.linear.x = max(-top, min(top, wish.linear.x))
        command.angular.z = max(-turn, min(turn, wish.angular.z))
        self.publisher.publish(command)


def main(args=None):
    rclpy.init(args=args)
    try:
        node = VelocityGovernor()
    except ParameterException as error:
        # declare_parameter raises for an override outside the descriptor's range.
        rclpy.logging.get_logger('velocity_governor').error(f'refusing to start: {error}')
        rclpy.try_shutdown()
        return 1
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
