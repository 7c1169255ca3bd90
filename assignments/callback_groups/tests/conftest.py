"""Fixtures shared by the callback_groups tests: the scans and rate reports as they came."""

import sys
from pathlib import Path

import pytest
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float32

sys.path.insert(0, str(Path(__file__).parent))

from helpers import Requests


@pytest.fixture(scope="module")
def scans(probe, world):
    """Every /scan of the module's world, stamped with the sim time it was published at."""
    return probe.subscribe(LaserScan, "/scan", stamp="published")


@pytest.fixture(scope="module")
def rates(probe, student):
    """What the node publishes on scans_per_second, stamped when it was published."""
    return probe.subscribe(Float32, "/scans_per_second", stamp="published")


@pytest.fixture(scope="module")
def alive(probe, student, rates):
    """Whether the node runs callbacks at all: a rate report in 3 s, or else an answer.

    A node that does neither (an executor that never runs a callback) fails the first
    test; the others are skipped instead of each waiting out its own deadline.
    """
    if probe.wait_for(lambda: len(rates) > 0, 3.0):
        return True
    requests = Requests(probe)
    try:
        if not requests.ready(2.0):
            return False
        return requests.wait([requests.send()], 2.0)
    finally:
        requests.close()
