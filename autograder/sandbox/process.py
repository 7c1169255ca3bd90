"""Run a student's program as its own process, contained and bounded.

Each program runs through :mod:`autograder.sandbox.contained.launcher` in its own session
and process group, in a throwaway working directory, with a minimal environment and resource limits.
Where the machine lets us create cgroups (v1 ``pids`` and ``memory``), the program also
runs in a cgroup of its own: that bounds processes even for root and lets :meth:`stop`
find and kill everything it started, daemons that left the session included.
"""

from __future__ import annotations

import atexit
import contextlib
import dataclasses
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from autograder.core.errors import GraderError
from autograder.core.exercise import Limits
from autograder.sandbox.cgroups import Cgroup
from autograder.sandbox.contained import runner
from autograder.sandbox.privileged import PACKAGE_PARENT, SAFE_CWD, module_command
from autograder.sandbox.sweep import is_student_uid, kill_user, sweep_user, user_processes
from sim.procstate import descendants

_PASS_THROUGH = (
    "PATH", "LD_LIBRARY_PATH", "PYTHONPATH", "AMENT_PREFIX_PATH", "ROS_DISTRO", "ROS_VERSION",
    "ROS_PYTHON_VERSION", "RMW_IMPLEMENTATION", "LANG", "LC_ALL", "TZ",
)


STUDENT_PROFILE = ".fastdds_profile.xml"
"""The name of the student's copy of the Fast DDS profile in its working directory."""


# The folders of students' programs in strict isolation, in the system's temporary folder.
STRICT_WORKDIR_PREFIX = "autograder-student-"


def student_process(script: Path, ros_args: list[str], limits: Limits, *, domain: int,
                    course: Path, strict: bool = False,
                    mode: str | None = None) -> StudentProcess:
    """The student's program as every launch prepares it: a copy of ``script`` and its
    sibling modules in a working directory of its own, a minimal environment on ROS
    domain ``domain``, and in isolation ``mode`` (``strict``, ``user``, ``basic``;
    ``strict=True`` says ``strict``) a user of its own, with the course hidden by
    namespaces (strict) or closed to it by permissions (user: see ``grading.run``).

    The grading (``autograder.plugin.launch``) and strict isolation's start-up check
    (``autograder.sandbox.isolation``) both start programs through here, so the check proves what
    a real launch does."""
    from autograder.sandbox.isolation import (
        PROFILE_ENV,
        Isolation,
        dds_env,
        protected_paths,
        student_uid,
    )

    isolation = Isolation(mode or ("strict" if strict else "basic"))  # type: ignore[arg-type]
    # A user of its own: a folder outside the grader's (0700) run folder, which the
    # launcher turns into the student's own tmpfs (strict) or gives to its user (user).
    # Basic: a throwaway folder beside the staged copy.
    own = isolation.own_user
    workdir = Path(tempfile.mkdtemp(prefix=STRICT_WORKDIR_PREFIX if own else "student-",
                                    dir=None if own else script.parent.parent))
    for source in script.parent.glob("*.py"):
        (workdir / source.name).write_bytes(source.read_bytes())
    middleware = dds_env(isolation)
    profile = workdir / STUDENT_PROFILE
    profile.write_bytes(Path(middleware[PROFILE_ENV] or "").read_bytes())
    env = minimal_env(workdir, {"ROS_DOMAIN_ID": str(domain), **middleware,
                                PROFILE_ENV: str(profile)})
    process = StudentProcess(workdir / script.name, workdir, ros_args, env, limits)
    if own:
        process.uid = student_uid(domain)
        process.namespaces = isolation.strict
        if isolation.strict:
            process.hide = protected_paths(course)
    return process


def student_python() -> str:
    """The interpreter that runs students' programs: ``AUTOGRADER_STUDENT_PYTHON``, else
    the grader's own (which has rclpy)."""
    return os.environ.get("AUTOGRADER_STUDENT_PYTHON") or sys.executable


