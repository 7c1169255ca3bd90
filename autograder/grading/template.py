"""A warm start for the grading's child pytests: a process that has imported pytest,
rclpy, numpy, pymunk and the grading plugin once, and forks each child pytest from there
(docs/contributors/design.md, "Forked child pytests"; the grader's side is
:mod:`autograder.grading.forked`).

    python -m autograder.grading.template FD

FD is one end of a ``SOCK_SEQPACKET`` socket pair; the grader holds the other, and the
template ends when that end closes, however the grader ends.  A request is one message:
pytest's arguments, the working folder and environment, whether to make namespaces of its
own (strict isolation), and the numbers its descriptors must have; with it, by
``SCM_RIGHTS``, a status pipe's write end, the log and the descriptors to pass.  The
forked child makes itself what an exec'd ``python -m pytest`` child is (its own session,
its descriptors where asked and no other, the environment, folder and arguments), writes
its pid on the status pipe and runs pytest; the template reaps it and writes its wait
status there.

The template is single-threaded but for LTTng's listener threads (rclpy's wheels bundle
LTTng-UST), whose library is told of each fork as it asks; OpenBLAS is held to one thread.
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
import sys
import traceback
from collections.abc import Mapping, Sequence
from typing import Any

from autograder.sandbox.contained.zygote import (
    close_all_but,
    ended_children,
    fork_with_hooks,
)

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
# Each signal as this interpreter started with it, before any handler of ours: what a
# fresh interpreter the grader starts has, a signal the grader ignores included (SIGINT,
# when a script started it in the background), since an exec keeps ignored signals.
AT_START = {signum: signal.getsignal(signum) for signum in signal.valid_signals()}
SETUP_FAILED = 121  # a forked child's exit status when it could not become the child
CLONE_NEWNS, CLONE_NEWNET = 0x00020000, 0x40000000
MS_REC, MS_PRIVATE = 0x4000, 1 << 18
MAX_MESSAGE = 1 << 20
MAX_FDS = 16  # descriptors one request may carry


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
    for pid, status, usage in ended_children():
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
        _default_signals()
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


def _default_signals() -> None:
    """Every signal as a fresh interpreter started by the grader has it, whatever the
    template set since (``AT_START``): SIGINT raises KeyboardInterrupt, SIGPIPE and SIGXFSZ
    are ignored, the rest default, and one the grader ignores stays ignored."""
    for signum in signal.valid_signals() - {signal.SIGKILL, signal.SIGSTOP}:
        handler = AT_START.get(signum)
        if handler is None:  # set outside Python: as a fresh interpreter, the default
            handler = signal.SIG_DFL
        with contextlib.suppress(OSError, ValueError):  # those the C library keeps
            signal.signal(signum, handler)


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
    path and ``sys.argv`` that ``python -m pytest`` would have, numpy's global random
    state seeded anew (``random`` reseeds itself at a fork); its pid on the status pipe,
    or why not."""
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
        if "numpy.random" in sys.modules:  # seeded once in the template: each child anew
            sys.modules["numpy.random"].seed()
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


if __name__ == "__main__":
    run_pytest(serve(int(sys.argv[1])))
