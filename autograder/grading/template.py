"""A warm start for the grading's child pytests: a process that has imported pytest,
rclpy, numpy, pymunk and the grading plugin once, and forks each child pytest from there
(docs/contributors/design.md, "Forked child pytests").

    python -m autograder.grading.template FD

FD is one end of a ``SOCK_SEQPACKET`` socket pair; the grader (:class:`Template`) holds
the other, and the template ends when that end closes, however the grader ends.  A
request is one message: pytest's arguments, the working folder and environment, whether
to make namespaces of its own (strict isolation), and the numbers its descriptors must
have; with it, by ``SCM_RIGHTS``, a status pipe's write end, the log and the descriptors
to pass.  The forked child makes itself what an exec'd ``python -m pytest`` child is (its
own session, its descriptors where asked and no other, the environment, folder and
arguments), writes its pid on the status pipe and runs pytest; the template reaps it and
writes its wait status there.  A status pipe that closes with no status means the
template died: the grader cannot know how the child ended (:attr:`ForkedChild.lost`).

The grader may be multi-threaded (``grade-batch``): it never forks, it asks.  The template
is single-threaded but for LTTng's listener threads (rclpy's wheels bundle LTTng-UST),
whose library is told of each fork as it asks; OpenBLAS is held to one thread.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import fcntl
import functools
import gc
import importlib
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time
import traceback
from collections.abc import Mapping, Sequence
from typing import Any

from autograder.sandbox.contained.zygote import close_all_but, fork_with_hooks

# What a child pytest imports: imported once here instead of in every child; a missing
# one is skipped.  The plugin's package module is then forgotten, so that pytest imports
# it again for ``-p`` (rewriting its asserts, as it would); what it imported stays.
WARM_MODULES = (
    "pytest", "_pytest.junitxml", "_pytest.pastebin", "_pytest.unittest", "_pytest.skipping",
    "_pytest.helpconfig", "_pytest.faulthandler", "_pytest.warnings",
    "_pytest.threadexception", "_pytest.unraisableexception", "_pytest.setuponly",
    "_pytest.setupplan", "numpy", "numpy.random", "pymunk", "rclpy", "rclpy.executors",
    "std_msgs.msg", "geometry_msgs.msg", "sensor_msgs.msg", "nav_msgs.msg",
    "rosgraph_msgs.msg", "rcl_interfaces.srv", "rosidl_parser.parser",
    "xml.etree.ElementTree", "autograder.plugin", "autograder.core.exercise",
    "autograder.core.submission", "autograder.sandbox.process", "sim.bridge",
)
FORGOTTEN = "autograder.plugin"
SWITCH = "AUTOGRADER_CHILD_TEMPLATE"  # "0": every child pytest is exec'd
# Read once per forked child: the bytecode cache (bytecode_env in children.py).
_READ_AGAIN = ("PYTHONPYCACHEPREFIX", "PYTHONDONTWRITEBYTECODE")
_AT_START = ("PYTHON", "LC_", "LD_", "MALLOC_", "OPENBLAS_", "OMP_")
SETUP_FAILED = 121  # a forked child's exit status when it could not become the child
CLONE_NEWNS, CLONE_NEWNET = 0x00020000, 0x40000000
MS_REC, MS_PRIVATE = 0x4000, 1 << 18
MAX_MESSAGE = 1 << 20
MAX_FDS = 16  # descriptors one request may carry
START_TIMEOUT = 60.0  # seconds for the template to start, or for a forked child's pid


def read_at_start(name: str) -> bool:
    """Whether the interpreter (or a module the template loaded) reads variable ``name``
    as it starts: only a process started with it behaves as it says."""
    return (name.startswith(_AT_START) or name in ("LANG", "LANGUAGE", "AMENT_PREFIX_PATH")
            ) and name not in _READ_AGAIN


def startup_env(env: Mapping[str, str]) -> dict[str, str]:
    """The part of ``env`` a started process cannot take on afterwards."""
    return {k: v for k, v in env.items() if read_at_start(k)}


# -- the template process ----------------------------------------------------------------
def _warm() -> None:
    for name in WARM_MODULES:
        with contextlib.suppress(Exception):
            importlib.import_module(name)
    sys.modules.pop(FORGOTTEN, None)
    parent, _dot, child = FORGOTTEN.rpartition(".")
    with contextlib.suppress(KeyError, AttributeError):
        delattr(sys.modules[parent], child)


def _write(fd: int, message: Mapping[str, object]) -> None:
    with contextlib.suppress(OSError):  # the grader stopped listening: nothing to tell
        os.write(fd, json.dumps(message).encode() + b"\n")


def serve(fd: int) -> list[str]:
    """Serve the grader until its socket closes (then exit); return only in a forked
    child, made the child pytest: with pytest's arguments."""
    sock = socket.socket(fileno=fd)
    _warm()
    libc = ctypes.CDLL(None, use_errno=True)  # loaded before any fork: no dlopen after one
    gc.freeze()  # what the imports made is never scanned again, so its pages stay shared
    fork = fork_with_hooks()
    wake_read, wake_write = os.pipe()
    os.set_blocking(wake_write, False)
    signal.set_wakeup_fd(wake_write)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    statuses: dict[int, int] = {}  # a running child's pid -> its status pipe
    sock.send(json.dumps({"ready": os.getpid()}).encode())
    while True:
        ready, _w, _x = select.select([sock, wake_read], [], [])
        if wake_read in ready:
            os.read(wake_read, 4096)
            _reap(statuses)
        if sock not in ready:
            continue
        try:
            data, fds, _flags, _addr = socket.recv_fds(sock, MAX_MESSAGE, MAX_FDS)
        except OSError:
            data, fds = b"", []
        if not data:  # the grader is done or gone
            _reap(statuses)
            os._exit(0)
        request = json.loads(data)
        try:
            pid = fork(functools.partial(_in_child, sock, request, fds, libc))
        except OSError as exc:  # no process to be had: the grader execs this child
            _write(fds[0], {"error": f"fork: {exc}"})
            pid = -1
        if pid == 0:
            return _become_pytest(request)
        if pid > 0:
            statuses[pid] = os.dup(fds[0])
        for passed in fds:
            os.close(passed)


