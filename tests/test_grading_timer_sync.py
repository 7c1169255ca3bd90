"""The timer_sync exercise proves its tests: every submission graded end to end.

The reference solution is the chapter's design (a MultiThreadedExecutor, the planner
timer in a callback group of its own) and scores 100% five times, with other gradings
running beside it; the starter scores below the pass mark; other correct designs (a
worker thread, an awaited future, one reentrant group) score 100%; each known-bad variant
loses exactly the tests its expect.yaml names.  Gradings run seven at a time.
"""

from __future__ import annotations

import re

import pytest
from designs import read_design
from proving import Proof, diagnosis, explain, without_both_types

from autograder.core.exercise import find_exercise
from autograder.render.html import to_html

pytestmark = pytest.mark.slow

# The submissions and what each must lose: tests/submissions/timer_sync/*/.
# Gradings here wait on simulation time (at twice real time), not on the CPU: seven at a
# time, two waves for the fourteen (measured: six in parallel beside a busy loop kept
# every 10 Hz beat, and seven at a time passed this proof).
PROOF = Proof("timer_sync", jobs=7)


def departures_from_the_chapter(source: str) -> list[str]:
    """How a multi-rate controller departs from the chapter's design (nothing: it is it)."""
    design = read_design(source)
    planner = design.entity("create_timer", "10.0")  # the 0.1 Hz timer
    found = []
    if not design.calls(planner.callback, "plan_route", "self"):
        found.append("the 0.1 Hz timer does not run the slow planner")
    if not design.spins_multithreaded():
        found.append("not spun by a MultiThreadedExecutor")
    if not design.alone_in_its_group(planner):
        found.append("the planner is not in a callback group of its own")
    return found


def test_chapter_design_is_the_reference(graded, proof):
    """The reference, which must score 100% every time, is the chapter's own design."""
    assert graded["reference#0"].max_score == 14
    assert all(graded[f"reference#{i}"].score == 14 for i in range(proof.repeats)), explain(
        runs=[diagnosis(graded[f"reference#{i}"]) for i in range(proof.repeats)])
    exercise = find_exercise("timer_sync")
    assert departures_from_the_chapter(exercise.solution.read_text()) == []
    # The check tells the design from others: each departs from it in its own way. (Only
    # these are read: a design made some other way, e.g. its timers in a loop over a
    # table as the blind corpus's partial_groups, is not the check's to parse.)
    departures = {name: departures_from_the_chapter(proof.variants[name].program(exercise))
                  for name in ("shared_group", "single_threaded", "reentrant_lock",
                               "worker_thread")}
    assert departures["shared_group"] == ["the planner is not in a callback group of its own"]
    assert departures["single_threaded"] == [
        "not spun by a MultiThreadedExecutor",
        "the planner is not in a callback group of its own"]
    assert departures["reentrant_lock"] == [
        "the planner is not in a callback group of its own"]
    assert "not spun by a MultiThreadedExecutor" in departures["worker_thread"]


def test_frozen_clock_is_explained(graded):
    """A single-threaded node freezes ROS time; the message says so and names the fix."""
    result = graded["single_threaded"]
    by_name = {t.name: t for t in result.tests}
    test = by_name["test_control_rate"]
    assert "stopped" in test.message
    assert "/clock" in test.hint and "MultiThreadedExecutor" in test.hint


def test_a_twist_stamped_node_is_told_both_types(graded):
    """The reference solution publishing TwistStamped, as for Jazzy's TurtleBot3: every test
    it loses says what it sent and what this exercise's robot takes."""
    assert without_both_types(graded["twist_stamped"]) == {}


def test_report_plots_the_intervals_each_rate_test_measured(graded):
    """The report shows the message-interval plots README promises for rate tests, and
    the robot's runs in the long hall as one replayable picture."""
    result = graded["reference#0"]
    charts = {t.name: t.charts for t in result.tests}
    (control,) = charts["test_control_rate"]
    assert control.title == "cmd_vel"
    assert control.limit == pytest.approx(0.15)  # the largest gap allowed
    assert len(control.points) > 100  # 12 s at 10 Hz, less what discovery took
    assert all(gap <= control.limit for _t, gap in control.points)  # the reference keeps it
    assert len(charts["test_control_while_planning"]) == 1  # one per planner run
    for name in ("test_status_rate", "test_plan_rate", "test_rates_at_half_speed"):
        assert [len(c.points) > 0 for c in charts[name]] == [True], name
    page = to_html(result, find_exercise("timer_sync").folder)
    assert page.count('<svg xmlns="http://www.w3.org/2000/svg" class="chart"') == sum(
        len(c) for c in charts.values())
    (hall,) = re.findall(r'<figure class="world">.*?</figure>', page, re.S)
    assert "test_controller.py" in hall and 'class="replay-data"' in hall
