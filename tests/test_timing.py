"""Where a grading's wall seconds and memory go: the accumulation (fast, with given
numbers) and one grading of parameter_validation's reference whose results file says it."""

from __future__ import annotations

import resource
import threading

import pytest

from autograder.plugin.timing import PHASES, Timing, module_of

MODULE = "tests/test_a.py"


def test_phases_sum_and_checks_is_the_rest() -> None:
    timing = Timing()
    timing.add(MODULE, "total", 10.0)
    timing.add(MODULE, "world_start", 1.0)
    timing.add(MODULE, "node_start", 0.5)
    timing.waited(MODULE, 4.0, 1.5)  # 1.5 s of the wait held for a busy process
    timing.waited(MODULE, 1.0, 0.0)
    assert timing.to_dict() == {MODULE: {
        "world_start": 1.0, "node_start": 0.5, "sim_wait": 3.5, "busy_hold": 1.5,
        "checks": 3.5, "total": 10.0}}


def test_a_hold_longer_than_its_wait_counts_the_wait_only() -> None:
    """A hold that began before the wait adds to the pacer's sum during it: the wait is
    all hold, no more."""
    timing = Timing()
    timing.add(MODULE, "total", 3.0)
    timing.waited(MODULE, 0.5, 2.0)
    row = timing.to_dict()[MODULE]
    assert (row["sim_wait"], row["busy_hold"], row["checks"]) == (0.0, 0.5, 2.5)


def test_waits_inside_a_phase_belong_to_it() -> None:
    """A node start waits on the world (held): that wait is node start, not sim wait."""
    timing = Timing()
    with timing.phase(MODULE, "node_start"):
        timing.waited(MODULE, 2.0, 0.0)
        with timing.phase(MODULE, "world_start"):  # nested: the outer phase owns it
            pass
    row = timing.to_dict()[MODULE]
    assert row["sim_wait"] == 0.0 and row["world_start"] == 0.0
    assert row["node_start"] >= 0.0
    timing.waited(MODULE, 2.0, 0.0)  # after the phase: a wait again
    assert timing.to_dict()[MODULE]["sim_wait"] == 2.0


def test_checks_never_negative() -> None:
    timing = Timing()
    timing.add(MODULE, "world_start", 2.0)
    timing.add(MODULE, "total", 1.0)
    assert timing.to_dict()[MODULE]["checks"] == 0.0


def test_threads_add_without_losing_any() -> None:
    timing = Timing()

    def add() -> None:
        for _ in range(1000):
            timing.waited(MODULE, 0.001, 0.0)

    threads = [threading.Thread(target=add) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert timing.to_dict()[MODULE]["sim_wait"] == pytest.approx(4.0)


def test_module_of_a_node_id() -> None:
    assert module_of("tests/test_a.py::test_b[1]") == MODULE
    assert module_of(MODULE) == MODULE


@pytest.mark.slow
def test_a_grading_says_where_its_seconds_and_memory_went() -> None:
    from autograder.core.exercise import find_exercise
    from autograder.grading.run import grade

    # One child, so its tests' seconds add up within the total (children at once
    # overlap: tests/test_modules.py).
    result = grade(find_exercise("parameter_validation"), None, module_jobs=1)
    assert result.grader_error is None, result.grader_details
    data = result.to_dict()
    timing, memory = data["timing"], data["memory"]
    modules = {t.nodeid.split("::")[0] for t in result.tests}
    assert set(timing["modules"]) == modules
    for row in timing["modules"].values():
        assert all(row[key] >= 0 for key in (*PHASES, "checks", "total"))
        assert sum(row[key] for key in (*PHASES, "checks")) <= row["total"] + 0.005
        assert row["world_start"] > 0 and row["total"] > 0
    assert any(row["node_start"] > 0 for row in timing["modules"].values())
    assert 0 < timing["child_start"] and timing["tests"] <= timing["total"]
    assert timing["child_start"] + timing["tests"] <= timing["total"]
    assert memory["grader_mb"] > 0 and memory["student_mb"] > 0
    assert memory["total_mb"] == pytest.approx(memory["grader_mb"] + memory["student_mb"])
    # The tree's PSS: this process, the child and a student at a time, each counting at
    # most its resident size (PSS divides the pages it shares), so under their peaks.
    own_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    assert 0 < memory["footprint_mb"] <= memory["total_mb"] + own_mb
