"""The launcher between the grader and a student's program: a failure before the exec is
the grader's, reported as such, never the student's zero; strict isolation works wherever
the interpreter lives, /tmp included."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from xml.etree import ElementTree

import pytest

from autograder.core.exercise import Limits
from autograder.grading.run import GRADER_FAULT
from autograder.sandbox.isolation import (
    FASTDDS_PROFILE,
    PROFILE_ENV,
    Isolation,
    dds_env,
    detect,
)
from autograder.sandbox.process import (
    STRICT_WORKDIR_PREFIX,
    LaunchFailed,
    reap_recorded,
    student_process,
)
from sim.procstate import descendants

REPO = Path(__file__).resolve().parents[2]
COURSE = REPO / "tests" / "fixtures" / "mini_course"
SOLUTION = COURSE / "assignments" / "shout" / "solution"


def _program(tmp_path: Path, text: str) -> Path:
    script = tmp_path / "staged" / "program.py"
    script.parent.mkdir(parents=True)
    script.write_text(text)
    return script


def test_a_launch_that_cannot_exec_raises_launch_failed(tmp_path, monkeypatch):
    monkeypatch.setenv("AUTOGRADER_STUDENT_PYTHON", "/nonexistent/python3")
    process = student_process(_program(tmp_path, "print('ran')\n"), [], Limits(), domain=0,
                              strict=False, course=COURSE)
    with pytest.raises(LaunchFailed) as failure:
        process.start()
    assert failure.value.stage == "exec /nonexistent/python3"
    assert "FileNotFoundError" in failure.value.error
    assert not process.running()
    assert "ran" not in process.output_text()


def test_a_program_that_fails_at_once_is_the_programs_failure(tmp_path):
    """Exit status 1 from the program itself is not a launch failure: the exec happened."""
    process = student_process(_program(tmp_path, "raise SystemExit('mine')\n"), [],
                              Limits(), domain=0, strict=False, course=COURSE)
    process.start()  # no LaunchFailed: the pipe closed on exec
    assert process.wait(30) == 1
    process.stop()
    assert "mine" in process.output_text()


# Two children, each with a child of its own; "forked" once all four are there (each
# grandchild writes a byte when it runs, so its parent has forked it by then).
_FAMILY = """import os, time
ready, told = os.pipe()
for _ in range(2):
    if os.fork() == 0:
        if os.fork() == 0:
            os.write(told, b"x")
            time.sleep(60)
            os._exit(0)
        time.sleep(60)
        os._exit(0)
heard = b""
while len(heard) < 2:
    heard += os.read(ready, 2)
