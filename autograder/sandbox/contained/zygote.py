"""A warm start for students' programs: a process that has imported rclpy once and forks
each program from there, so a launch skips Python's start and the imports, most of what an
rclpy program spends before its node exists (docs/contributors/design.md, "Warm starts").

    python -s -m autograder.sandbox.contained.zygote FD

FD is one end of a ``SOCK_SEQPACKET`` socket pair; the grader (:class:`Zygote`) holds the
other.  The zygote imports what students' nodes import, says ``ready``, and then for each
request forks a child that does what :mod:`.launcher` does before its
``exec`` (its own session, the environment and working folder asked for, output on the
pipe handed over, then :func:`~.launcher.contain`: cgroups, limits, and in
strict isolation the mount namespace and the student's user) and then runs the program as
``python SCRIPT ARGS...`` would, as the interpreter's main program.  The zygote tells the
grader each child's pid, and its wait status and peak resident size once it has exited.
It is its programs' subreaper: what they leave when they end (a fork bomb's children) is
the zygote's to reap, and is reported the same way.

The zygote holds nothing of the grader's: it is started from a clean environment, never
sees the course's tests, the report's key or the grader's files, and is single-threaded
but for LTTng's listener threads (OpenBLAS is held to one thread, so numpy starts none),
whose library is told of each fork as it asks (:func:`fork_with_hooks`).  It
ends when the grader's end of the socket closes, and with the grader's process
(its socket's end closes however the grader ends).
"""

from __future__ import annotations

import array
import contextlib
import ctypes
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

from autograder.sandbox.contained.launcher import LAUNCH_FAILED, contain
from autograder.sandbox.contained.runner import run_program
from sim.procstate import process_state

# What students' nodes import (the chapter's exercises and the book's code): imported once
# here instead of in every program.  A missing one is skipped.
WARM_MODULES = (
    "numpy", "rclpy", "rclpy.node", "rclpy.executors", "rclpy.callback_groups", "rclpy.qos",
    "rclpy.parameter", "rclpy.duration", "rclpy.time", "rclpy.action",
    "rcl_interfaces.msg", "std_msgs.msg", "std_srvs.srv", "geometry_msgs.msg",
    "sensor_msgs.msg", "nav_msgs.msg", "rosgraph_msgs.msg",
)
# Variables Python reads when it starts, not afterwards: a launch whose environment differs
# from the zygote's in one of them is started the ordinary way (see :meth:`Zygote.fits`).
STARTUP_VARIABLES = (
    "PYTHONPATH", "PYTHONUNBUFFERED", "PYTHONDONTWRITEBYTECODE", "PYTHONHASHSEED",
    "PYTHONIOENCODING", "LANG", "LC_ALL", "LC_CTYPE", "MALLOC_ARENA_MAX", "LD_LIBRARY_PATH",
)
MAX_MESSAGE = 1 << 20
PR_SET_CHILD_SUBREAPER = 36
# Wall seconds between two looks at the zygote while the grader waits for it: one stopped
# (SIGSTOP, or left stopped by a tracer that has gone) is woken, one held by a tracer is
# given up (see :meth:`Zygote._tend`).
LOOK_EVERY = 0.05
# Wall seconds a closed server (the zygote, the template) has to end before it is killed.
CLOSE_WITHIN = 5.0


# -- the zygote ----------------------------------------------------------------------
def _send(sock: socket.socket, message: Mapping[str, object]) -> None:
    sock.send(json.dumps(message).encode())


def _warm() -> None:
    for name in WARM_MODULES:
        with contextlib.suppress(Exception):
            __import__(name)


def serve(fd: int) -> tuple[str, list[str]]:
    """Serve the grader until its socket closes (then exit); return only in a forked child,
    contained, with the script to run and its arguments."""
    sock = socket.socket(fileno=fd)
    # The orphans of the programs forked here (a fork bomb's children, once it is killed)
    # become ours, reaped at once below, instead of waiting for the machine's init: each
    # counts against its user's RLIMIT_NPROC until reaped (see autograder.sandbox.sweep).
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    _warm()
    fork = fork_with_hooks()
    wake_read, wake_write = os.pipe()
    os.set_blocking(wake_write, False)
    signal.set_wakeup_fd(wake_write)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    _send(sock, {"ready": os.getpid()})
    while True:
        ready, _w, _x = select.select([sock, wake_read], [], [])
        if wake_read in ready:
            os.read(wake_read, 4096)
            _reap(sock)
        if sock in ready:
            data, fds = _receive(sock)
            if not data:  # the grader is done or gone: account for what has ended, and go
                _reap(sock)
                os._exit(0)
            request = json.loads(data)

            def in_child(keep: Sequence[int] = fds) -> None:
                signal.set_wakeup_fd(-1)
                signal.signal(signal.SIGCHLD, signal.SIG_DFL)
                sock.detach()  # its descriptor is closed below, with the wake pipe's
                close_all_but(keep)

            try:
                pid = fork(in_child)
            except OSError as exc:  # no process to be had: the grader execs this one
                for passed in fds:
                    os.close(passed)
                _send(sock, {"error": f"fork: {exc}"})
                continue
            if pid == 0:
                return _become_program(request, fds)
            for passed in fds:
                os.close(passed)
            _send(sock, {"pid": pid})


