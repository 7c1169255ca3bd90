"""A process made not dumpable: closed to tracing and to reading its memory by the other
processes of its user; what it forks stays closed, what it execs is dumpable again."""

from __future__ import annotations

import subprocess
import sys

from autograder.sandbox.privileged import PACKAGE_PARENT

SHOW = """\
import ctypes, os, subprocess, sys
from autograder.core.dumpable import PR_SET_DUMPABLE, not_dumpable
libc = ctypes.CDLL(None)
PR_GET_DUMPABLE = 3
def dumpable():
    return libc.prctl(PR_GET_DUMPABLE, 0, 0, 0, 0)
before = dumpable()
not_dumpable()
after = dumpable()
read, write = os.pipe()
if os.fork() == 0:
    os.write(write, str(dumpable()).encode())
    os._exit(0)
os.wait()
forked = int(os.read(read, 10))
execd = subprocess.run([sys.executable, "-c",
                        "import ctypes; print(ctypes.CDLL(None).prctl(3, 0, 0, 0, 0))"],
                       capture_output=True, text=True, check=True).stdout.strip()
print(before, after, forked, execd, PR_SET_DUMPABLE)
"""


def test_not_dumpable_closes_this_process_and_its_forks_not_what_it_execs():
    run = subprocess.run([sys.executable, "-c", SHOW], capture_output=True, text=True,
                         timeout=60, cwd=PACKAGE_PARENT)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["1", "0", "0", "1", "4"]
