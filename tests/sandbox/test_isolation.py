"""What each isolation shape says of its grades (issue 29): strict and user isolation give
official grades; basic isolation says it does not, in the results and the terminal, and a
grading whose pytest process something stopped is the grader's failure, never a verdict."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from autograder.core.report import RawReport
from autograder.core.results import Containment
from autograder.grading import children
from autograder.grading.children import Child, Watchers
from autograder.render.terminal import isolation_line
from autograder.sandbox.isolation import LOOPBACK_PROFILE, PROFILE_ENV, Isolation, dds_env

BOUNDS = {"cgroup": None, "processes": "rlimit", "memory": "rlimit"}
REPO = Path(__file__).resolve().parents[2]
COURSE = REPO / "tests" / "fixtures" / "mini_course"
CORPUS = REPO / "tests" / "submissions" / "hostile"
NOBODY = 65534


def test_only_a_user_of_its_own_gives_official_grades():
    assert Isolation("strict").to_dict()["official"] is True
    assert Isolation("user", "why").to_dict()["official"] is True
    basic = Isolation("basic", "the grader does not run as root").to_dict()
    assert basic["official"] is False and basic["separate_user"] is False
    assert Isolation("user").to_dict()["network"] is True  # said, not hidden


def _contained(isolation: Isolation) -> Containment:
    """What the results say of a grading in this shape, bounded by rlimits alone."""
    return Containment.from_dict({**isolation.to_dict(), "bounds": BOUNDS})


def test_the_terminal_says_which_shape_and_whether_the_grade_is_official():
    strict = isolation_line(_contained(Isolation("strict")))
    user = isolation_line(_contained(Isolation(
        "user", "namespaces are not allowed here (an unprivileged container?)")))
    basic = isolation_line(_contained(Isolation("basic", "the grader does not run as root")))
    assert strict.startswith("Isolation: strict") and "official" not in strict
    assert user.startswith("Isolation: by user, namespaces are not allowed here")
    assert "the network and the machine's processes in its reach" in user
    assert "Not an official grade" not in user
    assert basic.splitlines()[1].startswith("Not an official grade")


def test_isolation_by_user_keeps_fast_dds_on_loopback():
    env = dds_env(Isolation("user"))
    assert env[PROFILE_ENV] == str(LOOPBACK_PROFILE)
    assert env["FASTDDS_BUILTIN_TRANSPORTS"] is None
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] is None
    text = LOOPBACK_PROFILE.read_text()
    assert "<useBuiltinTransports>false</useBuiltinTransports>" in text
    assert text.count("<address>127.0.0.1</address>") == 2  # the allowlist, the peer


def _stopped(pid: int) -> bool:
    """Whether the kernel shows process ``pid`` stopped (``T`` in its stat)."""
    with open(f"/proc/{pid}/stat", "rb") as stat:
        return stat.read().rpartition(b")")[2].split()[0] == b"T"


def test_a_stopped_grading_is_the_graders_failure(tmp_path):
    """A program of the grader's own user (basic isolation) may SIGSTOP the pytest child
    to read its memory at leisure: the grader ends that child and calls the grading its
    own failure, whatever the child's report says."""
    process = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"],
                               start_new_session=True)
    try:
        process.send_signal(signal.SIGSTOP)
        deadline = time.monotonic() + 10
        while not _stopped(process.pid):
            assert time.monotonic() < deadline, "the process never showed as stopped"
            time.sleep(0.01)
        log = tmp_path / "pytest.log"
        log.write_text("")
        child = Child(process, tmp_path / "report.json", b"k" * 32, log, time.monotonic())
        children.wait([child], 60.0, Watchers())
        assert child.stopped and process.returncode == -signal.SIGKILL
        ended = children.Ended(RawReport(tests=[], data={}), process.returncode, False,
                               "", 0.0, child.stopped)
        assert ended.broken
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert not Path(f"/proc/{process.pid}").exists() or process.returncode is not None


@pytest.mark.slow
@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"),
                    reason="needs root and setpriv to grade as an ordinary user")
def test_an_ordinary_users_grading_resists_a_program_that_stops_it(tmp_path):
    """Graded as an ordinary user (basic isolation), a program finds the grading's pytest
    process: it cannot open its memory (not dumpable), and stopping it makes the grading
    the grader's failure (exit 3), never a verdict; the results say it is not official."""
    work = Path(tempfile.mkdtemp(prefix="autograder-user-"))
    try:
        work.chmod(0o777)
        course = work / "course"
        shutil.copytree(COURSE, course)
        submission = work / "submission"
        shutil.copytree(CORPUS / "stops_the_grader", submission)
        for path in [course, submission, *course.rglob("*"), *submission.rglob("*")]:
            path.chmod(0o755 if path.is_dir() else 0o644)
        env = {"PATH": os.environ.get("PATH", ""), "HOME": str(work), "LANG": "C.UTF-8",
               "AUTOGRADER_COURSE": str(course), "XDG_CACHE_HOME": str(work / "cache")}
        done = subprocess.run(
            ["setpriv", f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups",
             str(Path(sys.executable).with_name("autograder")), "grade", "shout",
             str(submission), "--results", str(work / "results.json")],
            env=env, cwd=str(work), capture_output=True, text=True, timeout=600)
        output = done.stdout + done.stderr
        said = Path(f"/tmp/stops-the-grader-{NOBODY}.txt")
        log = said.read_text() if said.exists() else ""
    finally:
        shutil.rmtree(work, ignore_errors=True)
        Path(f"/tmp/stops-the-grader-{NOBODY}.txt").unlink(missing_ok=True)
    assert "STOPPING" in log, output[-3000:]
    assert "MEM OPENED" not in log and "MEM DENIED" in log
    assert done.returncode == 3, output[-3000:]
    assert "this grade is not official" in output  # the student's sentence


def test_what_is_known_without_a_check_is_known_at_once(monkeypatch):
    """Basic isolation asked for (or an ordinary user): no start-up check runs, and the
    likely isolation is the answer."""
    from autograder.sandbox import isolation

    started: list[Isolation] = []
    monkeypatch.setattr(isolation, "start_check", started.append)
    monkeypatch.setenv("AUTOGRADER_ISOLATION", "basic")
    detecting = isolation.Detection()
    assert detecting.likely == detecting.result() == Isolation(
        "basic", "basic isolation was asked for (AUTOGRADER_ISOLATION)")
    assert started == []


@pytest.mark.skipif(os.geteuid() != 0, reason="the start-up check runs only for root")
def test_a_check_that_fails_falls_back_with_every_reason(monkeypatch):
    """Strict likely, its check refused: a user of its own is checked next, and where that
    fails too the answer is basic, naming both checks' details."""
    from autograder.sandbox import isolation

    def fake_check(tried: Isolation) -> subprocess.Popen[str]:
        code = f"import sys; print('no {tried.mode} here'); sys.exit(1)"
        return subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)

    monkeypatch.delenv("AUTOGRADER_ISOLATION", raising=False)
    monkeypatch.setattr(isolation, "start_check", fake_check)
    monkeypatch.setattr(isolation.shutil, "which", lambda name: f"/usr/bin/{name}")
    detecting = isolation.Detection()
    assert detecting.likely == Isolation("strict")
    found = detecting.result()
    assert found.mode == "basic"
    assert found.reason == "a test program could not run as a user of its own"
    assert found.detail == "no strict here / no user here"
    assert detecting.result() is found  # asked again: the same answer, no new check