ForkHook = tuple[Callable[[Any], Any], Callable[[Any], Any], Callable[[Any], Any], Any]


def _lttng_hooks() -> list[ForkHook]:
    """The fork hooks (before, after in the parent, after in the child, their saved
    state) of every LTTng-UST copy loaded: rclpy's wheels bundle it for ROS 2 tracing."""
    import ctypes

    with open("/proc/self/maps") as maps:
        paths = sorted({line.split()[-1] for line in maps
                        if "/liblttng-ust-" in line and "tracepoint" not in line})
    hooks: list[ForkHook] = []
    for path in paths:
        with contextlib.suppress(OSError, AttributeError):
            lib = ctypes.CDLL(path)
            hooks.append((lib.ust_before_fork, lib.ust_after_fork_parent,
                          lib.ust_after_fork_child, ctypes.create_string_buffer(1024)))
    return hooks


def fork_with_hooks(hooks: Sequence[ForkHook] | None = None,
                     ) -> Callable[[Callable[[], None]], int]:
    """``os.fork`` wrapped in LTTng's fork hooks, the protocol of LTTng's own
    ``liblttng-ust-fork``: without them a forked child dies of SIGSEGV at exit, when LTTng
    cancels threads that only its parent has.

    ``fork(in_child)`` runs ``in_child`` in the child before the child's hook, which
    starts LTTng's listener threads again; those open and close sockets and shared-memory
    files at once, so descriptors must be closed before they exist.  Closed afterwards, a
    listener's descriptor number went to the student's cgroup file and the listener's own
    close took it away ("the launcher failed at cgroup: Bad file descriptor", seen in CI)."""
    hooks = _lttng_hooks() if hooks is None else list(hooks)

    def fork(in_child: Callable[[], None]) -> int:
        for before, _parent, _child, saved in hooks:
            before(saved)  # takes LTTng's locks and blocks signals until the after hook
        pid = -1
        try:
            pid = os.fork()
            if pid == 0:
                in_child()
        finally:
            for _before, parent, child, saved in reversed(hooks):
                (child if pid == 0 else parent)(saved)
        return pid

    return fork


def close_all_but(keep: Sequence[int]) -> None:
    """Close every descriptor above stderr but those in ``keep``."""
    low = 3
    for fd in sorted(set(keep)):
        if fd >= low:
            os.closerange(low, fd)
            low = fd + 1
    os.closerange(low, os.sysconf("SC_OPEN_MAX"))


def ended_children() -> Iterator[tuple[int, int, Any]]:
    """The children of this process that have ended, waited for (pid, wait status,
    resource usage), without blocking: a forking server's reaping (the zygote's, the
    grader's template's)."""
    while True:
        try:
            pid, status, usage = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        yield pid, status, usage


def start_server(command: Sequence[str], env: Mapping[str, str],
                 cwd: str) -> tuple[subprocess.Popen[bytes], socket.socket]:
    """Start a forking server (the zygote, the grader's template) as ``command`` + the
    number of its end of a socket pair, in a session of its own; it and our end. OSError:
    it could not be started."""
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    try:
        process = subprocess.Popen(
            [*command, str(theirs.fileno())], env={**env, "OPENBLAS_NUM_THREADS": "1"},
            cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True, pass_fds=(theirs.fileno(),))
    except OSError:
        ours.close()
        raise
    finally:
        theirs.close()
    return process, ours


def close_server(sock: socket.socket, process: subprocess.Popen[Any]) -> None:
    """Close a forking server's socket (it then ends) and wait for it, killed if it has
    not ended within :data:`CLOSE_WITHIN` seconds, and then waited for as long again at
    most: a process a tracer holds (a program of the grader's user may trace the zygote in
    basic isolation) stays a zombie until the tracer lets it go, and the grader does not
    wait for the student's program."""
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_RDWR)
    sock.close()
    try:
        process.wait(CLOSE_WITHIN)
    except subprocess.TimeoutExpired:
        process.kill()
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(CLOSE_WITHIN)


