"""Fixtures shared by the timer_sync tests: the node's three streams and one run."""

import sys
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist
from std_msgs.msg import String

sys.path.insert(0, str(Path(__file__).parent))

from helpers import Streams, observe


@pytest.fixture(scope="module")
def streams(probe, student):
    """cmd_vel, status and plan, each stamped with the sim time it was published at."""
    started = student.appeared_at if student.appeared_at is not None else probe.now
    return Streams(started=started,
                   commands=probe.subscribe(Twist, "/cmd_vel", stamp="published"),
                   statuses=probe.subscribe(String, "/status", stamp="published"),
                   plans=probe.subscribe(String, "/plan", stamp="published"))


@pytest.fixture(scope="module")
def run(probe, world, streams):
    """Watched once per module, 12.25 s of simulation time from the node's start: to 11.75 s at
    the world's pace, then at half real time (helpers.SWITCH_AT, END_AT)."""
    return observe(probe, world, streams)
