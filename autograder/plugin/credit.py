"""Partial credit and evidence: what a test attaches to its own entry in the report."""

from __future__ import annotations

import itertools

import pytest

from autograder.core.results import IntervalChart
from autograder.plugin.stash import credit_key, evidence_key


class Credit:
    """Partial credit for the running test: ``credit.award(fraction, message)``.

    A test that awards less than 1 and returns normally is reported as failed with
    ``fraction`` of its points and the message; without an award, pass/fail decides.
    """

    def __init__(self) -> None:
        self.fraction: float | None = None
        self.message = ""
        self.hint = ""

    def award(self, fraction: float, message: str = "", hint: str = "") -> None:
        self.fraction = min(1.0, max(0.0, fraction))
        self.message, self.hint = message, hint


class Evidence:
    """Data a test attaches for the report's pictures (e.g. message intervals)."""

    def __init__(self) -> None:
        self.charts: list[IntervalChart] = []

    def intervals(self, title: str, times: list[float], limit: float | None = None) -> None:
        """Plot the gaps between messages over simulation time (``limit``: the allowed gap)."""
        points = tuple((round(b, 3), round(b - a, 4)) for a, b in itertools.pairwise(times))
        # Rounded as the gaps are: a test's 0.15 + 1e-6 is drawn and labelled 0.15.
        self.charts.append(IntervalChart(title, points,
                                         None if limit is None else round(limit, 4)))


@pytest.fixture
def evidence(request: pytest.FixtureRequest) -> Evidence:
    """Attach data to this test's entry in the report (see :class:`Evidence`)."""
    given = Evidence()
    request.node.stash[evidence_key] = given
    return given


@pytest.fixture
def credit(request: pytest.FixtureRequest) -> Credit:
    """Give this test partial credit (see :class:`Credit`)."""
    given = Credit()
    request.node.stash[credit_key] = given
    return given