def _reap(sock: socket.socket) -> None:
    """Wait for the programs that have ended (so their CPU time counts in the zygote's
    children's, and through it in the grader's) and tell the grader how each ended."""
    for pid, status, usage in ended_children():
        with contextlib.suppress(OSError):
            _send(sock, {"exited": pid, "status": status, "maxrss_kb": usage.ru_maxrss})


def _receive(sock: socket.socket) -> tuple[bytes, list[int]]:
    fds = array.array("i")
    data, ancillary, _flags, _addr = sock.recvmsg(MAX_MESSAGE, socket.CMSG_SPACE(
        8 * fds.itemsize))
    for level, kind, payload in ancillary:
        if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
            fds.frombytes(payload[:len(payload) - len(payload) % fds.itemsize])
    return data, list(fds)


def _become_program(request: dict, fds: list[int]) -> tuple[str, list[str]]:
    """In the forked child, whose other descriptors are closed: what the launcher does up
    to its exec, reporting a failure on the status pipe as it does; then the pipe is
    closed, as an exec would close it.  Only descriptors opened here are closed here:
    LTTng's threads run again and own the others."""
    output, status = fds
    os.setsid()
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    if null != 0:
        os.close(null)
    for target in (1, 2):
        os.dup2(output, target)
    if output not in (0, 1, 2):
        os.close(output)
    stage = ["environment"]
    try:
        os.environ.clear()
        os.environ.update(request["env"])
        os.chdir(request["cwd"])
        contain(request["spec"], stage)
    except BaseException as exc:  # every failure before the program is ours
        os.write(status, json.dumps({"stage": stage[0],
                                     "error": f"{type(exc).__name__}: {exc}"}).encode())
        os._exit(LAUNCH_FAILED)
    os.close(status)
    return request["script"], list(request["args"])


# -- the grader's side -----------------------------------------------------------------
class ForkedProcess:
    """A program the zygote forked, as much of :class:`subprocess.Popen` as
    :class:`~autograder.sandbox.process.StudentProcess` uses."""

    def __init__(self, zygote: Zygote, pid: int, stdout: int) -> None:
        self._zygote = zygote
        self.pid = pid
        self.stdout = os.fdopen(stdout, "rb")
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            status = self._zygote.status(self.pid, 0.0)
            if status is not None:
                self.returncode = status
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        if self.returncode is None:
            status = self._zygote.status(self.pid, timeout)
            if status is None:
                raise subprocess.TimeoutExpired(str(self.pid), timeout or 0.0)
            self.returncode = status
        return self.returncode


class ZygoteGone(Exception):
    """The zygote could not be started, or is gone: launch the ordinary way."""


