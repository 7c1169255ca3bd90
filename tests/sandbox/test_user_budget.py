"""A student's user gets its whole budget of tasks whatever ran as that user before.

A student's own user is per ROS domain, so the next grading on a domain runs as the user of
the last one there; and a killed process still counts against its user's ``RLIMIT_NPROC``
until its parent has reaped it. A fork bomb whose children are zombies that only the
machine's init would reap must not leave the next program unable to start a thread (an
rclpy ``Node()`` dies with "pthread_create failed: Resource temporarily unavailable"),
which would lose a classmate points for what the last program did. Tried in each shape
the grader meets: strict isolation, isolation by user on the host, a container (as
Kubernetes runs it: root without namespaces, its command PID 1), and an ordinary user (the
student is the grader's user: its budget is the grader's tasks and 128 more); with programs
forked from the zygote, and exec'd."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from shapes import DOCKER_CAPS, clean_env, container, ordinary_user, world_readable_folder

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv")
                       or not shutil.which("unshare"),
                       reason="needs root, setpriv and unshare to make the shapes"),
]

HELPER = Path(__file__).resolve().parents[1] / "user_budget.py"
# shape: (command prefix, isolation, whether programs are forked from the zygote, whose
# orphans are its own to reap, or exec'd, whose orphans go to the machine's init)
SHAPES = {
    "strict": ((), "strict", "1"),
    "strict-execd": ((), "strict", "0"),
    "user": ((), "user", "1"),
    "container": (tuple(container(DOCKER_CAPS, own_pids=True)), "user", "1"),
    "container-execd": (tuple(container(DOCKER_CAPS, own_pids=True)), "user", "0"),
    "ordinary-user": (tuple(ordinary_user()), "basic", "1"),
}


@pytest.mark.parametrize("shape", SHAPES)
def test_the_next_program_of_a_user_is_not_starved_by_a_fork_bombs_zombies(shape):
    prefix, mode, zygote = SHAPES[shape]
    work = world_readable_folder("autograder-budget-")
    work.chmod(0o777)
    try:
        shutil.copy(HELPER, work / HELPER.name)
        env = {**clean_env(os.environ.get("PATH", "")), "HOME": str(work),
               "XDG_CACHE_HOME": str(work / "cache"), "AUTOGRADER_ZYGOTE": zygote}
        done = subprocess.run([*prefix, sys.executable, str(work / HELPER.name), mode,
                               str(work)], env=env, cwd=work, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
        found = json.loads(done.stdout.strip().splitlines()[-1])
        made = int(found["bomb"].split("forked ", 1)[1].split()[0])
        assert made >= 100, found  # it spent its user's budget: 128 tasks, itself one
        assert found["status"] == 0, found
        assert "started 100" in found["threads"], found
    finally:
        shutil.rmtree(work, ignore_errors=True)
