"""Every command cleans up however it ends (issue 31): Ctrl-C, SIGTERM, SIGHUP, its parent
killed, its output pipe closed. Each case runs the real command in a temporary folder of
its own (``TMPDIR``), waits until it runs (the student's program up, where there is one),
ends it, and then finds no process working in that folder and nothing left in it but the
domain locks. Every wait is for a condition, with a deadline."""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from pasted import as_a_terminal_starts_it

REPO = Path(__file__).resolve().parents[2]
NODES = REPO / "tests" / "fixtures" / "hand_node"
AUTOGRADER = str(Path(sys.executable).with_name("autograder"))
NOBODY = 65534
WALL = 240.0  # generous wall seconds for a command to get going on a loaded machine
AS_ROOT = os.geteuid() == 0
needs_root = pytest.mark.skipif(not AS_ROOT or not shutil.which("setpriv"),
                                reason="needs root (and setpriv) to act as another user")


@dataclasses.dataclass
class Work:
    """A case's folder (every user may pass through it), its TMPDIR and its files."""

    folder: Path
    domain: int
    user: int | None  # None: this test's user

    @property
    def tmp(self) -> Path:
        return self.folder / "tmp"

    def env(self) -> dict[str, str]:
        env = {"PATH": os.environ.get("PATH", ""), "LANG": "C.UTF-8",
               "HOME": str(self.folder), "TMPDIR": str(self.tmp),
               "XDG_CACHE_HOME": str(self.folder / "cache"),
               "AUTOGRADER_COURSE": str(self.folder / "course"),
               # The machine's lock folder: a private TMPDIR must not hide others' domains.
               "AUTOGRADER_LOCK_DIR": str(Path(tempfile.gettempdir()) / "autograder-domains"),
               "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
        return env

    def command(self, args: list[str]) -> list[str]:
        prefix = [] if self.user is None else [
            "setpriv", f"--reuid={self.user}", f"--regid={self.user}", "--clear-groups"]
        return [*prefix, AUTOGRADER, *args]


@pytest.fixture()
def work(request: pytest.FixtureRequest, ros_domain: int) -> Iterator[Work]:
    folder = Path(tempfile.mkdtemp(prefix="ending-"))
    try:
        course = folder / "course" / "assignments" / "parameter_validation"
        shutil.copytree(REPO / "assignments" / "parameter_validation", course)
        shutil.copytree(REPO / "quizzes", folder / "course" / "quizzes")
        shutil.copy(course / "solution" / "velocity_governor.py", folder)
        shutil.copy(NODES / "talks_every_tick.py", folder)
        (folder / "tmp").mkdir()
        for path in [folder, *folder.rglob("*")]:
            path.chmod(0o777 if path.is_dir() else 0o666)
        (folder / "tmp").chmod(0o1777)
        yield Work(folder, ros_domain, getattr(request, "param", None))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@dataclasses.dataclass(frozen=True)
class Case:
    """A command as a student runs it, and how to tell that it runs."""

    args: Callable[[Work], list[str]]
    ready: str  # said once it runs
    student: bool  # the student's program runs by then
    on_sigint: int  # its status after Ctrl-C


COMMANDS = {
    "sim-run-node": Case(lambda w: ["sim", "run", "--domain", str(w.domain), "--node",
                                    "talks_every_tick.py", "--svg", "path.svg"],
                         "simulation time starts now", True, 0),
    "sim-drive": Case(lambda w: ["sim", "drive", "--domain", str(w.domain), "--linear", "0.1"],
                      "Driving on", False, 0),
    "check": Case(lambda w: ["check", "parameter_validation", "velocity_governor.py",
                             "--results", "r.json", "--html", "r.html"], "", True, 1),
    "grade": Case(lambda w: ["grade", "parameter_validation", "velocity_governor.py",
                             "--results", "r.json"], "", True, 1),
    "quiz-serve": Case(lambda w: ["quiz", "serve", "--port", "0"], "Quizzes at", False, 0),
}
SIGNALS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM, "SIGHUP": signal.SIGHUP}