class Zygote:
    """The grader's end: starts the zygote, asks it for programs, hears how they ended.

    One thread reads the zygote's messages; a program's exit status is known once the
    zygote has reaped it.  If the zygote dies, programs it forked and not yet reported are
    waited for by their pid until gone (their status is then unknown, read as killed)."""

    def __init__(self, python: str, env: Mapping[str, str], cwd: str) -> None:
        self.env = dict(env)
        try:
            self.process, ours = start_server(
                [python, "-s", "-m", "autograder.sandbox.contained.zygote"], env, cwd)
        except OSError as exc:
            raise ZygoteGone(str(exc)) from exc
        self._sock = ours
        self._lock = threading.Condition()
        self._replies: list[dict] = []
        self._statuses: dict[int, int] = {}
        self._alive = True
        self.peak_kb = 0  # the largest peak resident size of a program it reaped
        self._send_lock = threading.Lock()
        self._reader = threading.Thread(target=self._read, daemon=True, name="zygote")
        self._reader.start()
        if self._reply(60.0).get("ready") is None:
            self.close()
            raise ZygoteGone("the zygote did not start")

    def fits(self, env: Mapping[str, str]) -> bool:
        """True if a program with ``env`` would start the same from here as by an exec."""
        return self._alive and all(env.get(k) == self.env.get(k) for k in STARTUP_VARIABLES)

    def spawn(self, spec: Mapping[str, object], script: str, args: Sequence[str],
              env: Mapping[str, str], cwd: str, status_fd: int) -> ForkedProcess:
        """Fork a program; its output goes to a new pipe (the returned process's stdout),
        and the launcher's status report to ``status_fd`` (closed here)."""
        read_end, write_end = os.pipe()
        request = {"spec": dict(spec), "script": script, "args": list(args), "env": dict(env),
                   "cwd": cwd}
        try:
            with self._send_lock:
                try:
                    self._sock.sendmsg([json.dumps(request).encode()], [(
                        socket.SOL_SOCKET, socket.SCM_RIGHTS,
                        array.array("i", [write_end, status_fd]))])
                except OSError as exc:
                    raise ZygoteGone(str(exc)) from exc
                reply = self._reply(30.0)
        except BaseException:
            os.close(read_end)
            raise
        finally:
            os.close(write_end)
            os.close(status_fd)
        if "pid" not in reply:
            os.close(read_end)
            raise ZygoteGone(str(reply.get("error", "no answer from the zygote")))
        return ForkedProcess(self, int(reply["pid"]), read_end)

    def status(self, pid: int, timeout: float | None) -> int | None:
        """The exit status (as ``Popen.returncode``) of ``pid``, waiting up to ``timeout``."""
        with self._lock:
            self._wait(lambda: pid in self._statuses or not self._alive, timeout)
            if pid in self._statuses:
                return self._statuses[pid]
            if self._alive:
                return None
        return _orphan_status(pid, timeout)

    def _reply(self, timeout: float) -> dict:
        with self._lock:
            if not self._wait(lambda: bool(self._replies) or not self._alive, timeout):
                # No answer in time: it is not asked again, so that a late answer cannot be
                # taken for the next request's.
                self._give_up()
                return {}
            return self._replies.pop(0) if self._replies else {}

    def _wait(self, done: Callable[[], bool], timeout: float | None) -> bool:
        """Wait, with ``_lock`` held, until ``done()`` or ``timeout``, looking after the
        zygote every :data:`LOOK_EVERY` seconds meanwhile; whether it is done."""
        end = None if timeout is None else time.monotonic() + timeout
        while not done():
            left = None if end is None else end - time.monotonic()
            if left is not None and left <= 0:
                return False
            if self._lock.wait_for(done, LOOK_EVERY if left is None else min(LOOK_EVERY, left)):
                return True
            self._tend()
        return True

    def _tend(self) -> None:
        """A program of the student's user can stop or trace the zygote where that user is
        the grader's (basic isolation): it then answers nothing, and every launch would wait
        for its timeout.  Stopped (``T``: by SIGSTOP, or left so by a tracer that has gone),
        it is woken; held by a tracer that is still there (``t``), it is killed, so that its
        programs and the next launches go on without it (as when it dies)."""
        state = process_state(self.process.pid)
        if state == b"T":
            with contextlib.suppress(OSError):
                os.kill(self.process.pid, signal.SIGCONT)
        elif state == b"t":
            self._give_up()

    def _give_up(self) -> None:
        """With ``_lock`` held: kill the zygote and go on as if it had died (its programs
        are waited for by their pids, later launches are exec'd)."""
        with contextlib.suppress(OSError):
            self.process.kill()
        self._alive = False
        self._lock.notify_all()

    def _read(self) -> None:
        try:
            while data := self._sock.recv(MAX_MESSAGE):
                message = json.loads(data)
                with self._lock:
                    if "exited" in message:
                        self._statuses[int(message["exited"])] = os.waitstatus_to_exitcode(
                            int(message["status"]))
                        self.peak_kb = max(self.peak_kb, int(message.get("maxrss_kb", 0)))
                    else:
                        # A pid the zygote forks again (after an orphan's of that pid was
                        # reported, or an earlier program's) starts with no status.
                        self._statuses.pop(int(message.get("pid", -1)), None)
                        self._replies.append(message)
                    self._lock.notify_all()
        except (OSError, ValueError):
            pass
        with self._lock:
            self._alive = False
            self._lock.notify_all()

    def close(self) -> None:
        close_server(self._sock, self.process)


def _orphan_status(pid: int, timeout: float | None) -> int | None:
    """A program whose zygote died: -SIGKILL once it is gone, None while it runs."""
    end = None if timeout is None else time.monotonic() + timeout
    while True:
        if process_state(pid) in (None, b"Z"):  # a zombie nobody reaps is gone too
            return -signal.SIGKILL
        if end is not None and time.monotonic() >= end:
            return None
        time.sleep(0.01)


if __name__ == "__main__":
    run_program(*serve(int(sys.argv[1])))
