"""The same submission gets the same score every time, also with both cores kept busy;
gradings at the same time each hold a ROS domain of their own."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import modes_kept

from autograder.core.exercise import find_exercise
from autograder.grading.run import grade
from autograder.sandbox.isolation import protected_paths

pytestmark = pytest.mark.slow

COURSE = Path(__file__).parents[1] / "fixtures" / "mini_course"
RUNS = 6


@pytest.fixture
def shout(monkeypatch):
    monkeypatch.setenv("AUTOGRADER_COURSE", str(COURSE))
    return find_exercise("shout")


@pytest.fixture
def busy_cores():
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"])
            for _ in range(os.cpu_count() or 2)]
    yield
    for hog in hogs:
        hog.kill()
        hog.wait()


def test_same_score_every_time_under_load(shout, busy_cores):
    results = [grade(shout, None) for _ in range(RUNS)]
    assert {r.grader_error for r in results} == {None}
    assert {(r.score, r.max_score) for r in results} == {(3, 3)}


def test_concurrent_runs_hold_their_own_domains(shout):
    with ThreadPoolExecutor(max_workers=3) as pool:
        results = list(pool.map(lambda _: grade(shout, None), range(3)))
    assert len({r.domain for r in results}) == 3
    assert {(r.score, r.max_score) for r in results} == {(3, 3)}


@pytest.mark.skipif(os.geteuid() != 0, reason="isolation by user needs root")
def test_children_started_in_an_isolation_the_check_refutes_start_again(shout, monkeypatch):
    """The children start in the likely isolation while the start-up check runs: where
    the check finds less (strict likely, a user of its own found), they are ended before
    they start anything and the grading runs in what it found."""
    from autograder.grading import children, run
    from autograder.sandbox.isolation import Isolation

    class Refuted:
        likely = Isolation("strict")

        def result(self) -> Isolation:
            return Isolation("user", "namespaces refused (a test)")

    started: list[children.Child] = []
    real_started = children.started

    def watched(*args, **kwargs):
        with real_started(*args, **kwargs) as child:
            started.append(child)
            yield child

    monkeypatch.setattr(run, "detection", Refuted)
    monkeypatch.setattr(children, "started", contextlib.contextmanager(watched))
    with modes_kept(protected_paths(COURSE)):  # isolation by user closes them
        result = grade(shout, None)
    assert (result.grader_error, result.score, result.max_score) == (None, 3, 3)
    assert result.isolation is not None and result.isolation.mode == "user"
    first, again = started[:len(started) // 2], started[len(started) // 2:]
    assert len(first) == len(again) >= 1
    assert {child.process.returncode for child in first} == {-signal.SIGKILL}
    assert {child.process.returncode for child in again} == {0}