def wait_for(condition: Callable[[], object], seconds: float, what: str | None) -> bool:
    """Wait until ``condition()`` holds (checked ten times a second), at most ``seconds``;
    past the deadline, fail saying ``what`` was awaited (None: return False)."""
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            if what is None:
                return False
            pytest.fail(f"not within {seconds:.0f} s: {what}")
        time.sleep(0.1)
    return True


def working_in(folder: Path) -> list[tuple[int, str]]:
    """Processes whose working directory is in ``folder``: (pid, directory)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                cwd = os.readlink(entry / "cwd")
            except OSError:
                continue
            if cwd == str(folder) or cwd.startswith(f"{folder}/"):
                found.append((int(entry.name), cwd))
    return found


def student_running(work: Work, grading: bool) -> bool:
    """The student's program runs: a process in a student working folder of the run's,
    and for a grading, a child pytest (a test program as the isolation check starts it
    runs before any child)."""
    folders = [Path(cwd).name for _pid, cwd in working_in(work.tmp)]
    return (any(f.startswith(("student-", "autograder-student-")) for f in folders)
            and (not grading or any(f.startswith("child-") for f in folders)))


def left_behind(work: Work) -> tuple[list[tuple[int, str]], list[str]]:
    """What the command left: processes working in its TMPDIR, and its folders (the
    domain locks are the machine's, not the command's)."""
    folders = sorted(p.name for p in work.tmp.iterdir()
                     if not p.name.startswith("autograder-domains"))
    return working_in(work.tmp), folders


def described(pid: int) -> str:
    """A left process, as a failure should name it: its user, parent and command."""
    try:
        status = dict(line.split(":\t", 1) for line in
                      Path(f"/proc/{pid}/status").read_text().splitlines() if ":\t" in line)
        command = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ")
    except OSError:
        return f"{pid} (gone)"
    return (f"{pid} uid {status.get('Uid', '?').split()[0]} parent {status.get('PPid')}: "
            f"{command[:200].decode(errors='replace')}")


def assert_nothing_left(work: Work, output: str) -> None:
    wait_for(lambda: left_behind(work) == ([], []), 15, None)
    processes, folders = left_behind(work)
    assert (processes, folders) == ([], []), (
        output + "\n".join(described(pid) for pid, _cwd in processes))


def started(case: Case, work: Work, **popen: object) -> subprocess.Popen[bytes]:
    return subprocess.Popen(work.command(case.args(work)), cwd=work.folder, env=work.env(),
                            preexec_fn=as_a_terminal_starts_it,
                            **popen)  # type: ignore[call-overload]


def wait_running(case: Case, work: Work, log: Path, process: subprocess.Popen[bytes]) -> None:
    def running() -> bool:
        if process.poll() is not None:
            pytest.fail(f"ended with {process.returncode} before it ran:\n"
                        f"{log.read_text(errors='replace')}")
        said = case.ready in log.read_text(errors="replace")
        grading = case.args(work)[0] in ("check", "grade")
        return said and (not case.student or student_running(work, grading))

    wait_for(running, WALL, f"{case.args(work)} running")


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=str)
@pytest.mark.parametrize("name", COMMANDS, ids=str)
def test_a_signal_ends_the_command_and_leaves_nothing(name: str, sig: str, work: Work) -> None:
    case = COMMANDS[name]
    log = work.folder / "out.txt"
    with log.open("wb") as out:
        process = started(case, work, stdout=out, stderr=subprocess.STDOUT)
    try:
        wait_running(case, work, log, process)
        process.send_signal(SIGNALS[sig])
        process.wait(WALL)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    output = log.read_text(errors="replace")
    expected = case.on_sigint if sig == "SIGINT" else 128 + SIGNALS[sig]
    assert process.returncode == expected, output
    if sig != "SIGINT":
        assert f"Stopped by {sig}." in output
    if name == "sim-run-node":
        assert "Sim time:" in output  # the world's summary, as after Ctrl-C
        assert (work.folder / "path.svg").read_text().rstrip().endswith("</svg>")
    if name == "sim-drive":
        assert "with a zero command" in output
    if name in ("check", "grade") and sig != "SIGINT":
        assert "The grading was stopped" in output
        assert not (work.folder / "r.json").exists()  # no score from a stopped grading
    assert_nothing_left(work, output)


@pytest.mark.slow
@pytest.mark.parametrize("name", COMMANDS, ids=str)
def test_a_killed_parent_ends_the_command_and_leaves_nothing(name: str, work: Work) -> None:
    """The terminal's shell killed (SIGKILL): the command hears SIGHUP from the kernel."""
    case = COMMANDS[name]
    log = work.folder / "out.txt"
    shell = subprocess.Popen(  # `; true`: the shell waits for the command, as a terminal's
        ["bash", "-c", 'cd "$1" && shift && "$@" > out.txt 2>&1; true', "shell",
         str(work.folder), *work.command(case.args(work))],
        env=work.env(), start_new_session=True, preexec_fn=as_a_terminal_starts_it)
    try:
        children = Path(f"/proc/{shell.pid}/task/{shell.pid}/children")
        wait_for(lambda: log.exists() and children.read_text().split(), WALL, "the command")
        command = int(children.read_text().split()[0])
        wait_running(case, work, log, shell)
        shell.kill()
        shell.wait()
        wait_for(lambda: not Path(f"/proc/{command}").exists(), 60, "the command's end")
    finally:
        if shell.poll() is None:
            shell.kill()
            shell.wait()
    output = log.read_text(errors="replace")
    assert "Stopped by SIGHUP." in output
    assert_nothing_left(work, output)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["check", "sim-run-node"], ids=str)
