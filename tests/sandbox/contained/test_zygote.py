"""The zygote: a student's program forked from a warm process runs as one exec'd would.

Each case runs the same program both ways (``AUTOGRADER_ZYGOTE=0`` execs it through the
launcher) and compares what a grader sees: exit status, output, and the program's view
of itself (argv, working folder, environment, module path, ``__name__``, the thread
switch interval of :mod:`autograder.sandbox.contained.runner` and its executors' wait on a
subscription's QoS events).
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from autograder.core.exercise import Limits
from autograder.sandbox import process as process_module
from autograder.sandbox.contained import zygote as zygote_module
from autograder.sandbox.contained.zygote import ForkedProcess
from autograder.sandbox.process import (
    LaunchFailed,
    StudentProcess,
    close_zygotes,
    student_process,
    zygotes,
)
from sim.procstate import process_state

ROOT = Path(__file__).resolve().parents[3]
# Wall seconds a program may take to start or to end: generous, for a loaded machine (a
# fast-tier run beside other work once took more than 30 s to print its first line).
WALL = 240.0

SELF = """\
import os, sys
print("argv", [os.path.basename(sys.argv[0]), *sys.argv[1:]])
print("cwd", os.getcwd() == os.path.dirname(os.path.abspath(__file__)))
print("path0", sys.path[0] == os.path.dirname(__file__), __name__)
print("env", os.environ["ROS_DOMAIN_ID"], os.environ["HOME"] == os.getcwd())
print("switch", sys.getswitchinterval())
"""
PROGRAMS = {
    # A node left undestroyed at exit: a fork without LTTng's hooks died of SIGSEGV here.
    "exit_code": SELF + """\
import rclpy
from std_msgs.msg import Empty
rclpy.init()
node = rclpy.create_node("zygote_test")
subscription = node.create_subscription(Empty, "zygote_test", lambda message: None, 1)
every = len(list(node.waitables))
subscription._executor_event = True  # as an executor marks it, its message handed out
held = every - len(list(node.waitables))
print("held back", held == len(subscription.event_handlers) > 0)
subscription._executor_event = False
print("waited on again", len(list(node.waitables)) == every)
rclpy.shutdown()
sys.exit(3)
""",
    "crash": SELF + """\
def callback():
    raise ValueError("boom")
callback()
""",
    "interrupted": SELF + """\
import time
print("waiting", flush=True)
time.sleep(3600)  # ended by the test's Ctrl-C only, however slow the machine
""",
}


def _run(tmp_path: Path, name: str, forked: bool,
         monkeypatch: pytest.MonkeyPatch) -> tuple[int | None, str, StudentProcess]:
    monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1" if forked else "0")
    staged = tmp_path / ("forked" if forked else "execd") / name / "staged"
    staged.mkdir(parents=True)
    (staged / "prog.py").write_text(PROGRAMS[name])
    program = student_process(staged / "prog.py", [], Limits(), domain=7, strict=False,
                              course=ROOT)
    program.start()
    try:
        if name == "interrupted":  # Ctrl-C once the program runs its own code, not before
            end = time.monotonic() + WALL
            while "waiting" not in program.output_text():
                assert time.monotonic() < end, f"never printed 'waiting' ({forked=})"
                time.sleep(0.01)
            program.signal(signal.SIGINT)
        status = program.wait(WALL)
    finally:
        program.stop()
    output = re.sub(r"/\S+/(prog\.py)", r"\1", program.output_text())
    return status, output, program


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_a_forked_program_ends_as_an_execd_one(name: str, tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    execd, execd_output, plain = _run(tmp_path, name, False, monkeypatch)
    forked, forked_output, warm = _run(tmp_path, name, True, monkeypatch)
    assert not isinstance(plain.popen, ForkedProcess)
    assert isinstance(warm.popen, ForkedProcess)
    assert execd == forked == {"exit_code": 3, "crash": 1, "interrupted": -2}[name]
    assert forked_output == execd_output
    assert ("argv ['prog.py', '--ros-args']\ncwd True\npath0 True __main__\nenv 7 True\n"
            "switch 0.0005\n") in forked_output  # the GIL handed over within 0.5 ms (runner)
    if name == "exit_code":  # a subscription's QoS events wait with its message (runner)
        assert "held back True\nwaited on again True\n" in forked_output
    else:  # the traceback names the student's frames only
        assert "prog.py" in forked_output
        for ours in ("zygote", "runner", "<string>"):
            assert ours not in forked_output and ours not in execd_output


def test_a_program_gets_its_ctrl_c_however_the_grader_was_started(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A grader started in the background (``cmd &``, some CI runners) has SIGINT ignored,
    maybe signals blocked, and passes both on through fork and exec: the student's program
    still starts with them as a terminal gives them, forked or exec'd."""
    close_zygotes()  # a zygote started earlier has this process's dispositions of then
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGTERM])
    try:
        for forked in (False, True):
            status, output, _program = _run(tmp_path / str(forked), "interrupted", forked,
                                            monkeypatch)
            assert status == -signal.SIGINT, (forked, output)
            assert "KeyboardInterrupt" in output
    finally:
        signal.signal(signal.SIGINT, old)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, [signal.SIGTERM])
        close_zygotes()


