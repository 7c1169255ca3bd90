"""What a grading left running (autograder.sandbox.leftovers): a live process in one of its
process groups is found, a reaped or zombie one is not."""

from __future__ import annotations

import subprocess
import sys
import time

from autograder.core.results import RunResult, StartedProcess
from autograder.sandbox.leftovers import leftovers


def ran(*processes: dict) -> RunResult:
    return RunResult("exercise", "x", "X", (),
                     processes=tuple(StartedProcess.from_record(p) for p in processes))


def test_a_live_process_in_the_runs_group_is_left_over() -> None:
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"],
                               start_new_session=True)
    try:
        result = ran({"pid": sleeper.pid, "cgroups": []})
        assert leftovers(result) == [sleeper.pid]
        sleeper.kill()
        sleeper.wait()
        assert leftovers(result) == []
    finally:
        sleeper.kill()
        sleeper.wait()


def test_a_zombie_is_not_left_over() -> None:
    child = subprocess.Popen([sys.executable, "-c", "pass"], start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while True:  # until it has ended, not yet reaped: a zombie
            with open(f"/proc/{child.pid}/stat") as stat:
                if stat.read().rsplit(")", 1)[1].split()[0] == "Z":
                    break
            assert time.monotonic() < deadline, "the child never ended"
            time.sleep(0.01)
        assert leftovers(ran({"pid": child.pid, "cgroups": []})) == []
    finally:
        child.wait()


def test_a_run_that_started_nothing_leaves_nothing() -> None:
    assert leftovers(ran()) == []