def test_a_closed_pipe_is_no_error_and_every_file_is_written(name: str, work: Work) -> None:
    """``| head -1``: check goes on grading and writes its files; a hand run (running until
    stopped) ends as Ctrl-C ends it, its picture written; both exit 0."""
    case = COMMANDS[name]
    if name == "check":  # every format there is
        case = dataclasses.replace(case, args=lambda w: [
            *COMMANDS["check"].args(w), "--gradescope", "g.json", "--junit", "j.xml"])
    process = started(case, work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        assert process.stdout is not None
        first = process.stdout.readline()  # what head -1 reads; then it is gone
        process.stdout.close()
        process.wait(WALL)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert first
    assert process.returncode == 0
    if name == "check":
        results = json.loads((work.folder / "r.json").read_text())
        assert results["score"] == results["max_score"] > 0
        assert (work.folder / "r.html").read_text().rstrip().endswith("</html>")
        assert (work.folder / "r.log").exists()
        assert json.loads((work.folder / "g.json").read_text())["score"] > 0
        assert (work.folder / "j.xml").read_text().rstrip().endswith("</testsuites>")
    else:
        assert (work.folder / "path.svg").read_text().rstrip().endswith("</svg>")
    assert_nothing_left(work, first.decode(errors="replace"))


@pytest.mark.slow
def test_check_says_where_it_wrote_each_file(work: Work) -> None:
    done = subprocess.run(work.command(COMMANDS["check"].args(work)), cwd=work.folder,
                          env=work.env(), capture_output=True, text=True, timeout=WALL)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Wrote r.html (--html): open it in a browser." in done.stderr
    assert "Wrote r.json (--results)." in done.stderr
    assert "Wrote r.log: the programs' whole output." in done.stderr


@pytest.mark.slow
@needs_root
@pytest.mark.parametrize("work", [NOBODY], indirect=True, ids=["nobody"])
@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP"], ids=str)
@pytest.mark.parametrize("name", ["sim-run-node", "check", "grade"], ids=str)
def test_as_an_ordinary_user_a_signal_leaves_nothing(name: str, sig: str, work: Work) -> None:
    test_a_signal_ends_the_command_and_leaves_nothing(name, sig, work)


@pytest.mark.slow
@needs_root
@pytest.mark.parametrize("work", [NOBODY], indirect=True, ids=["nobody"])
@pytest.mark.parametrize("name", ["sim-run-node", "check"], ids=str)
def test_as_an_ordinary_user_a_killed_parent_leaves_nothing(name: str, work: Work) -> None:
    test_a_killed_parent_ends_the_command_and_leaves_nothing(name, work)


def test_nohup_and_setsid_keep_a_command_past_its_parent() -> None:
    """Asked to outlive its parent (SIGHUP ignored, or a session of its own), a command
    sets no parent-death signal; otherwise it sets SIGHUP, and puts back what it found."""
    probe = ("import ctypes, signal, sys\n"
             "from autograder.commands.ending import handled\n"
             "libc = ctypes.CDLL(None)\n"
             "def now():\n"
             "    v = ctypes.c_int(); libc.prctl(2, ctypes.byref(v), 0, 0, 0); return v.value\n"
             "with handled():\n"
             "    inside = now()\n"
             "print(inside, now())\n")
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    plain = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                           text=True, check=True, preexec_fn=as_a_terminal_starts_it)
    assert plain.stdout.split() == [str(int(signal.SIGHUP)), "0"]
    for prefix in (["nohup"], ["setsid", "--wait"]):
        kept = subprocess.run([*prefix, sys.executable, "-c", probe], env=env,
                              capture_output=True, text=True, check=True,
                              preexec_fn=as_a_terminal_starts_it)
        assert kept.stdout.split() == ["0", "0"], prefix


