"""The callback_groups exercise proves its tests: every submission graded end to end.

The reference solution is the chapter's design (a MultiThreadedExecutor; the service in
a callback group of its own waits on a condition that the scan callback, in another
group, notifies) and scores 100% five times, with other gradings running beside it; the
starter scores below the pass mark; other correct designs (requests served one at a
time, an awaited future on one thread) score 100%; each known-bad variant loses exactly
the tests its expect.yaml names, and a node spinning Jazzy's EventsExecutor (which runs
no callback, burns a core and ignores SIGINT) still ends with a score.
"""

from __future__ import annotations

import pytest
from designs import read_design
from proving import Proof, diagnosis, explain

from autograder.core.exercise import find_exercise
from autograder.render.html import to_html

pytestmark = pytest.mark.slow

# The submissions and what each must lose: tests/submissions/callback_groups/*/.
# Gradings here wait on simulation time at real-time pace, not on the CPU: five at a time
# (measured: six in parallel beside a busy loop kept every 10 Hz beat).
PROOF = Proof("callback_groups", jobs=5)


def departures_from_the_chapter(source: str) -> list[str]:
    """How a safety supervisor departs from the chapter's design (nothing: it is it)."""
    design = read_design(source)
    service = design.entity("create_service", "'check_path'")
    scan = design.entity("create_subscription", "'scan'")
    found = []
    if not design.spins_multithreaded():
        found.append("not spun by a MultiThreadedExecutor")
    if not design.alone_in_its_group(service):
        found.append("the service is not in a callback group of its own")
    if scan.group not in design.groups or scan.group == service.group:
        found.append("the scan callback is not in another group of the node's")
    if not any(design.calls(service.callback, "wait", c)
               and (design.calls(scan.callback, "notify_all", c)
                    or design.calls(scan.callback, "notify", c))
               for c in design.made_as("Condition")):
        found.append("the service does not wait on a condition the scan callback notifies")
    return found


def test_chapter_design_is_the_reference(graded, proof):
    """The reference, which must score 100% every time, is the chapter's own design."""
    assert graded["reference#0"].max_score == 13
    assert all(graded[f"reference#{i}"].score == 13 for i in range(proof.repeats)), explain(
        runs=[diagnosis(graded[f"reference#{i}"]) for i in range(proof.repeats)])
    exercise = find_exercise("callback_groups")
    assert departures_from_the_chapter(exercise.solution.read_text()) == []
    # The check tells the design from others: each departs from it in its own way.
    departures = {name: departures_from_the_chapter(v.program(exercise))
                  for name, v in proof.variants.items()}
    assert departures["shared_group"] == [
        "the service is not in a callback group of its own",
        "the scan callback is not in another group of the node's"]
    assert departures["events_executor"] == ["not spun by a MultiThreadedExecutor"]
    assert departures["old_scan"] == [
        "the service does not wait on a condition the scan callback notifies"]
    assert "not spun by a MultiThreadedExecutor" in departures["deadlock"]
    assert "not spun by a MultiThreadedExecutor" in departures["async_future"]
    assert departures["serial_service"] == []  # the chapter's design, one request at a time


def test_events_executor_ends_with_a_score_and_a_reason(graded):
    """It spins a core without running a callback and ignores SIGINT: stopped, scored,
    explained (the world slows to its CPU budget per tick, so its waits end on the wall)."""
    result = graded["events_executor"]
    assert result.grader_error is None and not result.timed_out
    assert result.score == 0
    assert all(t.status in ("failed", "skipped") and t.message for t in result.tests)
    assert result.execution_time < find_exercise("callback_groups").time_limit / 2


def test_old_scan_is_told_why(graded):
    result = graded["old_scan"]
    by_name = {t.name: t for t in result.tests}
    assert "before any scan newer than the request existed" in \
        by_name["test_answer_uses_newer_scan"].message


def test_report_plots_the_scan_rate_reports(graded):
    """The rate tests attach the intervals of scans_per_second they read (about 1 s)."""
    result = graded["reference#0"]
    charts = {t.name: t.charts for t in result.tests}
    for name in ("test_scan_rate", "test_concurrent_requests", "test_never_deadlocks"):
        (chart,) = charts[name]
        assert chart.title == "scans_per_second" and chart.points, name
        assert all(0.5 <= gap <= 1.5 for _t, gap in chart.points), (name, chart)
    page = to_html(result, find_exercise("callback_groups").folder)
    assert page.count('class="chart"') == 3
