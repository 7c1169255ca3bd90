"""A probe wait judged on what was sent in simulation time, not on how soon the probe's own
executor got round to it: the world waits for the student's node, not for the probe."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node
from std_msgs.msg import String

from autograder.plugin.probe import Probe
from sim.bridge import SimBridge
from sim.physics import World
from sim.worldfile import load_world

WALL = 20.0
BUSY = 0.6  # wall seconds the probe's executor is kept busy: many times the wait below


@pytest.fixture
def graph(ros_domain: int) -> Iterator[tuple[SimBridge, Probe, Node]]:
    context = Context()
    rclpy.init(context=context, domain_id=ros_domain)
    world = SimBridge(World(load_world("empty_room")), context, real_time_factor=4.0)
    probe = Probe(context, world)
    sender = Node("sender", context=context)
    world.start()
    try:
        yield world, probe, sender
    finally:
        probe.close()
        sender.destroy_node()
        world.stop()
        rclpy.try_shutdown(context=context)


def test_a_message_sent_in_time_counts_though_the_probe_took_it_late(graph) -> None:
    """The probe's executor is busy (a callback of its own spins for BUSY wall seconds)
    when a message it waits for is sent; the wait's 0.1 s of simulation time, 25 ms of
    wall time at 4x, runs out long before the executor is free. The message was sent
    before the wait began, so the wait is true."""
    world, probe, sender = graph
    started = threading.Event()

    def spin(_message: String) -> None:
        started.set()
        end = time.monotonic() + BUSY
        while time.monotonic() < end:
            pass

    probe.node.create_subscription(String, "/hog", spin, 10)
    pings = probe.subscribe(String, "/ping")
    hog, ping = (sender.create_publisher(String, topic, 10) for topic in ("/hog", "/ping"))
    assert probe.wait_for(lambda: hog.get_subscription_count() > 0
                          and ping.get_subscription_count() > 0, 5.0)
    hog.publish(String(data="spin"))
    assert started.wait(WALL)
    ping.publish(String(data="in time"))
    assert probe.wait_for(lambda: len(pings) > 0, 0.1)
    assert pings.messages[0].data == "in time"


def test_a_wait_for_what_never_comes_still_ends_false(graph) -> None:
    world, probe, _sender = graph
    pings = probe.subscribe(String, "/ping")
    start = world.now
    assert not probe.wait_for(lambda: len(pings) > 0, 0.5)
    assert world.now >= start + 0.5
