"""The grader as PID 1 of a container (a Kubernetes Job's command) reaps the orphans the
kernel hands it: zombies of a student's user would count against that user's process
limit in the next grading (issue 29)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("unshare"),
                                reason="needs root and unshare for a PID namespace")

# As PID 1: orphans that end at once; then the zombies whose parent is PID 1, counted
# from /proc once the orphans are gone; then an exit status of its own.
PROGRAM = """
import os, sys, time
from autograder.core.pid1 import reap_as_init
reap_as_init()
for _ in range(20):
    if os.fork() == 0:          # a middle process that leaves an orphan and ends
        if os.fork() == 0:
            os._exit(0)         # the orphan: handed to PID 1 when its parent is gone
        os._exit(0)
    os.wait()
deadline = time.monotonic() + 30
while True:
    zombies = []
    for name in os.listdir("/proc"):
        if name.isdigit():
            try:
                status = open(f"/proc/{name}/status").read()
            except OSError:
                continue
            fields = dict(line.split(":", 1) for line in status.splitlines() if ":" in line)
            if fields["State"].strip().startswith("Z") and fields["PPid"].strip() == "1":
                zombies.append(name)
    if not zombies or time.monotonic() > deadline:
        break
    time.sleep(0.05)
print("PID", os.getpid(), "ZOMBIES", len(zombies), flush=True)
sys.exit(7)
"""


def test_as_pid_1_the_grader_reaps_orphans_and_keeps_the_commands_status():
    done = subprocess.run(["unshare", "--pid", "--fork", "--mount", "--mount-proc",
                           sys.executable, "-c", PROGRAM], capture_output=True, text=True,
                          timeout=60, env={**os.environ, "PYTHONPATH": os.getcwd()})
    assert done.returncode == 7, done.stderr
    pid, zombies = done.stdout.split()[1], done.stdout.split()[3]
    assert pid != "1"  # the command ran in PID 1's child
    assert zombies == "0"


def test_elsewhere_nothing_forks():
    from autograder.core.pid1 import reap_as_init

    before = os.getpid()
    reap_as_init()
    assert os.getpid() == before