print("forked", flush=True)
time.sleep(60)
"""


def test_a_programs_family_is_every_process_it_started(tmp_path):
    """What a stalled wait counts as the program's (autograder/plugin/probe.py): its
    processes and their children, however the machine lets the grader find them (here
    basic isolation: no user of its own; with a cgroup where one can be made)."""
    process = student_process(_program(tmp_path, _FAMILY), [], Limits(), domain=0,
                              strict=False, course=COURSE)
    process.start()
    try:
        deadline = time.monotonic() + 30
        while "forked" not in process.output_text() and time.monotonic() < deadline:
            time.sleep(0.05)
        family = process.family()
        assert process.pid in family and len(family) == 5, family
        assert {process.pid, *descendants(process.pid)} == family  # none has left the tree
    finally:
        process.stop()


def test_the_program_gets_the_runs_fast_dds_profile_in_its_own_folder(tmp_path):
    """The student's program reads the run's Fast DDS profile from a copy in its working
    directory (in strict isolation the grader's package is hidden from it)."""
    shown = ("import os, pathlib\n"
             f"path = pathlib.Path(os.environ[{PROFILE_ENV!r}])\n"
             "print(path.parent == pathlib.Path.cwd(), path.read_text())\n")
    process = student_process(_program(tmp_path, shown), [], Limits(), domain=0,
                              strict=False, course=COURSE)
    process.start()
    assert process.wait(30) == 0
    process.stop()
    assert process.output_text().startswith("True ")
    assert FASTDDS_PROFILE.read_text() in process.output_text()


def test_the_fast_dds_profile_announces_participants_often():
    """The profile is Fast DDS XML whose default participant announces itself every 0.25 s
    and 20 times at the start (the file says why), and every process of a run gets it."""
    ns = {"f": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}
    root = ElementTree.parse(FASTDDS_PROFILE).getroot()
    participant = root.find("f:participant[@is_default_profile='true']", ns)
    assert participant is not None
    discovery = participant.find("f:rtps/f:builtin/f:discovery_config", ns)
    assert discovery.findtext("f:leaseAnnouncement/f:nanosec", namespaces=ns) == "250000000"
    assert discovery.findtext("f:initialAnnouncements/f:count", namespaces=ns) == "20"
    for mode in ("basic", "strict"):
        assert dds_env(Isolation(mode))[PROFILE_ENV] == str(FASTDDS_PROFILE)


_SUBSCRIBER = """
import rclpy
from geometry_msgs.msg import Twist
rclpy.init()
node = rclpy.create_node("acks_subscriber")
node.create_subscription(Twist, "/cmd_vel", lambda message: None, 10)
rclpy.spin(node)
"""
_PUBLISHER = """
import json, time
import rclpy
from geometry_msgs.msg import Twist
from rclpy.duration import Duration
rclpy.init()
node = rclpy.create_node("acks_publisher")
publisher = node.create_publisher(Twist, "/cmd_vel", 10)
deadline = time.monotonic() + 20
while publisher.get_subscription_count() < 1 and time.monotonic() < deadline:
    time.sleep(0.01)
acked = []
for _ in range(3):
    publisher.publish(Twist())
    acked.append(publisher.wait_for_all_acked(Duration(seconds=1.5)))
print(json.dumps(acked))
"""


def test_a_reliable_stop_is_acknowledged_within_the_wait(tmp_path):
    """A reliable writer is acknowledged within a ``wait_for_all_acked`` that a clean exit
    does (error_handling's README: 1 s). Acks come only after the writer's heartbeat: with
    Fast DDS's default of one every 3 s, three waits in a row cannot all succeed."""
    from autograder.sandbox.domains import hold_domain

    with hold_domain() as lock:  # both launched as a student's program is, profile and all
        subscriber, publisher = (
            student_process(_program(tmp_path / name, text), [], Limits(), domain=lock.domain,
                            strict=False, course=COURSE)
            for name, text in (("subscriber", _SUBSCRIBER), ("publisher", _PUBLISHER)))
        subscriber.start()
        try:
            publisher.start()
            assert publisher.wait(60) == 0, publisher.output_text()
            publisher.stop()
        finally:
            subscriber.stop()
    assert json.loads(publisher.output_text().splitlines()[-1]) == [True, True, True], \
        publisher.output_text()


@pytest.mark.slow
def test_a_grader_fault_is_exit_3_never_a_students_zero(tmp_path):
    """With the launcher unable to exec the interpreter, `grade` says the autograder
    failed (exit 3), marks no test as the student's failure, and still writes results."""
    env = dict(os.environ, AUTOGRADER_COURSE=str(COURSE),
               AUTOGRADER_STUDENT_PYTHON="/nonexistent/python3")
    results = tmp_path / "results.json"
    run = subprocess.run([sys.executable, "-m", "autograder.cli", "grade", "shout",
                          str(SOLUTION), "--results", str(results)],
                         capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 3, run.stdout + run.stderr
    assert "The autograder failed, tell your instructor." in run.stdout
    data = json.loads(results.read_text())
    assert data["grader_error"] == GRADER_FAULT
    assert {t["status"] for t in data["tests"]} == {"error"}
    assert "the launcher failed at exec /nonexistent/python3" in run.stdout  # the detail


def _venv_under_tmp() -> Path:
    """A venv in /tmp whose packages are this one's (a .pth file), made in a second."""
    folder = Path(tempfile.mkdtemp(prefix="autograder-venv-", dir="/tmp"))
    os.chmod(folder, 0o755)
    venv = folder / "venv"
    base = getattr(sys, "_base_executable", sys.executable)
    subprocess.run([base, "-m", "venv", "--without-pip", str(venv)], check=True)
    site = Path(sysconfig.get_path("purelib", vars={"base": str(venv)}))
    (site / "parent.pth").write_text(sysconfig.get_path("purelib") + "\n")
    return venv


@pytest.fixture(scope="module")
def tmp_setup() -> Iterator[tuple[Path, Path]]:
    """A venv and a copy of the course, both under /tmp, as a clone in /tmp has them."""
    if not detect().strict:
        pytest.skip(f"needs strict isolation: {detect().reason}")
    venv = _venv_under_tmp()
    course = Path(tempfile.mkdtemp(prefix="autograder-course-", dir="/tmp")) / "course"
    shutil.copytree(COURSE, course)
    os.chmod(course.parent, 0o755)
    yield venv, course
    shutil.rmtree(venv.parent, ignore_errors=True)
    shutil.rmtree(course.parent, ignore_errors=True)


def _grade_from(venv: Path, course: Path, submission: Path, out: Path) -> tuple[dict, str]:
    """Grade with the venv's Python; the results and the JUnit XML (it holds the log)."""
    env = dict(os.environ, AUTOGRADER_COURSE=str(course), PYTHONPATH=str(REPO))
    junit = out.with_suffix(".xml")
    run = subprocess.run([str(venv / "bin" / "python"), "-m", "autograder.cli", "grade",
                          "shout", str(submission), "--results", str(out), "--junit",
                          str(junit)], capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    return json.loads(out.read_text()), junit.read_text()


@pytest.mark.slow
def test_strict_isolation_with_the_venv_and_the_course_under_tmp(tmp_setup, tmp_path):
    venv, course = tmp_setup
    data, _log = _grade_from(venv, course, course / "assignments/shout/solution",
                             tmp_path / "results.json")
    assert data["isolation"]["mode"] == "strict"
    assert (data["score"], data["max_score"]) == (3, 3)
    _data, log = _grade_from(venv, course, REPO / "tests/submissions/hostile/reads_secrets",
                             tmp_path / "secrets.json")
    assert "SECRETS FOUND: 0" in log


@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv")
                    or not shutil.which("unshare"), reason="needs root, setpriv and unshare")
def test_refused_namespaces_are_named_as_the_reason():
    """In an unprivileged container (no CAP_SYS_ADMIN) the student still gets a user of its
    own (isolation by user), and the reason says namespaces were refused, not that the venv
    is unreadable."""
    code = "from autograder.sandbox.isolation import detect; i = detect(); print(i.mode, i.reason)"
    run = subprocess.run(["setpriv", "--bounding-set=-sys_admin", "--inh-caps=-sys_admin",
                          sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ, PYTHONPATH=str(REPO)), timeout=120)
    assert run.stdout.strip() == ("user namespaces are not allowed here (an unprivileged "
                                  "container?)"), run.stderr


def test_reaping_a_record_removes_the_strict_folder_it_names_and_no_other(tmp_path):
    """A run killed before its fixtures stop the program (the time limit, a wait that
    raised) leaves the strict folder in the temporary folder: the parent's reaping, from the
    run's report, removes it; a record naming any other folder removes nothing."""
    strict = Path(tempfile.mkdtemp(prefix=STRICT_WORKDIR_PREFIX))
    (strict / ".ros").mkdir()
    (strict / "program.py").write_text("print()\n")
    elsewhere = tmp_path / f"{STRICT_WORKDIR_PREFIX}not-in-tmp"
    elsewhere.mkdir()
    other = Path(tempfile.mkdtemp(prefix="not-a-student-"))
    try:
        # pid 0 would signal our own group: a pid that is surely gone instead.
        reap_recorded([{"pid": 2 ** 22 + 1, "cgroups": [], "workdir": str(folder)}
                       for folder in (elsewhere, other, strict)])
        assert not strict.exists()
        assert elsewhere.is_dir() and other.is_dir()
    finally:
        shutil.rmtree(strict, ignore_errors=True)
        shutil.rmtree(other, ignore_errors=True)


def test_reaping_sweeps_each_user_once_however_many_of_its_programs(monkeypatch):
    """A run records each program it started, often three of one student's user: reaping
    them sweeps that user once (a sweep reads the scratch folders whole), and each user
    of the records once."""
    from autograder.sandbox import process
    from autograder.sandbox.sweep import STUDENT_UID_BASE

    swept: list[int] = []
    monkeypatch.setattr(process, "sweep_user", swept.append)
    gone = 2 ** 22 + 1  # a pid that is surely gone
    reap_recorded([{"pid": gone, "cgroups": [], "uid": STUDENT_UID_BASE + 3}] * 3 +
                  [{"pid": gone, "cgroups": [], "uid": STUDENT_UID_BASE + 4},
                   {"pid": gone, "cgroups": [], "uid": 0}])
    assert swept == [STUDENT_UID_BASE + 3, STUDENT_UID_BASE + 4]


@pytest.mark.slow
@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"),
                    reason="needs root and setpriv to act as a student's user")
def test_a_user_an_earlier_program_still_holds_is_freed_or_the_launch_is_ours(
        tmp_path, monkeypatch):
    """Before the first program of a student's user starts here, what an earlier program
    left as that user (a run killed before its sweep) is ended; a task of it that cannot
    be ended in time (a zombie whose parent never reaps it, which still counts against the
    user's RLIMIT_NPROC) makes the launch fail as the grader's fault, not start a program
    short of its budget."""
    from autograder.sandbox import process as process_module
    from autograder.sandbox.contained.launcher import user_tasks
    from autograder.sandbox.isolation import student_uid

    domain = 228  # a domain no grading reserves
    uid = student_uid(domain)
    leftover = subprocess.Popen(["setpriv", f"--reuid={uid}", f"--regid={uid}", "--clear-groups",
                                 "sleep", "600"], start_new_session=True)
    # A parent that is not ours nor the student's, holding a zombie of the student's user.
    holder = subprocess.Popen([sys.executable, "-c",
                               "import os, sys, time\n"
                               f"if os.fork() == 0:\n    os.setuid({uid})\n    os._exit(0)\n"
                               "print('held', flush=True)\n"
                               "time.sleep(600)\n"], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        monkeypatch.setattr(process_module, "USER_FREE_TIMEOUT", 1.0)
        program = student_process(_program(tmp_path / "held", "print('ran')\n"), [], Limits(),
                                  domain=domain, mode="user", course=COURSE)
        with pytest.raises(LaunchFailed) as failure:
            program.start()
        assert failure.value.stage == "user"
        assert leftover.wait(10.0) == -9  # the live leftover was ended all the same
        holder.kill()  # its zombie goes to the machine's init, which reaps it in its time
        holder.wait()
        monkeypatch.setattr(process_module, "USER_FREE_TIMEOUT", 60.0)
        program = student_process(_program(tmp_path / "freed", "print('ran')\n"), [],
                                  Limits(), domain=domain, mode="user", course=COURSE)
        program.start()
        try:
            assert program.wait(60.0) == 0
        finally:
            program.stop()
        assert program.output_text() == "ran\n"
        assert user_tasks(uid) == 0
    finally:
        for process in (leftover, holder):
            process.kill()
            process.wait()


@pytest.mark.slow
@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"),
                    reason="needs root and setpriv to act as a student's user")
def test_a_program_that_starts_while_its_users_sweep_runs_waits_for_the_sweep(
        tmp_path, monkeypatch):
    """The sweep after a user's last program ends every process of the user: a program of
    that user starting meanwhile (the next test's) would be swept with it. It waits for
    the sweep instead, and runs."""
    import threading

    from autograder.sandbox import process as process_module
    from autograder.sandbox.domains import hold_domain

    in_sweep, release, spawned = threading.Event(), threading.Event(), threading.Event()
    sweep = process_module.sweep_user

    def held_sweep(uid: int) -> bool:
        in_sweep.set()
        release.wait(60.0)
        return sweep(uid)

    with hold_domain() as lock:
        first = student_process(_program(tmp_path / "first", "import time\ntime.sleep(60)\n"),
                                [], Limits(), domain=lock.domain, mode="user", course=COURSE)
        first.start()
        monkeypatch.setattr(process_module, "sweep_user", held_sweep)
        stopping = threading.Thread(target=first.stop)
        stopping.start()
        assert in_sweep.wait(60.0)
        second = student_process(_program(tmp_path / "second", "print('ran')\n"), [],
                                 Limits(), domain=lock.domain, mode="user", course=COURSE)
        second.on_spawn = spawned.set
        starting = threading.Thread(target=second.start)
        starting.start()
        # While the sweep is held the second program must not start; 2 s is ample for a
        # start here (about 0.3 s), so one that did not wait would have started by then.
        assert not spawned.wait(2.0)
        release.set()
        stopping.join(60.0)
        starting.join(60.0)
        try:
            assert second.wait(60.0) == 0
        finally:
            second.stop()
        assert second.output_text() == "ran\n"
