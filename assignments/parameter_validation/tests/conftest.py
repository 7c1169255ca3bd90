"""Fixtures shared by the public and hidden tests of parameter_validation."""

import sys
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist

sys.path.insert(0, str(Path(__file__).parent))


@pytest.fixture(scope="module")
def commands(probe, student):
    """What the student's node publishes on cmd_vel, from the start of the module."""
    return probe.subscribe(Twist, "/cmd_vel")
