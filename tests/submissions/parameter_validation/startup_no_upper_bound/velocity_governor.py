"""One flaw: the starting values are checked only against the lower bound.

Class-less, functools.partial callbacks. On set every bound is checked; at start an
override above the range (max_linear_speed:=3.0) is let through.
"""
import sys
from dataclasses import dataclass, replace
from functools import partial

import rclpy
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException

RANGES = {'max_linear_speed': (0.0, 1.5), 'max_angular_speed': (0.0, 2.5)}


@dataclass(frozen=True)
class Limits:
    max_linear_speed: float = 0.5
    max_angular_speed: float = 1.0
    robot_name: str = 'tb3'


def problem(name, value):
    """Why ``value`` is not acceptable for ``name`` ('' when it is)."""
    if name in RANGES:
        low, high = RANGES[name]
        if not low <= value <= high:
            return f'{name} must be within [{low}, {high}], got {value}'
    if name == 'robot_name' and value == '':
        return 'robot_name must not be empty'
    return ''


def on_set(state, params):
    for p in params:
        reason = problem(p.name, p.value)
        if reason:
            return SetParametersResult(successful=False, reason=reason)
    state['limits'] = replace(state['limits'], **{p.name: p.value for p in params
                                                   if p.name in Limits.__dataclass_fields__})
    return SetParametersResult(successful=True)


def clamp(value, limit):
    return max(-limit, min(limit, value))


def on_agent(state, publisher, msg):
    limits = state['limits']
    out = Twist()  # every field zero but the two a differential drive can follow
    out.linear.x = clamp(msg.linear.x, limits.max_linear_speed)
    out.angular.z = clamp(msg.angular.z, limits.max_angular_speed)
    publisher.publish(out)


def main(args=None):
    rclpy.init(args=args)
    node = rclpy.create_node('velocity_governor')
    defaults = Limits()
    start = {name: node.declare_parameter(name, getattr(defaults, name)).value
             for name in ('max_linear_speed', 'max_angular_speed', 'robot_name')}
    # -p overrides were applied by declare_parameter: check them here, no callback saw them.
    for name, value in start.items():
        low = RANGES.get(name, (None,))[0]
        reason = (f'{name} must be at least {low}, got {value}'
                  if low is not None and value < low else
                  problem(name, value) if name == 'robot_name' else '')
        if reason:
            node.get_logger().error(f'invalid starting value: {reason}')
            node.destroy_node()
            rclpy.try_shutdown()
            return 1
    state = {'limits': Limits(**start)}
    node.add_on_set_parameters_callback(partial(on_set, state))
    publisher = node.create_publisher(Twist, 'cmd_vel', 10)
    node.create_subscription(Twist, 'agent/cmd_vel', partial(on_agent, state, publisher), 10)
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
