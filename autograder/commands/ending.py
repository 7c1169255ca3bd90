"""How a command ends, whatever ends it.

- SIGTERM and SIGHUP end a command the way Ctrl-C does: :class:`Stopped` is a
  ``KeyboardInterrupt``, so every ``except KeyboardInterrupt`` and ``finally`` on the way
  out runs (the student's node stopped, folders removed, the summary printed), and the
  command then exits with the conventional 128 + signal. Repeats while it cleans up
  (a closed terminal sends SIGHUP more than once) are ignored.
- A parent that dies (the terminal's shell killed) sends SIGHUP (``PR_SET_PDEATHSIG``),
  unless SIGHUP is ignored (``nohup``) or the command leads a session of its own
  (``setsid``): those ask to outlive their parent.
- A closed stdout or stderr is not an error: from the first failed write on, that stream
  goes to /dev/null (CPython's advice for SIGPIPE, "Note on SIGPIPE" in the signal
  module's documentation), so files are still written and the status is the usual one.
  A command that runs until stopped (:func:`stop_on_closed_pipe`) then ends as Ctrl-C
  ends it, with status 0.
"""

from __future__ import annotations

import _thread
import contextlib
import ctypes
import dataclasses
import errno
import functools
import io
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any, TextIO

ENDING_SIGNALS = (signal.SIGTERM, signal.SIGHUP)
_PR_SET_PDEATHSIG = 1
_PR_GET_PDEATHSIG = 2
# A write to a stream nobody reads any more: a closed pipe, a terminal hung up.
_GONE = (errno.EPIPE, errno.EIO)


class Stopped(KeyboardInterrupt):
    """The command was told to stop by ``signum`` (SIGTERM, SIGHUP; SIGPIPE for a closed
    output): raised where Ctrl-C's ``KeyboardInterrupt`` would be."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name


@dataclasses.dataclass
class _State:
    """What ended this command so far."""

    signum: int | None = None  # the first signal that stopped it
    pipe_stops: bool = False  # a closed output stops it (see stop_on_closed_pipe)
    pipe_pending: bool = False  # a closed output asked for that stop
    lock: threading.Lock = dataclasses.field(default_factory=threading.Lock)

    def on_signal(self, signum: int, _frame: Any) -> None:
        if self.signum is not None:
            return  # already ending: let the cleanup finish
        # A closed output asks for its stop through this handler (see _stream_gone).
        self.signum = signal.SIGPIPE if self.pipe_pending else signum
        raise Stopped(self.signum)

    def exit_status(self, code: Any) -> Any:
        """The status to exit with: 128 + SIGTERM or SIGHUP once one stopped the command."""
        if self.signum in ENDING_SIGNALS:
            return 128 + self.signum
        if self.signum == signal.SIGPIPE and code in (None, 1):
            return 0  # ended by its reader going away (click says 1 for an abort)
        return code


_state: _State | None = None


def stop_on_closed_pipe() -> None:
    """This command runs until it is stopped (a world, a server): a closed stdout or stderr
    ends it as Ctrl-C would, instead of it running on unseen."""
    if _state is not None:
        _state.pipe_stops = True


class _Tolerant(io.FileIO):
    """The file under stdout or stderr: a write to a reader that went away goes to
    /dev/null from then on, and tells the command (:func:`_stream_gone`)."""

    def write(self, data: Any) -> int:
        try:
            return super().write(data)
        except OSError as exc:
            if exc.errno not in _GONE:
                raise
            _stream_gone(self.fileno())
            return memoryview(data).nbytes


def _stream_gone(fd: int) -> None:
    """``fd``'s reader is gone: point ``fd`` at /dev/null, and stop a command that runs
    until stopped (in its main thread, as a signal would: a write may come from any)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
    finally:
        os.close(devnull)
    state = _state
    if state is None:
        return
    with state.lock:
        ask = state.pipe_stops and not state.pipe_pending and state.signum is None
        state.pipe_pending = state.pipe_pending or ask
    if ask:
        _thread.interrupt_main(signal.SIGTERM)  # its handler stops with SIGPIPE


def _tolerant(stream: TextIO) -> TextIO:
    """``stream`` (sys.stdout or sys.stderr) rebuilt over a :class:`_Tolerant` file, with
    its encoding and buffering; ``stream`` itself where it has no file (a test's)."""
    try:
        fd = stream.fileno()
    except (AttributeError, OSError, ValueError):
        return stream
    with contextlib.suppress(OSError, ValueError):
        stream.flush()
    raw = _Tolerant(fd, "wb", closefd=False)
    return io.TextIOWrapper(
        io.BufferedWriter(raw), encoding=stream.encoding, errors=stream.errors,
        line_buffering=stream.line_buffering,
        write_through=getattr(stream, "write_through", False))


def _pdeathsig(signum: int) -> int:
    """Set this process's parent-death signal; the one it had (0: none)."""
    libc = ctypes.CDLL(None, use_errno=True)
    old = ctypes.c_int(0)
    libc.prctl(_PR_GET_PDEATHSIG, ctypes.byref(old), 0, 0, 0)
    libc.prctl(_PR_SET_PDEATHSIG, signum, 0, 0, 0)
    return old.value


def _wants_to_outlive_parent() -> bool:
    """``nohup`` (SIGHUP ignored) or ``setsid`` (a session of its own) asked for it."""
    return (signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            or os.getsid(0) == os.getpid())


@contextlib.contextmanager
def handled() -> Iterator[_State]:
    """Run a command with the endings above in place; everything is put back afterwards
    (a test may call the command in its own process). Outside the main thread, where
    signals cannot be handled, nothing is changed."""
    global _state
    state = _State()
    if threading.current_thread() is not threading.main_thread() or _state is not None:
        yield state
        return
    handlers = {sig: signal.getsignal(sig) for sig in ENDING_SIGNALS}
    for sig, old in handlers.items():
        if old is not signal.SIG_IGN:  # nohup's SIGHUP stays ignored
            signal.signal(sig, state.on_signal)
    streams = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _tolerant(sys.stdout), _tolerant(sys.stderr)
    parent = os.getppid()
    old_pdeathsig = None
    if not _wants_to_outlive_parent():
        old_pdeathsig = _pdeathsig(signal.SIGHUP)
        if os.getppid() != parent:  # it died before it could be watched
            os.kill(os.getpid(), signal.SIGHUP)
    _state = state
    try:
        yield state
    finally:
        _state = None
        if old_pdeathsig is not None:
            _pdeathsig(old_pdeathsig)
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(OSError, ValueError):
                stream.flush()
        sys.stdout, sys.stderr = streams
        for sig, old in handlers.items():
            if old is not signal.SIG_IGN:
                signal.signal(sig, old)


def until_stopped(command: Any, open_ended: Callable[[dict[str, Any]], bool]) -> None:
    """Make the click ``command`` one that runs until stopped (see
    :func:`stop_on_closed_pipe`) whenever ``open_ended(its options)`` says so (a world
    without ``--duration``, a drive without ``--for``)."""
    if getattr(command, "until_stopped", False):
        return  # already made so
    command.until_stopped = True
    original = command.callback

    @functools.wraps(original)
    def callback(**kwargs: Any) -> Any:
        if open_ended(kwargs):
            stop_on_closed_pipe()
        return original(**kwargs)

    command.callback = callback