def reap_recorded(records: Iterable[dict[str, Any]]) -> None:
    """Kill student processes known only by their records in the raw report (``pid`` and
    ``cgroups``), from another process: each one's process group and everything in its
    cgroups; then every process of each own user (``uid``, strict isolation), once a user
    however many of its programs the run recorded (a sweep reads the scratch folders
    whole), and remove their folders (``workdir``, strict isolation), which the run that
    started them removes when it stops a program, but not when the run itself is killed."""
    records = list(records)
    for record in records:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(record["pid"], signal.SIGKILL)
        group = Cgroup.existing(record.get("cgroups", []))
        group.kill_all()
        group.remove()
    users = {record.get("uid") for record in records}
    for uid in sorted(u for u in users if isinstance(u, int) and is_student_uid(u)):
        sweep_user(uid)
    for record in records:
        workdir = record.get("workdir")
        if isinstance(workdir, str) and is_strict_workdir(Path(workdir)):
            shutil.rmtree(workdir, ignore_errors=True)


def is_strict_workdir(path: Path) -> bool:
    """Whether ``path`` is a folder :func:`student_process` makes in strict isolation (the
    only ones a report may name for removal)."""
    return (path.parent == Path(tempfile.gettempdir())
            and path.name.startswith(STRICT_WORKDIR_PREFIX) and not path.is_symlink())


def minimal_env(workdir: Path, extra: dict[str, str | None]) -> dict[str, str]:
    env = {key: os.environ[key] for key in _PASS_THROUGH if key in os.environ}
    env.update({
        "HOME": str(workdir),
        "TMPDIR": str(workdir),
        "ROS_LOG_DIR": str(workdir / ".ros" / "log"),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "PYTHONUNBUFFERED": "1",
        "PYTHONDONTWRITEBYTECODE": "1",
        "RCUTILS_COLORIZED_OUTPUT": "0",
        # glibc makes an arena per thread (64 MiB of address space each): keep RLIMIT_AS sane.
        "MALLOC_ARENA_MAX": "2",
    })
    env.setdefault("LANG", "C.UTF-8")
    for key, value in extra.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env


_zygotes: dict[tuple[str, ...], Any] = {}
_zygotes_lock = threading.Lock()
_zygotes_failed: set[tuple[str, ...]] = set()


def warm_start(python: str, env: dict[str, str]) -> Any:
    """This process's zygote for programs run by ``python`` with ``env``
    (:mod:`autograder.sandbox.contained.zygote`), started at the first launch; None where launches
    are exec'd: ``AUTOGRADER_ZYGOTE=0``, or a zygote for that interpreter and start-up
    environment that could not start or died in this process."""
    from autograder.sandbox.contained.zygote import STARTUP_VARIABLES, Zygote, ZygoteGone

    if os.environ.get("AUTOGRADER_ZYGOTE", "1") == "0":
        return None
    key = (python, *(f"{k}={env.get(k)}" for k in STARTUP_VARIABLES))
    with _zygotes_lock:
        if key in _zygotes_failed:
            return None
        zygote = _zygotes.get(key)
        if zygote is None:
            if not _zygotes:
                atexit.register(close_zygotes)
            try:
                zygote = _zygotes[key] = Zygote(python, env, SAFE_CWD)
            except ZygoteGone:
                _zygotes_failed.add(key)
                return None
        if not zygote.fits(env):  # it died: from here on, exec
            _zygotes_failed.add(key)
            return None
        return zygote


def close_zygotes() -> None:
    """End this process's zygotes and wait for them (at exit): the CPU time of the programs
    they forked then counts in this process's children's, as an exec'd program's does, for
    whoever measures a grading's CPU (``grade-batch --jobs auto``, the benchmarks). A later
    launch starts a new one, for a start-up that failed before too."""
    with _zygotes_lock:
        zygotes = list(_zygotes.values())
        _zygotes.clear()
        _zygotes_failed.clear()
    for zygote in zygotes:
        zygote.close()


