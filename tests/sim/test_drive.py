"""``sim drive`` on a real graph: it drives the world's robot for its seconds of simulation
time and then stops it, and publishes TwistStamped stamped in simulation time."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest
import rclpy
from click.testing import CliRunner
from geometry_msgs.msg import TwistStamped
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from sim.bridge import SimBridge
from sim.cli import sim_cli
from sim.physics import World
from sim.worldfile import load_world

WALL = 30.0  # generous wall-clock deadline for any one condition
RTF = 2.0


@pytest.fixture(scope="module")
def context(ros_domain: int) -> Iterator[Context]:
    ctx = Context()
    rclpy.init(context=ctx, domain_id=ros_domain)
    yield ctx
    rclpy.try_shutdown(context=ctx)


@pytest.fixture(scope="module")
def bridge(context: Context) -> Iterator[SimBridge]:
    world = SimBridge(World(load_world("empty_room")), context, real_time_factor=RTF)
    world.start()
    yield world
    world.stop()


def drive(domain: int, *args: str) -> str:
    result = CliRunner().invoke(sim_cli, ["drive", "--domain", str(domain), *args])
    assert result.exit_code == 0, result.output
    return result.output


def test_drives_the_robot_for_its_seconds_then_stops_it(bridge: SimBridge,
                                                        ros_domain: int) -> None:
    start = bridge.now
    output = drive(ros_domain, "--linear", "0.3", "--angular", "0.5", "--for", "2")
    assert "in simulation time" in output
    assert bridge.wait_until(bridge.now + 1.0, WALL)  # the zero command has taken hold
    samples = [s for s in bridge.recording.snapshot()[0] if s.t > start]
    moving = [s for s in samples if abs(s.v) > 1e-6]
    assert moving, "the robot never moved"
    assert max(s.v for s in moving) == pytest.approx(0.3, rel=1e-3)
    assert max(s.w for s in moving) == pytest.approx(0.5, rel=1e-3)
    # Two seconds of simulation time at 0.3 m/s, give or take a clock tick at each end.
    span = moving[-1].t - moving[0].t
    assert 1.8 <= span <= 2.3, span
    assert samples[-1].v == 0.0 and samples[-1].w == 0.0
    assert bridge.world.command == (0.0, 0.0)


class Listener:
    """A node that keeps the TwistStamped messages of one topic."""

    def __init__(self, context: Context, topic: str) -> None:
        self.node = Node("drive_listener", context=context)
        self.messages: list[TwistStamped] = []
        self.node.create_subscription(TwistStamped, topic, self.messages.append, 100)
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()


def test_stamped_commands_carry_simulation_time(bridge: SimBridge, context: Context,
                                                ros_domain: int) -> None:
    listener = Listener(context, "/stamped_cmd")
    try:
        start = bridge.now
        drive(ros_domain, "--topic", "/stamped_cmd", "--stamped", "--linear", "0.2",
              "--for", "1", "--rate", "5")
        end = bridge.now
        # Acknowledged is not yet handed to the listener's callback: wait for that.
        assert bridge.wait_for(lambda: any(m.twist.linear.x == 0.0 for m in listener.messages),
                               sim_timeout=5.0, wall_timeout=WALL)
        messages = list(listener.messages)
    finally:
        listener.close()
    stamps = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in messages]
    assert len(messages) >= 5
    assert all(start <= t <= end for t in stamps), (start, stamps, end)
    assert stamps == sorted(stamps)
    assert {m.header.frame_id for m in messages} == {"base_link"}
    assert [m.twist.linear.x for m in messages[:-1]] == [pytest.approx(0.2)] * (
        len(messages) - 1)
    assert messages[-1].twist.linear.x == 0.0  # it ends with a zero command


def test_keys_need_a_terminal() -> None:
    result = CliRunner().invoke(sim_cli, ["drive", "--keys"], input="w")
    assert result.exit_code == 2
    assert "--keys needs a terminal" in result.output
