"""Isolation's start-up check: it passes only if a test program, started as a student's
program is, ran Python and rclpy as a user of its own; otherwise it says what went wrong
(the launcher's stage, or the program's status and last lines); stopped, it leaves nothing
behind."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.sandbox.domains import shared_lock_dir
from autograder.sandbox.isolation import Isolation, detect, run_prefix
from autograder.sandbox.privileged import PACKAGE_PARENT, SAFE_CWD, module_command
from autograder.sandbox.startup_check import TEST_PROGRAM

WALL = 180


@pytest.fixture
def tmp_path() -> Iterator[Path]:
    """A folder a student's user may enter (pytest's own is closed to other users)."""
    folder = Path(tempfile.mkdtemp(prefix="startup-check-test-", dir="/tmp"))
    os.chmod(folder, 0o755)
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


def _check(tmp_path: Path, mode: str, program: str | None = None,
           env: dict[str, str] | None = None) -> subprocess.Popen[str]:
    """The check in a process of its own, its temporary folders under ``tmp_path/tmp``, with
    ``program`` in place of the test program."""
    (tmp_path / "tmp").mkdir(exist_ok=True)
    code = ("import sys\n"
            "from autograder.sandbox import startup_check\n"
            f"startup_check.TEST_PROGRAM = {program or TEST_PROGRAM!r}\n"
            "sys.exit(startup_check.main(sys.argv[1:]))\n")
    return subprocess.Popen(
        [sys.executable, "-c", code, mode], cwd=SAFE_CWD, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
        env={**os.environ, "PYTHONPATH": PACKAGE_PARENT, "TMPDIR": str(tmp_path / "tmp"),
             **(env or {})})


def _left(tmp_path: Path) -> list[Path]:
    """What the check left in its temporary folder, but the domain lock folders, which
    every run shares and keeps (``autograder.sandbox.domains.lock_dirs``)."""
    shared = shared_lock_dir().name
    return [p for p in (tmp_path / "tmp").iterdir()
            if p.name != shared and not p.name.startswith(f"{shared}-")]


def _result(check: subprocess.Popen[str]) -> tuple[int, str]:
    out, err = check.communicate(timeout=WALL)
    return check.returncode, out.strip() + err


def test_a_program_running_as_the_graders_own_user_fails_the_check(tmp_path):
    """Basic isolation runs it as the grader's user: not a user of its own."""
    status, said = _result(_check(tmp_path, "basic"))
    assert status == 1
    assert said.startswith("the test program exited with status 0: "
                           f"autograder-check-ok {os.getuid()}"), said
    assert _left(tmp_path) == []  # its folders removed


def test_a_failing_program_is_named_with_its_status_and_last_lines(tmp_path):
    program = "print('one')\nprint('two')\nraise SystemExit('no middleware here')\n"
    status, said = _result(_check(tmp_path, "basic", program))
    assert status == 1
    assert said.startswith("the test program exited with status 1: "), said
    assert "two" in said and "no middleware here" in said
    assert _left(tmp_path) == []


def test_a_launch_failure_is_named_by_its_stage(tmp_path):
    status, said = _result(_check(tmp_path, "basic",
                                  env={"AUTOGRADER_STUDENT_PYTHON": "/nonexistent/python3"}))
    assert status == 1
    assert said.startswith("the launcher failed at exec /nonexistent/python3: "
                           "FileNotFoundError"), said
    assert _left(tmp_path) == []


def test_stopped_it_stops_its_program_and_removes_its_folders(tmp_path):
    """SIGTERM (the grader giving up on it) ends the check as Ctrl-C would."""
    started = tmp_path / "started"
    program = (f"import os, time\nopen({str(started)!r}, 'w').write(str(os.getpid()))\n"
               "time.sleep(600)\n")
    check = _check(tmp_path, "basic", program)
    deadline = time.monotonic() + WALL
    while not (started.exists() and started.read_text()):
        assert time.monotonic() < deadline and check.poll() is None, check.communicate()
        time.sleep(0.05)
    check.send_signal(signal.SIGTERM)
    status, said = _result(check)
    assert status != 0 and "KeyboardInterrupt" in said
    assert not Path(f"/proc/{started.read_text()}").exists()  # its program is gone
    assert _left(tmp_path) == []


@pytest.mark.skipif(not detect().strict, reason=f"needs strict isolation: {detect().reason}")
@pytest.mark.parametrize("mode", ["strict", "user"])
def test_where_isolation_works_the_check_passes_silently(mode, tmp_path):
    """As :func:`detect` runs it: isolated, from ``/``, strict in the run's namespaces."""
    run = subprocess.run(
        [*run_prefix(Isolation(mode)),
         *module_command("autograder.sandbox.startup_check", [mode])],
        cwd=SAFE_CWD, capture_output=True, text=True, timeout=WALL)
    assert (run.returncode, run.stdout) == (0, ""), run.stdout + run.stderr
    # The same check, its folders (the student's own included) under tmp_path: all removed.
    status, said = _result(_check(tmp_path, mode))
    assert (status, said) == (0, ""), said
    assert _left(tmp_path) == []


@pytest.mark.skipif(not detect().strict, reason=f"needs strict isolation: {detect().reason}")
def test_checks_at_once_leave_each_others_programs_running(tmp_path):
    """Two graders that start at once each check isolation: the end of one check's program
    (which sweeps every process of its user) must not end the other's, or that grader falls
    to basic isolation and an unofficial grade. Each runs as the user of a domain it holds."""
    def lingering(seconds: float) -> str:
        return TEST_PROGRAM.replace("rclpy.shutdown()\n",
                                    f"rclpy.shutdown()\nimport time\ntime.sleep({seconds})\n")

    checks = [_check(tmp_path, "strict", lingering(seconds)) for seconds in (0.2, 2.0, 4.0)]
    assert [_result(check) for check in checks] == [(0, "")] * 3
