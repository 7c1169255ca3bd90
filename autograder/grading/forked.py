"""Child pytests forked from this process's template (:mod:`autograder.grading.template`):
the grader's side, which starts the template once, asks it for each child, and hears how
each ended (docs/contributors/design.md, "Forked child pytests").

The grader may be multi-threaded (``grade-batch``): it never forks, it asks.  A forked
child's exit status comes on a status pipe of its own, written by the template when it
reaps the child.  A pipe that ends with no status means the template died: the grader
cannot know how the child ended (:attr:`ForkedChild.lost`), and the grading is its own
failure.  Where the template cannot be used (:data:`SWITCH`, a template that could not
start or died, an environment it did not start with), children are exec'd.
"""

from __future__ import annotations

import atexit
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any

from autograder.grading.template import MAX_MESSAGE
from autograder.sandbox.contained.zygote import close_server, start_server
from sim.procstate import process_state

SWITCH = "AUTOGRADER_CHILD_TEMPLATE"  # "0": every child pytest is exec'd
# Read once per forked child: the bytecode cache (bytecode_env in children.py).
_READ_AGAIN = ("PYTHONPYCACHEPREFIX", "PYTHONDONTWRITEBYTECODE")
_AT_START = ("PYTHON", "LC_", "LD_", "MALLOC_", "OPENBLAS_", "OMP_")
START_TIMEOUT = 60.0  # seconds for the template to start, or for a forked child's pid


def read_at_start(name: str) -> bool:
    """Whether the interpreter (or a module the template loaded) reads variable ``name``
    as it starts: only a process started with it behaves as it says."""
    return (name.startswith(_AT_START) or name in ("LANG", "LANGUAGE", "AMENT_PREFIX_PATH")
            ) and name not in _READ_AGAIN


def startup_env(env: Mapping[str, str]) -> dict[str, str]:
    """The part of ``env`` a started process cannot take on afterwards."""
    return {k: v for k, v in env.items() if read_at_start(k)}


class TemplateGone(Exception):
    """The template could not be started, is gone, or did not fork: exec the child."""


class _StatusPipe:
    """The read end of a child's status pipe: one JSON document a line."""

    def __init__(self, fd: int) -> None:
        self.fd: int | None = fd
        self._buffer = b""

    def next(self, timeout: float | None) -> dict[str, Any] | None:
        """The next message, waiting up to ``timeout``; None if none came in that time or
        the pipe ended (then :attr:`fd` is None)."""
        while self.fd is not None and b"\n" not in self._buffer:
            ready, _w, _x = select.select([self.fd], [], [], timeout)
            if not ready:
                return None
            chunk = os.read(self.fd, 4096)
            if not chunk:
                self.close()
                break
            self._buffer += chunk
        if b"\n" not in self._buffer:
            return None
        line, _nl, self._buffer = self._buffer.partition(b"\n")
        return json.loads(line)

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


class ForkedChild:
    """A child pytest the template forked, as much of :class:`subprocess.Popen` as
    :mod:`autograder.grading.children` uses.  Its exit status comes on its status pipe;
    if the pipe ends without one (the template died), the child is waited for by its pid
    until gone, then reads as killed, with :attr:`lost` set: how it ended is unknown."""

    def __init__(self, pid: int, status: _StatusPipe, template: int) -> None:
        self.pid = pid
        self.template = template  # the template's pid: the grading's footprint counts it
        self.returncode: int | None = None
        self.lost = False
        self.cpu_seconds = 0.0  # its CPU time and its waited-for descendants', once ended
        self._status = status

    def poll(self) -> int | None:
        try:
            return self.wait(0.0)
        except subprocess.TimeoutExpired:
            return None

    def wait(self, timeout: float | None = None) -> int:
        end = None if timeout is None else time.monotonic() + timeout
        while self.returncode is None:
            left = None if end is None else max(0.0, end - time.monotonic())
            if self._status.fd is not None:
                message = self._status.next(left)
                if message is not None and "status" in message:
                    self._ended(message)
                if self.returncode is not None or self._status.fd is None:
                    continue  # ended, or the pipe did: then the pid is looked at
            elif _gone(self.pid):
                self.returncode, self.lost = -signal.SIGKILL, True
                continue
            else:
                time.sleep(0.01 if left is None else min(0.01, left))
            if end is not None and time.monotonic() >= end:
                raise subprocess.TimeoutExpired(str(self.pid), timeout or 0.0)
        return self.returncode

    def _ended(self, message: Mapping[str, Any]) -> None:
        self.returncode = os.waitstatus_to_exitcode(int(message["status"]))
        self.cpu_seconds = float(message.get("cpu", 0.0))
        self._status.close()
        _count_cpu(self.cpu_seconds)

    def __del__(self) -> None:
        self._status.close()


