"""A student's MultiThreadedExecutor under a fast ``/clock`` waits for work instead of
spinning (:func:`autograder.sandbox.contained.runner.calm_executors`).

Jazzy's executor keeps a subscription's QoS event handlers in its wait set while the
subscription's own message waits for a worker thread; they share the reader's status
condition with its data, so each wait returned at once, and the executor went round
hundreds of times for each ``/clock`` message (design.md, "A MultiThreadedExecutor that
does not spin").  The program counts its executor's rounds; the test is the world, sending
``/clock`` as a grading's world does for timer_sync (80 messages a second of wall time,
0.05 s of simulation time each).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from autograder.sandbox.contained.runner import command

rclpy = pytest.importorskip("rclpy")
from rclpy.node import Node  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

PROGRAM = """\
import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.parameter import Parameter


class Counting(MultiThreadedExecutor):
    rounds = 0

    def wait_for_ready_callbacks(self, *args, **kwargs):
        Counting.rounds += 1
        return super().wait_for_ready_callbacks(*args, **kwargs)


rclpy.init()
node = rclpy.create_node('spin_test', parameter_overrides=[
    Parameter('use_sim_time', Parameter.Type.BOOL, True)])
heard = []


def on_control():
    heard.append(node.get_clock().now().nanoseconds)
    if heard[-1] >= END_NS:
        print('rounds', Counting.rounds, 'ticks', len(heard), flush=True)
        rclpy.shutdown()


node.create_timer(0.1, on_control, callback_group=MutuallyExclusiveCallbackGroup())
executor = Counting(num_threads=4)
executor.add_node(node)
print('spinning', flush=True)
try:
    executor.spin()
except ExternalShutdownException:
    pass
"""
TICK_NS = 50_000_000  # simulation time a /clock message moves on
END_NS = 6_000_000_000  # the program reports and ends at 6 s of simulation time
RATE = 80.0  # /clock messages a second of wall time
WALL = 240.0  # seconds the program may take to start or to end, on a loaded machine


def test_a_multithreaded_executor_goes_round_a_few_times_a_clock_message(
        tmp_path: Path, ros_domain: int) -> None:
    script = tmp_path / "node.py"
    script.write_text(PROGRAM.replace("END_NS", str(END_NS)))
    output = tmp_path / "out.txt"
    env = {**os.environ, "ROS_DOMAIN_ID": str(ros_domain)}
    with output.open("w") as out:
        program = subprocess.Popen(command(sys.executable, str(script), []), stdout=out,
                                   stderr=subprocess.STDOUT, env=env)
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=ros_domain)
    world = Node("spin_test_world", context=context)
    try:
        clock = world.create_publisher(Clock, "/clock", 10)
        deadline = time.monotonic() + WALL
        while "spinning" not in output.read_text() or clock.get_subscription_count() == 0:
            assert program.poll() is None, output.read_text()
            assert time.monotonic() < deadline, "the program never subscribed to /clock"
            time.sleep(0.05)
        sent, now = 0, 0
        while program.poll() is None:
            assert time.monotonic() < deadline, output.read_text()
            now += TICK_NS
            message = Clock()
            message.clock.sec, message.clock.nanosec = divmod(now, 1_000_000_000)
            clock.publish(message)
            sent += 1
            time.sleep(1.0 / RATE)  # the world's pace, as a grading's world sends /clock
    finally:
        if program.poll() is None:
            program.kill()
        program.wait()
        world.destroy_node()
        rclpy.shutdown(context=context)
    report = output.read_text()
    words = report.split()
    assert "rounds" in words, report
    rounds = int(words[words.index("rounds") + 1])
    # A round per callback it hands out, and one or two wakes as each starts and ends: a
    # few per message.  Spinning, it went round hundreds of times for each.
    assert rounds < 10 * sent, (rounds, sent, report)
