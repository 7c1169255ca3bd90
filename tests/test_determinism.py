"""The same submission gets the same score every time, also with both cores kept busy;
gradings at the same time each hold a ROS domain of their own."""

from __future__ import annotations

import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from autograder.core.exercise import find_exercise
from autograder.grading.run import grade

pytestmark = pytest.mark.slow

COURSE = Path(__file__).parent / "fixtures" / "mini_course"
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