def zygotes() -> list[Any]:
    """This process's zygotes that started (each a
    :class:`~autograder.sandbox.contained.zygote.Zygote`, alive or not)."""
    with _zygotes_lock:
        return list(_zygotes.values())


def forked_peak_mb() -> float:
    """The largest peak resident size, in MB, of the programs this process's zygotes forked
    and reaped (what ``RUSAGE_CHILDREN`` tells of the programs it exec'd itself)."""
    with _zygotes_lock:
        return max((z.peak_kb for z in _zygotes.values()), default=0) / 1024


# The programs of each student user this process has started and not reaped (by id): a
# user's processes are swept once the last of its programs here is reaped.
_users: dict[int, set[int]] = {}
_users_lock = threading.Lock()
# One lock a user, held while its first program here frees the user and starts, and while
# its last one's sweep runs: a sweep never meets a program of the user that is starting.
_user_locks: dict[int, threading.Lock] = {}


def _user_lock(uid: int | None) -> contextlib.AbstractContextManager[object]:
    if uid is None:
        return contextlib.nullcontext()
    with _users_lock:
        return _user_locks.setdefault(uid, threading.Lock())


def _user_done(process: StudentProcess) -> bool:
    """Forget ``process``; whether no other program of its user is left in this process."""
    with _users_lock:
        mine = _users.get(process.uid, set())  # type: ignore[arg-type]
        mine.discard(id(process))
        return not mine


class LaunchFailed(GraderError):
    """The launcher failed before the student's program ran: our fault, never theirs."""

    def __init__(self, stage: str, error: str) -> None:
        super().__init__(f"the launcher failed at {stage}: {error}")
        self.stage, self.error = stage, error


# Wall seconds the launcher has to contain the program and exec it (mounts, cgroups).
LAUNCH_TIMEOUT = 60.0
# Wall seconds a student's own user has, before its first program here starts, to be rid of
# an earlier program's processes: its sweep waits for them already; this is for one whose
# sweep did not end (the run killed), and a zombie still counts against RLIMIT_NPROC.
USER_FREE_TIMEOUT = 30.0


