"""Fixtures shared by the public and hidden tests of error_handling."""

import sys
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist

sys.path.insert(0, str(Path(__file__).parent))


@pytest.fixture(scope="module")
def commands(probe):
    """Everything published on cmd_vel in this module, stamped with simulation time."""
    return probe.subscribe(Twist, "/cmd_vel", stamp="published")
