"""The child pytests of one grading: started, watched, stopped at the time limit, reaped.

Each child runs a group of whole test modules on a ROS domain of its own, with its own
signed report, key, lifeline and settings (see :func:`autograder.grading.run.grade`).
The child inherits its domain's lock (it holds the domain as long as it lives) and the
read end of a *lifeline* pipe whose write end only the grader holds: when the grader
dies, however it dies, the child sees the pipe close and ends itself and every student
process it started (see ``autograder.plugin``).  It is forked from this process's
template where there is one (:mod:`autograder.grading.forked`), else exec'd as
``python -m pytest``: the same child either way.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import secrets
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from autograder.core import report
from autograder.core.report import RawReport, RawTest
from autograder.core.settings import RunSettings
from autograder.grading import forked
from autograder.grading.footprint import Footprint
from autograder.grading.forked import ForkedChild, TemplateGone
from autograder.sandbox.domains import DomainLock
from autograder.sandbox.isolation import Isolation, run_prefix, student_uid
from autograder.sandbox.process import reap_recorded
from autograder.sandbox.sweep import sweep_user
from sim.procstate import process_state

Progress = Callable[[RawTest], None]
Process = subprocess.Popen[bytes] | ForkedChild


@dataclasses.dataclass(frozen=True)
class Watchers:
    """Who is told how the run goes (see :func:`autograder.grading.run.grade`)."""

    progress: Progress | None = None
    running: Callable[[list[RawTest]], None] | None = None  # the tests running now


@dataclasses.dataclass
class Child:
    """One running child pytest and where it reports."""

    process: Process
    report_path: Path
    key: bytes
    log_path: Path
    launched: float  # monotonic, the same clock in both processes
    # The student's own user in this child's runs (strict and user isolation), else None.
    uid: int | None = None
    timed_out: bool = False
    stopped: bool = False  # something stopped it (SIGSTOP): what it reports is not trusted
    # The report's tests as last read, and the file's (inode, size, mtime) then.
    tests: list[RawTest] = dataclasses.field(default_factory=list)
    seen: tuple[int, int, int] | None = None
    # The key pipe's write end while the key is held back (see :func:`started`).
    key_pipe: int | None = None

    def release(self) -> None:
        """Send the child its key: until then it waits, having started pytest and the
        plugin, before it collects a test or starts anything."""
        if self.key_pipe is not None:
            pipe, self.key_pipe = self.key_pipe, None
            with os.fdopen(pipe, "wb") as out:
                out.write(self.key)

    def discard(self) -> None:
        """End a child whose key was held back (it has started nothing), unreported."""
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.process.pid, signal.SIGKILL)
        self.process.wait()
        if self.key_pipe is not None:
            os.close(self.key_pipe)
            self.key_pipe = None

    def reported_tests(self) -> list[RawTest]:
        """The tests as the report says now, read again only when the file changed: it is
        replaced whole on each write (a new inode), and unchanged most of the time, while
        parsing it (the world's recordings in it) is not cheap."""
        try:
            stat = self.report_path.stat()
        except OSError:
            return self.tests
        stamp = (stat.st_ino, stat.st_size, stat.st_mtime_ns)
        if stamp != self.seen:
            self.tests, self.seen = report.read(self.report_path, self.key).tests, stamp
        return self.tests


@dataclasses.dataclass(frozen=True)
class Ended:
    """One child after it ended: its report (with the programs' logs), exit status and
    pytest's own output."""

    raw: RawReport
    returncode: int | None
    timed_out: bool
    pytest_log: str
    launched: float
    stopped: bool = False

    @property
    def broken(self) -> bool:
        """It ended without reporting its tests: a crash or a test file that does not
        import, or the time limit before any test was collected; or something stopped it
        (a program of the grader's own user, in basic isolation): never a verdict.  How it
        ended may be unknown (None: the template it was forked from died): broken too,
        unless the time limit ended it (then the grader's own kill did)."""
        return (self.returncode not in (0, 1) and not self.timed_out) or self.stopped or (
            not self.raw.forged and not self.raw.tests)


def bytecode_cache() -> Path:
    """Where child pytests keep their compiled modules: a cache folder of this user's."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "rclpy-autograder" / "pycache"


def bytecode_env(env: dict[str, str]) -> dict[str, str]:
    """``env`` for a child pytest: compiled modules (the grader's, the exercise's tests)
    kept in :func:`bytecode_cache`, never beside the sources, so no bytecode of hidden tests
    lands in the course; where that folder cannot be made, none written at all.  Each
    child then starts without compiling what the one before it compiled."""
    env = dict(env)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    try:
        cache = bytecode_cache()
        cache.mkdir(mode=0o700, parents=True, exist_ok=True)
        usable = os.access(cache, os.W_OK | os.X_OK)
    except (OSError, RuntimeError):  # RuntimeError: no home folder to be found
        usable = False
    if usable:
        env["PYTHONPYCACHEPREFIX"] = str(cache)
    else:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        env.pop("PYTHONPYCACHEPREFIX", None)
    return env


# What the grader's environment may say to any pytest: options (-x stops at the first
# failed test, and with it the score), plugins to load, whether to load installed ones.
_PYTEST_VARIABLES = ("PYTEST_ADDOPTS", "PYTEST_PLUGINS", "PYTEST_DISABLE_PLUGIN_AUTOLOAD",
                     "PYTEST_DEBUG", "PYTEST_CURRENT_TEST", "PYTEST_VERSION")


def pytest_env(env: dict[str, str]) -> dict[str, str]:
    """``env`` for a child pytest: the same tests, options and plugins whoever grades.
    Nothing of the caller's pytest settings reaches it, and no installed plugin loads but
    ours (named with ``-p``): a pytest-randomly would reorder the tests, a rerun plugin
    grade twice, an ``-x`` in ``PYTEST_ADDOPTS`` stop at the first failure."""
    env = {k: v for k, v in env.items() if k not in _PYTEST_VARIABLES}
    env["PYTEST_DISABLE_PLUGIN_AUTOLOAD"] = "1"
    return env


@contextlib.contextmanager
def started(isolation: Isolation, settings: RunSettings, targets: Sequence[str],
            folder: Path, rootdir: Path, lock: DomainLock, *,
            zygote: bool = True, hold_key: bool = False) -> Iterator[Child]:
    """Start one child pytest over ``targets`` (test folders or modules) in ``folder``, in
    namespaces of its own in strict ``isolation``; its lifeline closes when the block
    ends.  ``zygote``: whether it forks students' programs from a zygote (see
    :func:`autograder.sandbox.process.warm_start`).  ``hold_key``: its key is sent only at
    :meth:`Child.release` (it waits for it)."""
    folder.mkdir(parents=True, exist_ok=True)
    report_path = folder / "report.json"
    key = secrets.token_bytes(32)
    key_read, key_write = os.pipe()
    life_read, life_write = os.pipe()
    settings = dataclasses.replace(settings, report=str(report_path), key_fd=key_read,
                                   lifeline_fd=life_read, domain=lock.domain)
    args = [
        "-q", "-p", "no:cacheprovider", "-p", "autograder.plugin", "--rootdir", str(rootdir),
        "--basetemp", str(folder / "pytest"), "--autograder-settings", settings.to_json(),
        *targets,
    ]
    env = pytest_env(bytecode_env(dict(os.environ)))
    if not zygote:
        env["AUTOGRADER_ZYGOTE"] = "0"
    log_path = folder / "pytest.log"
    child: Child | None = None
    try:
        with log_path.open("wb") as log:
            launched = time.monotonic()
            process = _launch(isolation, args, folder, env, log.fileno(),
                              (key_read, life_read, *lock.fds))
        os.close(key_read)
        os.close(life_read)
        child = Child(process, report_path, key, log_path, launched,
                      student_uid(lock.domain) if settings.own_user else None,
                      key_pipe=key_write)
        if not hold_key:
            child.release()
        yield child
    finally:
        if child is not None and child.key_pipe is not None:  # never released: it ends
            child.discard()
        os.close(life_write)


def _launch(isolation: Isolation, args: Sequence[str], folder: Path, env: dict[str, str],
            log: int, passed: Sequence[int]) -> Process:
    """The child pytest forked from this process's template, else (none, or it could not
    fork) exec'd as ``python -m pytest``, in strict isolation through ``unshare``.

    Only where the student has a user of its own: in basic isolation its program is the
    grader's user and may stop any process of it, the template too, whose children's
    exit statuses would then never come; an exec'd child is the grader's own child, whose
    end the grader sees whatever the program does."""
    warm = forked.shared(env) if isolation.own_user else None
    if warm is not None:
        with contextlib.suppress(TemplateGone):
            return warm.spawn(args, str(folder), env, log, passed, namespaces=isolation.strict)
    return subprocess.Popen([*run_prefix(isolation), sys.executable, "-m", "pytest", *args],
                            cwd=folder, env=env, stdout=log, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, start_new_session=True,
                            pass_fds=passed)


def forked_from(children: Sequence[Child]) -> list[int]:
    """The templates ``children`` were forked from (their pids): processes of the
    grading's tree that are not its children's ancestors."""
    return sorted({c.process.template for c in children if isinstance(c.process, ForkedChild)})


def wait(children: Sequence[Child], limit: float, watchers: Watchers,
         footprint: Footprint | None = None) -> None:
    """Wait for every child, telling ``watchers`` as tests run and finish; a child still
    running ``limit`` seconds from now is stopped (``timed_out``) with all it started.
    ``footprint``, if given, samples the grading's memory meanwhile (it keeps to its own
    interval, every fourth of these wake-ups)."""
    deadline = time.monotonic() + limit
    reported: set[str] = set()
    while True:
        live = [c for c in children if c.process.poll() is None]
        for child in live:
            if _stopped(child.process.pid):  # only a signal from outside stops it
                os.killpg(child.process.pid, signal.SIGKILL)
                child.process.wait()
                child.stopped = True
        if live and footprint is not None:
            footprint.sample()
        if live:
            with contextlib.suppress(subprocess.TimeoutExpired):
                live[0].process.wait(timeout=0.25)
        finished = all(c.process.poll() is not None for c in children)
        if watchers.progress is not None or watchers.running is not None:
            now = _tell(children, reported, watchers)
            if watchers.running is not None:
                watchers.running([] if finished else now)
        if finished:
            return
        if time.monotonic() > deadline:
            for child in children:
                if child.process.poll() is None:
                    os.killpg(child.process.pid, signal.SIGKILL)
                    child.process.wait()
                    child.timed_out = True
            return


def _stopped(pid: int) -> bool:
    """Whether process ``pid`` is stopped (``T``) or held by a tracer (``t``)."""
    return process_state(pid) in (b"T", b"t")


def _tell(children: Sequence[Child], reported: set[str], watchers: Watchers) -> list[RawTest]:
    """Tell ``progress`` each test that finished since last time; the tests that run now,
    one per running child (each runs its tests in collection order: the first not done),
    so that whichever ends next was among them."""
    running = []
    for child in children:
        tests = child.reported_tests()
        for test in tests:
            if test.done and test.nodeid not in reported:
                reported.add(test.nodeid)
                if watchers.progress is not None:
                    watchers.progress(test)
        now = next((t for t in tests if not t.done), None)
        if now is not None and child.process.returncode is None:
            running.append(now)
    return running


def abandon(running: Sequence[Child], grace: float = 10.0) -> None:
    """The grading was stopped before its children ended (a signal, Ctrl-C), and their
    lifelines are closed: each ends what it started and then itself. Wait for that (at
    most ``grace`` seconds in all), then kill what is left and reap every program their
    reports name, so that nothing of the student's outlives the grader and its folder
    can go."""
    deadline = time.monotonic() + grace
    for child in running:
        with contextlib.suppress(subprocess.TimeoutExpired):
            child.process.wait(max(0.0, deadline - time.monotonic()))
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(child.process.pid, signal.SIGKILL)
        with contextlib.suppress(subprocess.TimeoutExpired):
            child.process.wait(5.0)
        reap_recorded(report.read(child.report_path, child.key).processes)
        # A program the child was starting when it was killed has no record: where the
        # student has a user of its own, that user's sweep ends it all the same.
        if child.uid is not None:
            sweep_user(child.uid)


def end(child: Child) -> Ended:
    """The child's report, read (with its programs' logs) before anything is removed, and
    everything it started reaped (its process group, the students' cgroups)."""
    raw = report.read(child.report_path, child.key, with_logs=True)
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(child.process.pid, signal.SIGKILL)
    reap_recorded(raw.processes)
    log = child.log_path.read_text(errors="replace")
    if child.stopped:
        log += ("\nThe grading's pytest process was stopped from outside (SIGSTOP or a "
                "tracer): its report is not trusted.\n")
    returncode = child.process.returncode
    if isinstance(child.process, ForkedChild) and child.process.lost:
        returncode = None
        log += ("\nThe process this pytest was forked from ended before it did: how it "
                "ended is unknown.\n")
    return Ended(raw, returncode, child.timed_out, log, child.launched, child.stopped)
