"""What a watched process is doing, read from ``/proc``: the pacing's only view of it.

Two facts per process, summed over its threads:

* **busy**: some thread is running or runnable (state ``R`` in
  ``/proc/<pid>/task/*/stat``).  A runnable thread that waits for a CPU counts as busy,
  which is what lets a starved process hold simulation time back.
* **cpu_ns**: CPU time used so far, in nanoseconds (the first field of
  ``/proc/<pid>/task/*/schedstat``).  Told apart from *busy*, it separates a process that
  computes (its CPU time grows) from one that only waits for a CPU (it does not).

A process that is gone reads as idle with no CPU time and ``exists`` false: it has
nothing left to react to.

It also says whether this process's own middleware is still taking messages in
(:class:`Receiving`), which the pacing waits for once the watched processes are done.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class ProcessState:
    """One reading of a process: is any thread running or runnable, CPU ns used so far."""

    busy: bool
    cpu_ns: int
    exists: bool = True


IDLE = ProcessState(busy=False, cpu_ns=0, exists=False)
"""How a process that is gone reads."""

ProcessReader = Callable[[int], ProcessState]
"""Reads the state of process ``pid`` (the pacing takes one, so tests can fake it)."""


def _thread_running(stat: bytes) -> bool:
    # The state follows the command name, which is in parentheses and may itself hold
    # spaces or parentheses: read it after the last ")".
    end = stat.rindex(b")")
    return stat[end + 2:end + 3] == b"R"


def read_process_state(pid: int) -> ProcessState:
    """The state of ``pid`` now, from ``/proc``; :data:`IDLE` if it is gone.

    Each file is opened for this reading alone, with plain ``os`` calls on string paths:
    220 us for a 16-thread process, against 480 through ``pathlib``."""
    base = f"/proc/{pid}/task/"
    try:
        tids = os.listdir(base)
    except OSError:
        return IDLE
    busy, cpu = False, 0
    for tid in tids:
        try:  # a thread may end between listing and reading: skip it
            stat = _read_file(f"{base}{tid}/stat", 4096)
            cpu += int(_read_file(f"{base}{tid}/schedstat", 128).split()[0])
            busy = busy or _thread_running(stat)
        except (OSError, ValueError, IndexError):
            continue
    return ProcessState(busy, cpu)


def runqueue_wait_ns(pid: int) -> int:
    """Nanoseconds the threads of ``pid`` have spent runnable but waiting for a CPU (the
    second field of ``/proc/<pid>/task/*/schedstat``): what a busy machine took from it.
    0 if it is gone, the kernel keeps no such count, or it has children (then the wait
    may be its own doing: a program that forks spinning children starves itself)."""
    base = f"/proc/{pid}/task/"
    try:
        tids = os.listdir(base)
    except OSError:
        return 0
    waited = 0
    for tid in tids:
        try:
            if _read_file(f"{base}{tid}/children", 64).strip():
                return 0
            waited += int(_read_file(f"{base}{tid}/schedstat", 128).split()[1])
        except (OSError, ValueError, IndexError):
            continue
    return waited


def _read_file(path: str, size: int) -> bytes:
    fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    try:
        return os.read(fd, size)
    finally:
        os.close(fd)


RECEIVE_THREADS = (b"dds.udp.", b"dds.shm.")
"""How Fast DDS (Jazzy's default middleware) names the threads that receive its
transports' datagrams (``dds.udp.<port>``, ``dds.shm.<port>``)."""
NOT_RECEIVING = (b"dds.shm.wdog",)
"""Threads with those names that receive nothing (the shared-memory watchdog)."""
SOFTNET_STAT = "/proc/net/softnet_stat"


class Receiving:
    """Whether this process's middleware still has messages to take in: one of its
    receive threads is running or runnable, or the kernel holds received packets that no
    socket has been handed yet.

    A node that is idle has sent what it sent: each datagram is then in the kernel's
    backlog (a busy machine leaves that work to ``ksoftirqd``), or queued on a socket,
    which makes the thread reading that socket runnable, or already in the reader's
    history, where the world takes it (:meth:`sim.bridge.SimBridge.take_commands`).  The
    backlog is the machine's, not this process's (``/proc/net/softnet_stat``, the sum of
    every CPU's queue, from Linux 5.10): reading it as ours only holds longer, never
    shorter.

    Each thread's ``stat`` is kept open (a thread's name is read once); safe to call from
    any thread; :meth:`close` closes the files.
    """

    def __init__(self, names: tuple[bytes, ...] = RECEIVE_THREADS,
                 softnet: str = SOFTNET_STAT) -> None:
        self._names = names
        self._softnet = softnet
        self._threads: dict[str, int | None] = {}  # tid -> its stat file, None if not one
        self._lock = threading.Lock()
        self._closed = False

    def __call__(self) -> bool:
        with self._lock:
            if self._closed:
                return False
            return self._threads_busy() or backlog(self._softnet) > 0

    def _threads_busy(self) -> bool:
        try:
            tids = os.listdir("/proc/self/task")
        except OSError:
            return False
        for tid in self._threads.keys() - set(tids):
            fd = self._threads.pop(tid)
            if fd is not None:
                os.close(fd)
        for tid in tids:
            if tid not in self._threads:
                self._threads[tid] = self._open_if_receiving(tid)
            fd = self._threads[tid]
            if fd is None:
                continue
            try:
                if _thread_running(os.pread(fd, 4096, 0)):
                    return True
            except OSError:  # ended, or its number reused: look again next time
                os.close(self._threads.pop(tid))
            except (ValueError, IndexError):
                continue
        return False

    def _open_if_receiving(self, tid: str) -> int | None:
        try:
            with open(f"/proc/self/task/{tid}/comm", "rb") as fh:
                name = fh.read().strip()
            if not name.startswith(self._names) or name.startswith(NOT_RECEIVING):
                return None
            return os.open(f"/proc/self/task/{tid}/stat", os.O_RDONLY | os.O_CLOEXEC)
        except OSError:
            return None

    def close(self) -> None:
        with self._lock:
            self._closed = True
            for fd in self._threads.values():
                if fd is not None:
                    os.close(fd)
            self._threads.clear()


def backlog(path: str = SOFTNET_STAT) -> int:
    """Packets the kernel has received and not yet handed to a socket, over every CPU
    (0 where the kernel does not say: before Linux 5.10, or no ``/proc/net``)."""
    try:
        with open(path, "rb") as fh:
            rows = fh.read().split(b"\n")
    except OSError:
        return 0
    total = 0
    for row in rows:
        columns = row.split()
        if len(columns) >= 13:  # ..., flow_limit_count, backlog length, CPU number, ...
            total += int(columns[11], 16)
    return total


def process_busy(pid: int) -> bool:
    """True if any thread of ``pid`` is running or runnable; False if idle or gone."""
    return read_process_state(pid).busy