def _gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (a zombie nobody reaps has too)."""
    return process_state(pid) in (None, b"Z")


class Template:
    """The grader's end: starts the template with ``env`` and asks it for children."""

    def __init__(self, env: Mapping[str, str]) -> None:
        self.startup = startup_env(env)
        try:
            self.process, ours = start_server(
                [sys.executable, "-m", "autograder.grading.template"], env, "/")
        except OSError as exc:
            raise TemplateGone(str(exc)) from exc
        self.pid = self.process.pid
        self._sock = ours
        self._lock = threading.Lock()
        self._broken = False
        ours.settimeout(START_TIMEOUT)  # a template that takes no request is gone too
        try:
            ready = json.loads(ours.recv(MAX_MESSAGE) or b"{}")
        except (OSError, ValueError):
            ready = {}
        if ready.get("ready") != self.pid:
            self.close()
            raise TemplateGone("the template did not start")

    @property
    def alive(self) -> bool:
        return not self._broken and self.process.poll() is None

    def fits(self, env: Mapping[str, str]) -> bool:
        """Whether a child with ``env`` forked from here starts as an exec'd one would."""
        return self.alive and startup_env(env) == self.startup

    def spawn(self, args: Sequence[str], cwd: str, env: Mapping[str, str], log_fd: int,
              passed: Sequence[int], *, namespaces: bool = False) -> ForkedChild:
        """Fork a child pytest with ``args`` in ``cwd``, output to ``log_fd``, the
        descriptors ``passed`` at the same numbers; :class:`TemplateGone` if none was."""
        read_end, write_end = os.pipe()
        request = {"args": list(args), "cwd": cwd, "env": dict(env),
                   "targets": list(passed), "namespaces": namespaces}
        try:
            with self._lock:
                socket.send_fds(self._sock, [json.dumps(request).encode()],
                                [write_end, log_fd, *passed])
        except OSError as exc:
            os.close(read_end)
            self._broken = True
            raise TemplateGone(str(exc)) from exc
        finally:
            os.close(write_end)
        status = _StatusPipe(read_end)
        first = status.next(START_TIMEOUT)
        if first is None and status.fd is not None:  # no word: the template hangs
            self._broken = True
            self.process.kill()  # a child forked meanwhile still says its pid, or dies
            first = status.next(START_TIMEOUT)
            if first is None and status.fd is not None:
                status.close()
                raise RuntimeError("a child pytest forked from the template never started")
        if first is None or "pid" not in first:
            self._broken = self._broken or first is None  # the pipe ended: the template died
            status.close()
            raise TemplateGone(str((first or {}).get("error", "the template is gone")))
        return ForkedChild(int(first["pid"]), status, self.pid)

    def close(self) -> None:
        """Close the template's socket (it then ends) and wait for it."""
        close_server(self._sock, self.process)


# -- this process's template ---------------------------------------------------------------
_shared: Template | None = None
_shared_failed = False
_shared_lock = threading.Lock()
_reaped_cpu = 0.0


def shared(env: Mapping[str, str]) -> Template | None:
    """This process's template, started at the first call; None where children are
    exec'd: :data:`SWITCH` is "0", the template could not start or died, or a child with
    ``env`` would not start from it as exec'd."""
    global _shared, _shared_failed
    if os.environ.get(SWITCH) == "0":
        return None
    with _shared_lock:
        if _shared_failed:
            return None
        if _shared is None:
            try:
                _shared = Template(env)
            except TemplateGone:
                _shared_failed = True
                return None
            atexit.register(close_shared)
        if not _shared.alive:
            _shared_failed = True
            return None
        return _shared if _shared.fits(env) else None


def close_shared() -> None:
    """End this process's template and wait for it (at exit)."""
    global _shared
    with _shared_lock:
        template, _shared = _shared, None
    if template is not None:
        template.close()


def _count_cpu(seconds: float) -> None:
    global _reaped_cpu
    with _shared_lock:
        _reaped_cpu += seconds


def forked_cpu_seconds() -> float:
    """The CPU time of this process's template so far and of every child it forked that
    has ended, with their waited-for descendants: what ``RUSAGE_CHILDREN`` would count of
    them had this process exec'd them (the template is waited for only at exit)."""
    with _shared_lock:
        running = _shared.pid if _shared is not None else None
        reaped = _reaped_cpu
    return reaped + (process_cpu_seconds(running) if running is not None else 0.0)


def process_cpu_seconds(pid: int) -> float:
    """Process ``pid``'s own CPU time so far (its ``/proc`` stat), 0 if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            fields = fh.read().rpartition(b")")[2].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return 0.0
