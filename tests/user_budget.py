"""A fork bomb, then the next program of the same student user (the next grading on the
same ROS domain): does the second get its whole budget of tasks?

    python user_budget.py MODE FOLDER

Run as each shape runs the grader (directly as root, or behind a container's or an
ordinary user's command prefix): it starts as the grader's command does (as PID 1 of a
container it reaps orphans, :func:`autograder.core.pid1.reap_as_init`), holds a free ROS
domain, and in FOLDER starts, through :func:`autograder.sandbox.process.student_process`
in isolation MODE, a program that forks until its user may fork no more and never reaps
its children; stops it as a grading does; then at once starts a program that starts 100
threads. Prints one JSON line: how many children the bomb made, and how the second
program ended and what it printed."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

BOMB = """\
import os, time
made = 0
while True:
    try:
        if os.fork() == 0:
            os._exit(0)
    except OSError:
        break
    made += 1
print("forked", made, flush=True)
time.sleep(600)
"""

THREADS = """\
import threading, time
threads = [threading.Thread(target=time.sleep, args=(1.0,)) for _ in range(100)]
for thread in threads:
    thread.start()
print("started", len(threads), flush=True)
for thread in threads:
    thread.join()
"""


def main(mode: str, folder: Path) -> dict[str, object]:
    from autograder.core.exercise import Limits
    from autograder.sandbox.domains import hold_domain
    from autograder.sandbox.process import student_process

    found: dict[str, object] = {}
    with hold_domain() as lock:
        for name, text in (("bomb", BOMB), ("threads", THREADS)):
            script = folder / name / "staged" / f"{name}.py"
            script.parent.mkdir(parents=True)
            script.write_text(text)
            process = student_process(script, [], Limits(), domain=lock.domain, mode=mode,
                                      course=folder)
            process.start()
            if name == "bomb":
                deadline = time.monotonic() + 60.0
                while "forked" not in process.output_text() and time.monotonic() < deadline:
                    time.sleep(0.05)
                process.stop(grace=0.5)
                found["bomb"] = process.output_text().strip()
            else:
                found["status"] = process.wait(60.0)
                found["threads"] = process.output_tail(3)
                process.stop(grace=0.5)
    return found


if __name__ == "__main__":
    from autograder.core.pid1 import reap_as_init

    reap_as_init()
    print(json.dumps(main(sys.argv[1], Path(sys.argv[2]))), flush=True)