class BoundedOutput:
    """Collects a stream: keeps the first and last bytes up to a budget, counts the rest."""

    def __init__(self, budget: int) -> None:
        self.budget = budget
        self.head = bytearray()
        self.tail = bytearray()
        self.total = 0
        self._lock = threading.Lock()

    def feed(self, chunk: bytes) -> None:
        with self._lock:
            self.total += len(chunk)
            room = self.budget // 2 - len(self.head)
            if room > 0:
                self.head += chunk[:room]
                chunk = chunk[room:]
            self.tail += chunk
            if len(self.tail) > self.budget // 2:
                del self.tail[: len(self.tail) - self.budget // 2]

    def text(self) -> str:
        with self._lock:
            dropped = self.total - len(self.head) - len(self.tail)
            middle = f"\n[... {dropped} bytes of output dropped ...]\n".encode() if dropped else b""
            return bytes(self.head + middle + self.tail).decode("utf-8", "replace")


def _read_status(fd: int, timeout: float) -> dict[str, str] | None:
    """What the launcher reported on its close-on-exec pipe: None once the program was
    exec'd (end of file, nothing written), else the failed stage and its error."""
    deadline = time.monotonic() + timeout
    data = b""
    while True:
        ready, _w, _x = select.select([fd], [], [], max(0.0, deadline - time.monotonic()))
        if not ready:
            return {"stage": "start", "error": f"no exec within {timeout:.0f} s"}
        chunk = os.read(fd, 65536)
        if not chunk:
            break
        data += chunk
    if not data:
        return None
    try:
        return json.loads(data)
    except ValueError:
        return {"stage": "?", "error": data.decode(errors="replace")}


@dataclasses.dataclass
class StudentProcess:
    """The student's program, started with ``--ros-args`` like ``ros2 run`` would."""

    script: Path
    workdir: Path
    ros_args: list[str]
    env: dict[str, str]
    limits: Limits
    popen: Any = None  # a subprocess.Popen, or a zygote's ForkedProcess
    cgroup: Cgroup | None = None
    output: BoundedOutput | None = None
    uid: int | None = None
    namespaces: bool = True  # with ``uid``: strict isolation's namespaces, or none (user)
    hide: list[Path] = dataclasses.field(default_factory=list)
    workdir_mb: int = 64
    started_at: float = 0.0
    timed_out: bool = False
    # Called as soon as the launcher's process exists, before it is contained: whoever
    # must reap it if the grader dies can know it from the start.
    on_spawn: Callable[[], None] | None = None
    # Held from before the fork until ``on_spawn`` returned: whoever ends the run closes it
    # first, so a program is either recorded before the run reaps, or never started.
    gate: contextlib.AbstractContextManager[object] | None = None
    # Also given every chunk of output as it comes (a hand run streams it to the terminal).
    echo: Callable[[bytes], None] | None = None
    _reader: threading.Thread | None = None
    _watchdog: threading.Timer | None = None

    def start(self) -> None:
        """Start the program (forked from the zygote where there is one, else through the
        launcher); return once it runs, or raise :class:`LaunchFailed` if what contains it
        failed before that."""
        self.workdir.mkdir(parents=True, exist_ok=True)
        (self.workdir / ".ros" / "log").mkdir(parents=True, exist_ok=True)
        self.cgroup = Cgroup(f"run-{os.getpid()}-{uuid.uuid4().hex[:8]}", self.limits)
        spec: dict[str, object] = {"limits": dataclasses.asdict(self.limits),
                                   "cgroups": [str(p) for p in self.cgroup.paths],
                                   "workdir": str(self.workdir)}
        if self.uid is not None:
            spec.update(uid=self.uid, namespaces=self.namespaces,
                        hide=[str(p) for p in self.hide], workdir_mb=self.workdir_mb)
        args = ["--ros-args", *self.ros_args]
        self.output = BoundedOutput(self.limits.output_kb * 1024)
        launcher_env = dict(self.env)
        launcher_env["PYTHONPATH"] = os.pathsep.join(
            p for p in (PACKAGE_PARENT, self.env.get("PYTHONPATH"))
            if p)
        with _user_lock(self.uid):
            if self.uid is not None:
                with _users_lock:
                    first = not _users.get(self.uid)
                    _users.setdefault(self.uid, set()).add(id(self))
                if first and not kill_user(self.uid, USER_FREE_TIMEOUT):
                    _user_done(self)
                    self.cgroup.remove()  # made above, and nothing joined it
                    raise LaunchFailed("user", f"user {self.uid} still has processes of "
                                       "an earlier program that the machine has not reaped")
            with self.gate if self.gate is not None else contextlib.nullcontext():
                started = (self._fork(spec, args, launcher_env)
                           or self._exec(spec, args, launcher_env))
                self.popen, status_read = started
                self.started_at = time.monotonic()
                if self.on_spawn is not None:
                    self.on_spawn()
        self._reader = threading.Thread(target=self._read, daemon=True, name="student-output")
        self._reader.start()
        try:
            failure = _read_status(status_read, LAUNCH_TIMEOUT)
        finally:
            os.close(status_read)
        if failure is not None:
            self.reap()
            raise LaunchFailed(failure.get("stage", "?"), failure.get("error", "?"))
        self._watchdog = threading.Timer(self.limits.wall_seconds, self._out_of_time)
        self._watchdog.daemon = True
        self._watchdog.start()

    def _fork(self, spec: dict[str, object], args: list[str],
              env: dict[str, str]) -> tuple[Any, int] | None:
        """The program forked from this process's zygote, and the read end of its status
        pipe; None where there is no zygote for it (then it is exec'd)."""
        from autograder.sandbox.contained.zygote import ZygoteGone

        zygote = warm_start(student_python(), env)
        if zygote is None:
            return None
        status_read, status_write = os.pipe()
        try:
            return zygote.spawn(spec, str(self.script), args, env, str(self.workdir),
                                status_write), status_read
        except ZygoteGone:
            os.close(status_read)
            return None

    def _exec(self, spec: dict[str, object], args: list[str],
              env: dict[str, str]) -> tuple[Any, int]:
        """The program started through the launcher, which execs it once contained."""
        status_read, status_write = os.pipe()
        spec = {**spec, "status_fd": status_write}
        command = module_command("autograder.sandbox.contained.launcher", [
            json.dumps(spec), "--", *runner.command(student_python(), str(self.script), args)])
        try:
            popen = subprocess.Popen(
                command, cwd=SAFE_CWD, env=env, stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True,
                pass_fds=(status_write,))
        except BaseException:
            os.close(status_read)
            raise
        finally:
            os.close(status_write)
        return popen, status_read

    def _out_of_time(self) -> None:
        if self.running():
            self.timed_out = True
            self.signal(signal.SIGKILL)

    def _read(self) -> None:
        assert self.popen and self.popen.stdout and self.output
        stream = self.popen.stdout
        while chunk := stream.read1(65536):
            self.output.feed(chunk)
            if self.echo is not None:
                self.echo(chunk)

    @property
    def pid(self) -> int:
        assert self.popen
        return self.popen.pid

    @property
    def returncode(self) -> int | None:
        return self.popen.poll() if self.popen else None

    def running(self) -> bool:
        return self.popen is not None and self.popen.poll() is None

    def family(self) -> set[int]:
        """The program's processes now: its cgroup's where it has one; else, where it runs
        as a user of its own (strict isolation, isolation by user), every process of that
        user, daemons that left it included; else (basic isolation) its process and their
        descendants (one that left them, reparented, is not found)."""
        if self.popen is None:
            return set()
        if self.cgroup is not None and self.cgroup.available:
            return self.cgroup.pids()
        if self.uid is not None and is_student_uid(self.uid):
            return set(user_processes(self.uid))
        return {self.pid, *descendants(self.pid)}

    def wait(self, timeout: float) -> int | None:
        """Wait (wall time) for the process to exit; its status, or None if it still runs."""
        assert self.popen
        try:
            return self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def signal(self, sig: int) -> None:
        if self.running():
            try:
                os.killpg(self.pid, sig)
            except ProcessLookupError:
                pass

    def stop(self, grace: float = 3.0) -> int | None:
        """SIGINT (as Ctrl-C would), then SIGKILL; then nothing of it is left running."""
        status = self.returncode
        if status is None:
            self.signal(signal.SIGINT)
            status = self.wait(grace)
        if status is None:
            self.signal(signal.SIGKILL)
            status = self.wait(5.0)
        self.reap()
        return status

    def reap(self) -> None:
        """Kill whatever is left of the submission: its process group and its cgroup."""
        if self._watchdog is not None:
            self._watchdog.cancel()
        if self.popen is not None:
            try:
                os.killpg(self.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            try:
                self.popen.wait(5.0)
            except subprocess.TimeoutExpired:
                pass
        if self.cgroup is not None:
            self.cgroup.kill_all()
            self.cgroup.remove()
        with _user_lock(self.uid):
            if self.uid is not None and _user_done(self):
                sweep_user(self.uid)  # what left the group and the cgroup, or had no cgroup
        if self._reader is not None:
            self._reader.join(2.0)

    def output_text(self) -> str:
        return self.output.text() if self.output else ""

    def output_tail(self, lines: int = 20) -> str:
        return "\n".join(self.output_text().rstrip().splitlines()[-lines:])
