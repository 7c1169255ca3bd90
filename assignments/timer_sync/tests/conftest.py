"""Fixtures shared by the timer_sync tests: the node's three streams and one long run."""

import sys
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist
from std_msgs.msg import String

sys.path.insert(0, str(Path(__file__).parent))

from helpers import Streams, observe  # noqa: E402


@pytest.fixture(scope="module")
def streams(probe, student):
    """cmd_vel, status and plan, each stamped with the sim time it was published at."""
    return Streams(commands=probe.subscribe(Twist, "/cmd_vel", stamp="published"),
                   statuses=probe.subscribe(String, "/status", stamp="published"),
                   plans=probe.subscribe(String, "/plan", stamp="published"))


@pytest.fixture(scope="module")
def run(probe, world, streams):
    """30 s of simulation time watched once per module: 20 s at RTF 1, then 10 s at 0.5."""
    return observe(probe, world, streams)