def _reap(statuses: dict[int, int]) -> None:
    """Wait for the children that have ended and tell the grader how each ended, with the
    CPU time it and what it waited for used (a batch counts its CPU with it)."""
    while True:
        try:
            pid, status, usage = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        fd = statuses.pop(pid, None)
        if fd is not None:
            _write(fd, {"status": status, "cpu": usage.ru_utime + usage.ru_stime})
            os.close(fd)


# The status pipe in the forked child, where _in_child left it.
_status_fd = -1


def _in_child(sock: socket.socket, request: Mapping[str, Any], fds: Sequence[int],
              libc: ctypes.CDLL) -> None:
    """In the forked child, before LTTng's threads start again (they open descriptors at
    once): a session, every descriptor but the passed ones closed and those put where
    asked, in strict isolation namespaces of its own.  A failure is told on the status
    pipe, and the child ends."""
    global _status_fd
    status = fds[0]
    try:
        signal.set_wakeup_fd(-1)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        sock.detach()  # closed by number, next
        close_all_but(fds)
        os.setsid()
        if request["namespaces"]:
            _own_namespaces(libc)
        status = place(fds, request["targets"])
    except BaseException as exc:  # every failure here is the template's, told
        _write(status, {"error": f"{type(exc).__name__}: {exc}"})
        os._exit(SETUP_FAILED)
    _status_fd = status


