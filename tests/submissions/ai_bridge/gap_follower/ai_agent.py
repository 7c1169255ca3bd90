"""AI agent without a timer callback: an asyncio loop steps a gap-following agent.

Tier A: simulation. Written from the README alone. The agent is a pure function of an
observation (pose, goal, scan as NumPy arrays); the node's asyncio task runs it at 10 Hz
of ROS time while a thread spins rclpy.
"""
import asyncio
import math
import sys
import threading
from dataclasses import dataclass

import numpy as np
import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String

RADIUS = 0.105
CLEARANCE = RADIUS + 0.12   # a corridor half as wide again as the robot
LOOKAHEAD = 0.9             # metres of free way a heading needs to be chosen
REACHED = 0.2


@dataclass(frozen=True)
class Observation:
    x: float
    y: float
    yaw: float
    speed: float
    goal: tuple[float, float]
    angles: np.ndarray   # beam angles in the robot frame, wrapped to [-pi, pi]
    ranges: np.ndarray   # metres; inf where nothing valid


def free_way(obs: Observation, heading: float) -> float:
    """How far the robot could drive along ``heading`` (robot frame) before touching."""
    rel = np.arctan2(np.sin(obs.angles - heading), np.cos(obs.angles - heading))
    along = obs.ranges * np.cos(rel)
    across = np.abs(obs.ranges * np.sin(rel))
    blocking = (along > 0) & (across < CLEARANCE)
    return float(along[blocking].min()) if blocking.any() else math.inf


def act(obs: Observation) -> tuple[float, float, bool]:
    """(linear, angular, arrived): head for the free heading nearest the goal's."""
    dx, dy = obs.goal[0] - obs.x, obs.goal[1] - obs.y
    distance = math.hypot(dx, dy)
    if distance < REACHED:
        return 0.0, 0.0, abs(obs.speed) < 0.01
    to_goal = math.atan2(math.sin(math.atan2(dy, dx) - obs.yaw),
                         math.cos(math.atan2(dy, dx) - obs.yaw))
    candidates = sorted(np.radians(np.arange(-180, 180, 5)), key=lambda h: abs(
        math.atan2(math.sin(h - to_goal), math.cos(h - to_goal))))
    need = min(LOOKAHEAD, distance)
    heading = next((h for h in candidates if free_way(obs, h) >= need), None)
    if heading is None:
        return 0.0, 0.8, False  # boxed in: turn on the spot until a way opens
    ahead = free_way(obs, 0.0)
    turn = max(-1.5, min(1.5, 2.0 * heading))
    linear = 0.0 if abs(heading) > math.radians(40) or ahead < CLEARANCE else \
        min(0.35, 0.6 * distance, 0.5 * (ahead - RADIUS))
    return max(0.0, linear), turn, False


class Bridge:
    """Keeps the latest odometry and scan; everything ROS stays here."""

    def __init__(self, node):
        self.node = node
        self.odom = None
        self.scan = None
        node.create_subscription(Odometry, 'odom', self._on_odom, 10)
        node.create_subscription(LaserScan, 'scan', self._on_scan, 10)
        self.cmd = node.create_publisher(Twist, 'cmd_vel', 10)
        self.status = node.create_publisher(String, 'agent_status', 10)
        self.goal = (node.declare_parameter('goal_x', 0.0).value,
                     node.declare_parameter('goal_y', 0.0).value)

    def _on_odom(self, msg):
        self.odom = msg

    def _on_scan(self, msg):
        self.scan = msg

    def observation(self):
        odom, scan = self.odom, self.scan
        if odom is None or scan is None:
            return None
        q = odom.pose.pose.orientation
        ranges = np.asarray(scan.ranges, dtype=float)
        angles = scan.angle_min + np.arange(len(ranges)) * scan.angle_increment
        valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
        return Observation(odom.pose.pose.position.x, odom.pose.pose.position.y,
                           2 * math.atan2(q.z, q.w), odom.twist.twist.linear.x, self.goal,
                           np.arctan2(np.sin(angles), np.cos(angles)),
                           np.where(valid, ranges, np.inf))

    def drive(self, linear, angular):
        msg = Twist()
        msg.linear.x, msg.angular.z = float(linear), float(angular)
        self.cmd.publish(msg)


async def run(bridge: Bridge, stop: threading.Event):
    """The agent's loop: one step per 0.1 s of ROS time, until arrival is reported."""
    clock = bridge.node.get_clock()
    reported = False
    next_step = clock.now().nanoseconds
    while not stop.is_set():
        while clock.now().nanoseconds < next_step and not stop.is_set():
            await asyncio.sleep(0.005)
        next_step += 100_000_000
        obs = bridge.observation()
        if obs is None:
            continue
        linear, angular, arrived = act(obs)
        bridge.drive(linear, angular)
        if arrived and not reported:
            bridge.status.publish(String(data='goal reached'))
            reported = True


def main(args=None):
    rclpy.init(args=args)
    node = rclpy.create_node('ai_agent')
    bridge = Bridge(node)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    stop = threading.Event()
    spinner = threading.Thread(target=lambda: _spin(executor, stop), daemon=True)
    spinner.start()
    try:
        asyncio.run(run(bridge, stop))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        stop.set()
        bridge.drive(0.0, 0.0)
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


def _spin(executor, stop):
    try:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


if __name__ == '__main__':
    sys.exit(main())