def test_a_reader_gone_before_the_first_line_is_no_error(tmp_path: Path) -> None:
    """``autograder list | true``: nothing is printed to a traceback, and the status is 0."""
    read, write = os.pipe()
    os.close(read)  # the reader is gone before anything is written
    try:
        done = subprocess.run([AUTOGRADER, "list"], stdout=write, stderr=subprocess.PIPE,
                              text=True, timeout=60, cwd=REPO)
    finally:
        os.close(write)
    assert (done.returncode, done.stderr) == (0, "")


def test_quiz_score_writes_its_files_first_and_says_where(tmp_path: Path) -> None:
    quiz = json.loads(subprocess.run([AUTOGRADER, "list", "--json"], capture_output=True,
                                     text=True, check=True, cwd=REPO).stdout)["quizzes"][0]
    answers = tmp_path / "answers.json"
    answers.write_text(subprocess.run([AUTOGRADER, "quiz", "key", quiz["id"]], cwd=REPO,
                                      capture_output=True, text=True, check=True).stdout)
    read, write = os.pipe()
    os.close(read)
    try:
        done = subprocess.run([AUTOGRADER, "quiz", "score", quiz["id"], str(answers),
                               "--results", str(tmp_path / "r.json"),
                               "--html", str(tmp_path / "r.html")],
                              stdout=write, stderr=subprocess.PIPE, text=True, timeout=60,
                              cwd=REPO)
    finally:
        os.close(write)
    assert done.returncode == 0, done.stderr
    assert json.loads((tmp_path / "r.json").read_text())["score"] > 0
    assert (tmp_path / "r.html").read_text().rstrip().endswith("</html>")
    assert f"Wrote {tmp_path / 'r.json'} (--results)." in done.stderr
    assert f"Wrote {tmp_path / 'r.html'} (--html): open it in a browser." in done.stderr


def test_signals_while_it_cleans_up_do_not_cut_the_cleanup_short() -> None:
    """A closed terminal sends SIGHUP more than once (to the group, from the shell, at the
    shell's death): the first stops the command, the rest wait for its cleanup."""
    probe = ("import os, signal\n"
             "from autograder.commands.ending import Stopped, handled\n"
             "with handled() as state:\n"
             "    try:\n"
             "        os.kill(os.getpid(), signal.SIGHUP)\n"
             "        signal.pause()\n"
             "    except Stopped as stop:\n"
             "        os.kill(os.getpid(), signal.SIGHUP)\n"
             "        os.kill(os.getpid(), signal.SIGTERM)\n"
             "        print('cleaned up after', stop.name)\n"
             "    print('exit', state.exit_status(0))\n")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=60,
                          preexec_fn=as_a_terminal_starts_it)
    assert done.stdout.splitlines() == ["cleaned up after SIGHUP", "exit 129"], done.stderr
