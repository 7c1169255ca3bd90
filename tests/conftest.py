"""Fixtures shared by the project's tests."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest

from autograder.domains import reserve_domain


@pytest.fixture(scope="module")
def ros_domain() -> Iterator[int]:
    """A ROS domain id reserved for this module (the same lock files the grader uses)."""
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    with reserve_domain() as domain:
        yield domain