def _own_namespaces(libc: ctypes.CDLL) -> None:
    """What ``unshare --net --mount --propagation private`` does before its exec: a
    network namespace (only a loopback) and a mount namespace, its mounts its own."""
    if libc.unshare(CLONE_NEWNET | CLONE_NEWNS) != 0:
        raise OSError(ctypes.get_errno(), "unshare: " + os.strerror(ctypes.get_errno()))
    if libc.mount(b"none", b"/", None, ctypes.c_ulong(MS_REC | MS_PRIVATE), None) != 0:
        raise OSError(ctypes.get_errno(), "mount /: " + os.strerror(ctypes.get_errno()))


def place(fds: Sequence[int], targets: Sequence[int]) -> int:
    """Put the passed descriptors (those after the status pipe and the log) at
    ``targets``, the log at stdout and stderr, /dev/null at stdin; return where the status
    pipe went.  Each is first copied above every number involved, so that no ``dup2``
    lands on one not yet placed."""
    top = max([2, *fds, *targets]) + 1
    status, log, *passed = (fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, top) for fd in fds)
    for fd in set(fds):
        os.close(fd)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    if null != 0:
        os.close(null)
    os.dup2(log, 1)
    os.dup2(log, 2)
    for source, target in zip(passed, targets, strict=True):
        os.dup2(source, target)  # inheritable, as pass_fds leaves them
    for fd in (log, *passed):
        os.close(fd)
    return status


def _become_pytest(request: Mapping[str, Any]) -> list[str]:
    """The rest of the child's making: the environment, folder, bytecode cache, module
    path and ``sys.argv`` that ``python -m pytest`` would have; its pid on the status
    pipe, or why not."""
    try:
        env = request["env"]
        os.environ.clear()
        os.environ.update(env)
        os.chdir(request["cwd"])
        sys.pycache_prefix = env.get("PYTHONPYCACHEPREFIX") or None
        sys.dont_write_bytecode = bool(env.get("PYTHONDONTWRITEBYTECODE"))
        import pytest

        sys.argv = [os.path.join(os.path.dirname(pytest.__file__), "__main__.py"),
                    *request["args"]]
        sys.path[0] = os.getcwd()  # python -m puts its working folder first
    except BaseException as exc:
        _write(_status_fd, {"error": f"{type(exc).__name__}: {exc}"})
        os._exit(SETUP_FAILED)
    _write(_status_fd, {"pid": os.getpid()})
    os.close(_status_fd)
    return list(request["args"])


def run_pytest(args: list[str]) -> None:
    """Run pytest as ``python -m pytest`` does and exit with its status, skipping the
    interpreter's finalization: the ``atexit`` handlers run, the streams are flushed."""
    import pytest

    try:
        code = int(pytest.main(args))
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
    except BaseException:  # as the interpreter would end: a traceback, status 1
        traceback.print_exc()
        code = 1
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code & 0xFF)


# -- the grader's side -----------------------------------------------------------------
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
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rpartition(b")")[2].split()[0] == b"Z"
    except (OSError, IndexError):
        return True


class Template:
    """The grader's end: starts the template with ``env`` and asks it for children."""

    def __init__(self, env: Mapping[str, str]) -> None:
        self.startup = startup_env(env)
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "autograder.grading.template", str(theirs.fileno())],
                env={**env, "OPENBLAS_NUM_THREADS": "1"}, cwd="/", stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                pass_fds=(theirs.fileno(),))
        except OSError as exc:
            ours.close()
            raise TemplateGone(str(exc)) from exc
        finally:
            theirs.close()
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
        with contextlib.suppress(OSError):
            self._sock.shutdown(socket.SHUT_RDWR)
        self._sock.close()
        try:
            self.process.wait(5.0)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


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


def reaped_cpu_seconds() -> float:
    """The CPU time of every forked child that has ended, with its waited-for descendants:
    what ``RUSAGE_CHILDREN`` would count of them had this process exec'd them."""
    with _shared_lock:
        return _reaped_cpu


if __name__ == "__main__":
    run_pytest(serve(int(sys.argv[1])))
