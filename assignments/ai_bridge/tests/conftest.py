"""Fixtures shared by the public and hidden tests of ai_bridge."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from helpers import Mission, fly


@pytest.fixture(scope="module")
def mission(request, world, probe, student) -> Mission:
    """The agent's run to this module's goal: until it stops there, collides, dies or the
    module's LIMIT (simulation seconds) passes."""
    return fly(world, probe, student, request.module.LIMIT)
