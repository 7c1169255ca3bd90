"""Run a student's program as its own process, contained and bounded.

Each program runs through :mod:`autograder.sandbox_exec` in its own session and process
group, in a throwaway working directory, with a minimal environment and resource limits.
Where the machine lets us create cgroups (v1 ``pids`` and ``memory``), the program also
runs in a cgroup of its own: that bounds processes even for root and lets :meth:`stop`
find and kill everything it started, daemons that left the session included.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

from autograder.cgroups import Cgroup
from autograder.exercise import Limits

_PASS_THROUGH = (
    "PATH", "LD_LIBRARY_PATH", "PYTHONPATH", "AMENT_PREFIX_PATH", "ROS_DISTRO", "ROS_VERSION",
    "ROS_PYTHON_VERSION", "RMW_IMPLEMENTATION", "LANG", "LC_ALL", "TZ",
)


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


class _Output:
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


@dataclasses.dataclass
class StudentProcess:
    """The student's program, started with ``--ros-args`` like ``ros2 run`` would."""

    script: Path
    workdir: Path
    ros_args: list[str]
    env: dict[str, str]
    limits: Limits
    popen: subprocess.Popen[bytes] | None = None
    cgroup: Cgroup | None = None
    output: _Output | None = None
    uid: int | None = None
    hide: list[Path] = dataclasses.field(default_factory=list)
    workdir_mb: int = 64
    started_at: float = 0.0
    timed_out: bool = False
    _reader: threading.Thread | None = None
    _watchdog: threading.Timer | None = None

    def start(self) -> None:
        self.workdir.mkdir(parents=True, exist_ok=True)
        (self.workdir / ".ros" / "log").mkdir(parents=True, exist_ok=True)
        self.cgroup = Cgroup(f"run-{os.getpid()}-{uuid.uuid4().hex[:8]}", self.limits)
        spec: dict[str, object] = {"limits": dataclasses.asdict(self.limits),
                                   "cgroups": [str(p) for p in self.cgroup.paths]}
        if self.uid is not None:
            spec.update(uid=self.uid, hide=[str(p) for p in self.hide],
                        workdir=str(self.workdir), workdir_mb=self.workdir_mb)
        command = [sys.executable, "-m", "autograder.sandbox_exec", json.dumps(spec), "--",
                   sys.executable, str(self.script), "--ros-args", *self.ros_args]
        self.output = _Output(self.limits.output_kb * 1024)
        launcher_env = dict(self.env)
        launcher_env["PYTHONPATH"] = os.pathsep.join(
            p for p in (str(Path(__file__).resolve().parent.parent), self.env.get("PYTHONPATH"))
            if p)
        self.popen = subprocess.Popen(
            command, cwd=self.workdir, env=launcher_env, stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
        self.started_at = time.monotonic()
        self._reader = threading.Thread(target=self._read, daemon=True, name="student-output")
        self._reader.start()
        self._watchdog = threading.Timer(self.limits.wall_seconds, self._out_of_time)
        self._watchdog.daemon = True
        self._watchdog.start()

    def _out_of_time(self) -> None:
        if self.running():
            self.timed_out = True
            self.signal(signal.SIGKILL)

    def _read(self) -> None:
        assert self.popen and self.popen.stdout and self.output
        stream = self.popen.stdout
        while chunk := stream.read1(65536):
            self.output.feed(chunk)

    @property
    def pid(self) -> int:
        assert self.popen
        return self.popen.pid

    @property
    def returncode(self) -> int | None:
        return self.popen.poll() if self.popen else None

    def running(self) -> bool:
        return self.popen is not None and self.popen.poll() is None

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
        if self._reader is not None:
            self._reader.join(2.0)

    def output_text(self) -> str:
        return self.output.text() if self.output else ""

    def output_tail(self, lines: int = 20) -> str:
        return "\n".join(self.output_text().rstrip().splitlines()[-lines:])
