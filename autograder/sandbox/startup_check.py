"""Isolation's start-up check, a process of its own in the run's namespaces::

    python -I -m autograder.sandbox.startup_check MODE

starts a test program exactly as a student's is started in isolation ``MODE``
(:func:`autograder.sandbox.process.student_process`) and exits 0 if it ran Python and
rclpy as a user of its own, else prints what went wrong and exits 1
(:func:`autograder.sandbox.isolation.detect` reads it).
"""

from __future__ import annotations

import shutil
import sys
from collections.abc import Sequence
from pathlib import Path

from autograder.sandbox.isolation import Mode, bring_up_loopback, student_uid
from autograder.sandbox.privileged import PACKAGE_PARENT

# What the start-up check's test program runs: Python, rclpy and its middleware.
TEST_PROGRAM = """\
import os
import rclpy

rclpy.init()
rclpy.shutdown()
print("autograder-check-ok", os.getuid())
"""


def check_launch(mode: Mode = "strict") -> str | None:
    """Start a test program exactly as a student's is started in isolation ``mode``; None
    if it ran as its own user, else what went wrong. Runs inside the run's namespaces.

    The program runs as the user of a domain held for the check, as a grading holds its
    own: no other check or grading uses that user meanwhile (the end of a program sweeps
    every process of its user)."""
    from autograder.sandbox.domains import NoDomain, hold_domain

    if mode == "strict":
        bring_up_loopback()
    try:
        with hold_domain() as lock:
            return _test_program(mode, lock.domain)
    except NoDomain as exc:
        return str(exc)


def _test_program(mode: Mode, domain: int) -> str | None:
    """:func:`check_launch`'s test program, run as ``domain``'s student user."""
    import tempfile

    from autograder.core.exercise import Limits
    from autograder.sandbox.process import LaunchFailed, student_process

    with tempfile.TemporaryDirectory(prefix="autograder-check-",
                                     ignore_cleanup_errors=True) as tmp:
        script = Path(tmp) / "staged" / "check.py"
        script.parent.mkdir()
        script.write_text(TEST_PROGRAM)
        process = student_process(script, [], Limits(), domain=domain, mode=mode,
                                  course=Path(PACKAGE_PARENT))
        try:
            try:
                process.start()
            except LaunchFailed as exc:
                return str(exc)
            status = process.wait(60.0)
        finally:  # also when stopped (see __main__): nothing of the test program is left
            if process.popen is not None:
                process.stop(grace=1.0)
            shutil.rmtree(process.workdir, ignore_errors=True)
        expected = f"autograder-check-ok {student_uid(domain)}"
        if status == 0 and expected in process.output_text():
            return None
        return (f"the test program exited with status {status}: "
                f"{process.output_tail(3) or '(no output)'}")


def _stop_as_ctrl_c() -> None:
    """SIGTERM, SIGHUP, and the grader's death (``PR_SET_PDEATHSIG``) end the check as
    Ctrl-C would: its ``finally`` stops the test program and removes its folders."""
    import ctypes
    import signal

    def stop(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, stop)
    ctypes.CDLL(None).prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG


def main(argv: Sequence[str] | None = None) -> int:
    """The check as its process runs it (``argv``, else the command line's: the isolation
    mode, else strict): 0 if the test program ran as its own user, else 1 with what went
    wrong printed; stopped by a signal or the grader's death, it raises KeyboardInterrupt
    with nothing left behind."""
    _stop_as_ctrl_c()
    args = sys.argv[1:] if argv is None else argv
    problem = check_launch(*args[:1])  # type: ignore[arg-type]
    if problem is None:
        return 0
    print(problem)
    return 1


if __name__ == "__main__":
    sys.exit(main())
