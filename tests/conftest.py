"""Fixtures shared by the project's tests."""

from __future__ import annotations

import os
from collections.abc import Iterator
from typing import Any

import pytest

from autograder.sandbox.domains import reserve_domain


@pytest.fixture(scope="module")
def ros_domain() -> Iterator[int]:
    """A ROS domain id reserved for this module (the same lock files the grader uses)."""
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    with reserve_domain() as domain:
        yield domain


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """Parametrize the standard proof checks (tests/proving.py) from the module's PROOF."""
    proof = getattr(metafunc.module, "PROOF", None)
    if proof is None:
        return
    if "correct" in metafunc.fixturenames:
        metafunc.parametrize("correct", list(proof.correct))
    if "mutant" in metafunc.fixturenames:
        metafunc.parametrize("mutant", list(proof.mutants))


@pytest.fixture(scope="module")
def proof(request: pytest.FixtureRequest) -> Any:
    """The module's PROOF (tests/proving.py)."""
    return request.module.PROOF


@pytest.fixture(scope="module")
def graded(proof: Any) -> dict[str, Any]:
    """Every submission of the module's PROOF, graded once for all its checks."""
    return proof.grade_all()
