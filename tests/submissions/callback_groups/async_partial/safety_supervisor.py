"""Safety supervisor without a Node subclass: the README's async def design on one thread.

Tier A: simulation. Written from the README alone. Each request awaits a Future that the
next scan completes, or a one-shot timer after 1.0 s of ROS time; the service has a
ReentrantCallbackGroup of its own, so an awaiting request holds back neither the scan
callback nor /clock.
"""
import math
import sys
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.task import Future
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float32
from std_srvs.srv import Trigger


@dataclass(frozen=True)
class Config:
    sector: float = math.radians(30.0)
    clearance: float = 0.5
    wait: float = 1.0


@dataclass
class State:
    waiting: list = field(default_factory=list)   # futures of requests awaiting a scan
    counted: int = 0


def nearest_ahead(scan, config):
    ranges = np.asarray(scan.ranges, dtype=float)
    angles = scan.angle_min + np.arange(len(ranges)) * scan.angle_increment
    angles = np.arctan2(np.sin(angles), np.cos(angles))
    ok = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    ahead = ranges[ok & (np.abs(angles) <= config.sector + 1e-9)]
    return float(ahead.min()) if ahead.size else None


def on_scan(state, scan):
    state.counted += 1
    waiting, state.waiting = state.waiting, []
    for future in waiting:
        if not future.done():
            future.set_result(scan)


def on_rate(state, publisher):
    publisher.publish(Float32(data=float(state.counted)))
    state.counted = 0


async def on_check(node, state, config, request, response):
    fresh = Future()
    state.waiting.append(fresh)
    timer = None

    def give_up():
        timer.cancel()
        if not fresh.done():
            fresh.set_result(None)

    timer = node.create_timer(config.wait, give_up)
    scan = await fresh
    timer.cancel()
    node.destroy_timer(timer)
    if scan is None:
        response.success, response.message = False, f'no fresh scan within {config.wait} s'
        return response
    nearest = nearest_ahead(scan, config)
    response.success = nearest is None or nearest >= config.clearance
    response.message = ('no obstacle ahead within range' if nearest is None
                        else f'nearest obstacle ahead: {nearest:.2f} m')
    return response


def main(args=None):
    rclpy.init(args=args)
    node = rclpy.create_node('safety_supervisor')
    config, state = Config(), State()
    node.create_subscription(LaserScan, 'scan', partial(on_scan, state), 10)
    publisher = node.create_publisher(Float32, 'scans_per_second', 10)
    node.create_timer(1.0, partial(on_rate, state, publisher))
    node.create_service(Trigger, 'check_path', partial(on_check, node, state, config),
                        callback_group=ReentrantCallbackGroup())
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
