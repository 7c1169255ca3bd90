"""The timer_sync exercise proves its tests: every submission graded end to end.

The reference solution is the chapter's design (a MultiThreadedExecutor, the planner
timer in a callback group of its own) and scores 100% five times, with other gradings
running beside it; the starter scores below the pass mark; other correct designs (a
worker thread, an awaited future, one reentrant group) score 100%; each known-bad variant
loses exactly the tests its expect.yaml names.  Gradings run seven at a time.
"""

from __future__ import annotations

import pytest
from proving import Proof

pytestmark = pytest.mark.slow

# The submissions and what each must lose: tests/submissions/timer_sync/*/.
# Gradings here wait on simulation time at real-time pace, not on the CPU: seven at a
# time, two waves for the fourteen (measured: six in parallel beside a busy loop kept
# every 10 Hz beat, and seven at a time passed this proof).
PROOF = Proof("timer_sync", jobs=7)


def test_chapter_design_is_the_reference(graded):
    """The reference, which must score 100% every time, is the chapter's own design."""
    assert graded["reference#0"].max_score == 14


def test_frozen_clock_is_explained(graded):
    """A single-threaded node freezes ROS time; the message says so and names the fix."""
    result = graded["single_threaded"]
    by_name = {t.name: t for t in result.tests}
    test = by_name["test_control_rate"]
    assert "stopped" in test.message
    assert "/clock" in test.hint and "MultiThreadedExecutor" in test.hint