def test_a_failure_before_the_program_is_the_launchers_either_way(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    class Unjoinable(process_module.Cgroup):  # a cgroup folder that is not there
        def __init__(self, *args: object) -> None:
            super().__init__(*args)  # type: ignore[arg-type]
            self.paths = [tmp_path / "no-such-cgroup", *self.paths]

    monkeypatch.setattr(process_module, "Cgroup", Unjoinable)
    for forked in (False, True):
        monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1" if forked else "0")
        staged = tmp_path / str(forked) / "staged"
        staged.mkdir(parents=True)
        (staged / "prog.py").write_text("print('never')\n")
        program = student_process(staged / "prog.py", [], Limits(), domain=7, strict=False,
                                  course=ROOT)
        with pytest.raises(LaunchFailed) as failed:
            program.start()
        assert failed.value.stage == "cgroup"
        assert "never" not in program.output_text()


@pytest.fixture
def fresh_zygotes() -> Iterator[None]:
    """No zygote from an earlier test, nor a failed start remembered, before or after."""
    close_zygotes()
    yield
    close_zygotes()


@pytest.mark.usefixtures("fresh_zygotes")
def test_a_dead_zygote_leaves_its_programs_killed_and_later_ones_execd(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1")
    staged = tmp_path / "staged"
    staged.mkdir()
    (staged / "prog.py").write_text("import time\nprint('up', flush=True)\ntime.sleep(60)\n")

    def start() -> StudentProcess:
        program = student_process(staged / "prog.py", [], Limits(), domain=7, strict=False,
                                  course=ROOT)
        program.start()
        return program

    first = start()
    try:
        assert isinstance(first.popen, ForkedProcess)
        (zygote,) = zygotes()
        os.kill(zygote.process.pid, signal.SIGKILL)
        zygote.process.wait()
        assert first.wait(0.5) is None  # still running, though its zygote is gone
        first.signal(signal.SIGKILL)
        assert first.wait(10.0) == -signal.SIGKILL
        second = start()
        try:
            assert not isinstance(second.popen, ForkedProcess)
        finally:
            second.stop()
    finally:
        first.stop()


def _sleeper(tmp_path: Path) -> Path:
    staged = tmp_path / "staged"
    staged.mkdir()
    (staged / "prog.py").write_text("import time\nprint('up', flush=True)\ntime.sleep(60)\n")
    return staged / "prog.py"


def _started(script: Path) -> StudentProcess:
    program = student_process(script, [], Limits(), domain=7, strict=False, course=ROOT)
    program.start()
    return program


def _within(condition: Callable[[], bool]) -> bool:
    """Whether ``condition()`` holds within WALL seconds."""
    end = time.monotonic() + WALL
    while not condition():
        if time.monotonic() > end:
            return False
        time.sleep(0.01)
    return True


def _says_up(program: StudentProcess) -> bool:
    """Whether the program printed its first line within WALL seconds."""
    return _within(lambda: program.output_text().startswith("up\n"))


def _reaches(pid: int, state: bytes) -> bool:
    """Whether ``pid`` is in ``state`` (a ``/proc`` state letter) within WALL seconds."""
    return _within(lambda: process_state(pid) == state)


# Attaches to a pid as a tracer (as tests/submissions/hostile/snoops_processes does) and
# stays, so the tracee stays stopped.
TRACER = """\
import ctypes, sys, time
attached = ctypes.CDLL(None, use_errno=True).ptrace(16, int(sys.argv[1]), None, None) == 0
print("attached" if attached else "refused", flush=True)
time.sleep(600)
"""


@pytest.mark.usefixtures("fresh_zygotes")
def test_a_stopped_zygote_is_woken_and_forks_the_next_program(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the student's user is the grader's (basic isolation), a program can SIGSTOP
    the zygote, or trace it and end, which leaves it stopped: the next launch wakes it and
    is forked as before (it waited 30 s for an answer, then was exec'd)."""
    monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1")
    script = _sleeper(tmp_path)
    _started(script).stop()
    (zygote,) = zygotes()
    os.kill(zygote.process.pid, signal.SIGSTOP)
    assert _reaches(zygote.process.pid, b"T")
    program = _started(script)
    try:
        assert isinstance(program.popen, ForkedProcess)
        assert _says_up(program)
    finally:
        program.stop()


@pytest.mark.usefixtures("fresh_zygotes")
def test_a_zygote_held_by_a_tracer_is_given_up_for_exec(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A zygote a tracer holds answers nothing while the tracer stays: the next launch
    ends it (it waited 30 s for an answer and kept asking it) and is exec'd, the program
    it forked before is still the grader's to end, and ending the zygotes does not wait
    for the tracer to let the dead one go (it waited as long as the tracer stayed)."""
    monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1")
    script = _sleeper(tmp_path)
    first = _started(script)
    (zygote,) = zygotes()
    tracer = subprocess.Popen([sys.executable, "-c", TRACER, str(zygote.process.pid)],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert tracer.stdout is not None
        if tracer.stdout.readline().strip() != "attached":
            pytest.skip("this machine lets no process trace another of its user (Yama)")
        assert _reaches(zygote.process.pid, b"t")
        second = _started(script)
        try:
            assert not isinstance(second.popen, ForkedProcess)
            assert _says_up(second)
            # Killed: a zombie, reaped once its tracer lets it go.
            assert _reaches(zygote.process.pid, b"Z")
        finally:
            second.stop()
        assert first.wait(0.5) is None
        first.signal(signal.SIGKILL)
        assert first.wait(WALL) == -signal.SIGKILL
        # Ending the zygotes (at the child's exit) does not wait for the tracer.
        monkeypatch.setattr(zygote_module, "CLOSE_WITHIN", 0.2)
        closing = threading.Thread(target=close_zygotes, daemon=True)
        closing.start()
        closing.join(WALL)
        assert not closing.is_alive()
    finally:
        tracer.kill()
        tracer.wait()
        first.stop()


@pytest.mark.usefixtures("fresh_zygotes")
def test_a_zygote_that_cannot_start_costs_only_its_own_launches(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An interpreter that is not there (test_launch's case) fails its own zygote, and
    the launcher reports it; the next program, run by the real interpreter, is forked."""
    monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1")
    for name, python in (("missing", "/nonexistent/python3"), ("real", None)):
        if python is None:
            monkeypatch.delenv("AUTOGRADER_STUDENT_PYTHON")
        else:
            monkeypatch.setenv("AUTOGRADER_STUDENT_PYTHON", python)
        staged = tmp_path / name / "staged"
        staged.mkdir(parents=True)
        (staged / "prog.py").write_text("print('ran')\n")
        program = student_process(staged / "prog.py", [], Limits(), domain=7, strict=False,
                                  course=ROOT)
        if python is not None:
            with pytest.raises(LaunchFailed) as failed:
                program.start()
            assert failed.value.stage == f"exec {python}"
            continue
        program.start()
        try:
            assert isinstance(program.popen, ForkedProcess)
            assert program.wait(30.0) == 0
        finally:
            program.stop()
        assert program.output_text() == "ran\n"


def test_the_zygotes_descriptors_are_closed_before_lttngs_threads_start_again(
        tmp_path: Path) -> None:
    """In the forked child, LTTng's after-fork hook starts listener threads that open
    sockets at once.  The zygote's descriptors are closed before that hook runs, so nothing
    the hook opens is closed behind its back (CI once saw a listener's close take the
    student's cgroup file: "the launcher failed at cgroup: Bad file descriptor")."""
    from autograder.sandbox.contained.zygote import close_all_but, fork_with_hooks

    report_read, report_write = os.pipe()
    leftover = os.open(tmp_path, os.O_RDONLY)  # a descriptor of the zygote's own
    opened: list[int] = []

    def child_hook(_saved: object) -> None:  # what LTTng's listener threads do
        opened.append(os.open(os.devnull, os.O_RDONLY))

    def nothing(_saved: object) -> None:
        return None

    fork = fork_with_hooks([(nothing, nothing, child_hook, None)])
    pid = fork(lambda: close_all_but([report_write]))
    if pid == 0:
        def is_open(fd: int) -> bool:
            try:
                os.fstat(fd)
            except OSError:
                return False
            return True
        os.write(report_write, f"{is_open(opened[0])} {is_open(leftover)}".encode())
        os._exit(0)
    os.close(report_write)
    os.close(leftover)
    try:
        report = os.read(report_read, 100).decode()
    finally:
        os.close(report_read)
        os.waitpid(pid, 0)
    assert report == "True False", "the hook's descriptor, then the zygote's leftover"


@pytest.mark.usefixtures("fresh_zygotes")
def test_a_programs_orphans_are_the_zygotes_to_reap(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A child left by a program that ended (a fork bomb's, once it is killed) goes to the
    zygote, which reaps it at once, instead of to the machine's init: until reaped it
    counts against its user's RLIMIT_NPROC (tests/sandbox/test_user_budget.py). The zygote
    reports it as it reports its programs."""
    monkeypatch.setenv("AUTOGRADER_ZYGOTE", "1")
    staged = tmp_path / "staged"
    staged.mkdir()
    (staged / "prog.py").write_text(
        "import os, sys, time\n"
        "parent = os.getpid()  # before the fork: the parent may be gone before the child runs\n"
        "if os.fork() == 0:\n"
        "    end = time.monotonic() + 60\n"
        "    while os.getppid() == parent and time.monotonic() < end:\n"
        "        time.sleep(0.01)\n"
        "    print('orphan', os.getpid(), os.getppid(), flush=True)\n"
        "    os._exit(0)\n"
        "print('parent', os.getpid(), flush=True)\n")
    program = student_process(staged / "prog.py", [], Limits(), domain=7, strict=False,
                              course=ROOT)
    program.start()
    try:
        assert isinstance(program.popen, ForkedProcess)
        (zygote,) = zygotes()
        assert program.wait(WALL) == 0
        end = time.monotonic() + WALL
        while "orphan" not in program.output_text():
            assert time.monotonic() < end, program.output_text()
            time.sleep(0.01)
        orphan, adopter = (int(word) for word in
                           program.output_text().split("orphan ", 1)[1].split()[:2])
        assert adopter == zygote.process.pid
        assert zygote.status(orphan, WALL) == 0  # reaped by the zygote, and reported
    finally:
        program.stop()
