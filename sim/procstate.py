"""What a watched process is doing, read from ``/proc``: the pacing's only view of it.

Two facts per process, summed over its threads:

* **busy**: some thread is running or runnable (state ``R`` in
  ``/proc/<pid>/task/*/stat``).  A runnable thread that waits for a CPU counts as busy,
  which is what lets a starved process hold simulation time back.
* **blocked**: some thread sleeps in the kernel uninterruptibly (state ``D``): a page
  being read in from disk, memory being reclaimed, a ``vfork`` child not yet started.
  It waits for the machine, not for a message, and goes on by itself.
* **cpu_ns**: CPU time used so far, in nanoseconds (the first field of
  ``/proc/<pid>/task/*/schedstat``).  Told apart from *busy*, it separates a process that
  computes (its CPU time grows) from one that only waits for a CPU (it does not).

Both are also read over the program's **own** threads alone (``own_busy``,
``own_cpu_ns``): every thread but its middleware's, which Fast DDS names ``dds.*``.
A node's middleware takes a ``/clock`` sample in on its own threads whether or not
the node's executor wakes for it, so only the program's own threads say that the node
has heard a tick.

A process that is gone reads as idle with no CPU time and ``exists`` false: it has
nothing left to react to.

It also says whether this process's own middleware is still taking messages in
(:class:`Receiving`), which the pacing waits for once the watched processes are done.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class ProcessState:
    """One reading of a process: is any thread running or runnable, CPU ns used so far,
    and both over its own threads alone (not its middleware's; when not given, the same
    as over all its threads)."""

    busy: bool
    cpu_ns: int
    exists: bool = True
    own_busy: bool = None  # type: ignore[assignment]  # None: as busy
    own_cpu_ns: int = None  # type: ignore[assignment]  # None: as cpu_ns
    blocked: bool = False  # some thread is in uninterruptible sleep (state D)
    own_blocked: bool = None  # type: ignore[assignment]  # None: as blocked

    def __post_init__(self) -> None:
        if self.own_busy is None:
            object.__setattr__(self, "own_busy", self.busy)
        if self.own_cpu_ns is None:
            object.__setattr__(self, "own_cpu_ns", self.cpu_ns)
        if self.own_blocked is None:
            object.__setattr__(self, "own_blocked", self.blocked)


IDLE = ProcessState(busy=False, cpu_ns=0, exists=False)
"""How a process that is gone reads."""

ProcessReader = Callable[[int], ProcessState]
"""Reads the state of process ``pid`` (the pacing takes one, so tests can fake it)."""


MIDDLEWARE_THREADS = b"dds."
"""How Fast DDS (Jazzy's default middleware) begins the names of the threads it starts
(``dds.udp.<port>``, ``dds.ev.<n>``, ``dds.shm.wdog``, ...): their work is the
middleware's, not the program's."""


def _thread_state(stat: bytes) -> bytes:
    # The state follows the command name, which is in parentheses and may itself hold
    # spaces or parentheses: read it after the last ")".
    end = stat.rindex(b")")
    return stat[end + 2:end + 3]


def _thread_running(stat: bytes) -> bool:
    return _thread_state(stat) == b"R"


def _middleware_thread(stat: bytes) -> bool:
    """The thread's name (between the first "(" and the last ")") is Fast DDS's."""
    return stat[stat.index(b"(") + 1:stat.rindex(b")")].startswith(MIDDLEWARE_THREADS)


def process_state(pid: int) -> bytes | None:
    """The state letter of process ``pid`` (``R``, ``S``, ``D``, ``T``, ``t``, ``Z``...,
    its main thread's), or None once it is gone."""
    try:
        return _thread_state(_read_file(f"/proc/{pid}/stat", 4096)) or None
    except (OSError, ValueError):
        return None


def thread_busy(tid: int) -> bool:
    """True if thread ``tid`` of this process is running or waits for a CPU; False if it
    sleeps or is gone."""
    try:
        return _thread_running(_read_file(f"/proc/self/task/{tid}/stat", 4096))
    except (OSError, ValueError):
        return False


# Each watched thread's ``stat`` and ``schedstat``, kept open and read with ``pread``: the
# pacing reads a busy process every 0.5 ms, and opening two files per thread each time is
# most of the kernel's share of the world's CPU (``benchmarks/RESULTS.md``). pid -> tid ->
# (stat, schedstat); the processes read least recently are closed past MAX_PROCESSES.
_open: dict[int, dict[str, tuple[int, int]]] = {}
_open_lock = threading.Lock()
MAX_PROCESSES = 32


def read_process_state(pid: int) -> ProcessState:
    """The state of ``pid`` now, from ``/proc``; :data:`IDLE` if it is gone.

    The threads are listed afresh at each reading (a thread started since counts at
    once); each thread's files are opened at its first reading and read again in place. A
    file that fails (its thread ended, or a new thread took its number) is opened again,
    once, before that thread is skipped."""
    base = f"/proc/{pid}/task/"
    try:
        tids = os.listdir(base)
    except OSError:
        with _open_lock:
            _close_process(pid)
        return IDLE
    busy, cpu, own_busy, own_cpu, blocked, own_blocked = False, 0, False, 0, False, False
    with _open_lock:
        files = _open.pop(pid, None) or {}
        _open[pid] = files  # last: the most recently read
        while len(_open) > MAX_PROCESSES:
            _close_process(next(iter(_open)))
        for tid in files.keys() - set(tids):
            _close(files.pop(tid))
        for tid in tids:
            reading = _read_thread(base, tid, files)
            if reading is not None:
                state, used, middleware = reading
                running, waiting = state == b"R", state == b"D"
                busy, blocked = busy or running, blocked or waiting
                cpu += used
                if not middleware:
                    own_busy, own_blocked = own_busy or running, own_blocked or waiting
                    own_cpu += used
    return ProcessState(busy, cpu, own_busy=own_busy, own_cpu_ns=own_cpu, blocked=blocked,
                        own_blocked=own_blocked)


def _read_thread(base: str, tid: str, files: dict[str, tuple[int, int]],
                 ) -> tuple[bytes, int, bool] | None:
    """(state letter, CPU ns, the middleware's) of one thread through its kept files;
    None if it cannot be read (it ended between listing and reading)."""
    for attempt in range(2):
        fds = files.get(tid)
        try:
            if fds is None:
                fds = files[tid] = _open_thread(f"{base}{tid}/")
            stat = os.pread(fds[0], 4096, 0)
            return (_thread_state(stat), int(os.pread(fds[1], 128, 0).split()[0]),
                    _middleware_thread(stat))
        except (OSError, ValueError, IndexError):
            if tid in files:
                _close(files.pop(tid))
            if fds is None or attempt:  # a fresh open failed too: the thread is gone
                return None
    return None


def _open_thread(folder: str) -> tuple[int, int]:
    stat = os.open(f"{folder}stat", os.O_RDONLY | os.O_CLOEXEC)
    try:
        return stat, os.open(f"{folder}schedstat", os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        os.close(stat)
        raise


def _close(fds: tuple[int, int]) -> None:
    for fd in fds:
        os.close(fd)


def _close_process(pid: int) -> None:
    for fds in (_open.pop(pid, None) or {}).values():
        _close(fds)


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


def child_pids(children: str) -> list[int]:
    """The process ids a thread's ``children`` file lists (separated by spaces)."""
    return [int(field) for field in children.split() if field.isdigit()]


def descendants(pid: int, proc: str | os.PathLike[str] = "/proc") -> list[int]:
    """Every process below ``pid`` (children, their children, ...), each once, as the
    children files of every thread list them; empty if ``pid`` has ended."""
    found: list[int] = []
    seen = {pid}
    todo = [pid]
    while todo:
        parent = todo.pop()
        try:
            threads = os.listdir(f"{proc}/{parent}/task")
        except OSError:
            continue
        for thread in threads:
            try:
                text = _read_file(f"{proc}/{parent}/task/{thread}/children", 65536).decode()
            except OSError:
                continue
            for child in child_pids(text):
                if child not in seen:
                    seen.add(child)
                    found.append(child)
                    todo.append(child)
    return found


ProcessKey = tuple[int, int]
"""(pid, start time in clock ticks): a pid taken again by a new process is another key."""


def family_usage(pids: Iterable[int]) -> dict[ProcessKey, tuple[int, int]]:
    """For each live process of ``pids``: CPU ns used and ns waited for a CPU so far, summed
    over its threads (``/proc/<pid>/task/*/schedstat``). One gone meanwhile is left out."""
    usage: dict[ProcessKey, tuple[int, int]] = {}
    for pid in pids:
        base = f"/proc/{pid}/task/"
        try:
            # The start time is field 22; the fields after the ")" that closes the command
            # name begin at field 3.
            start = int(_read_file(f"/proc/{pid}/stat", 1024).rsplit(b")", 1)[1].split()[19])
            tids = os.listdir(base)
        except (OSError, ValueError, IndexError):
            continue
        cpu = waited = 0
        for tid in tids:
            try:
                fields = _read_file(f"{base}{tid}/schedstat", 128).split()
                cpu, waited = cpu + int(fields[0]), waited + int(fields[1])
            except (OSError, ValueError, IndexError):
                continue
        usage[(pid, start)] = (cpu, waited)
    return usage


class UsageTally:
    """What a family of processes (``family()``: their pids now) used over a span of wall
    time, from readings along it: the first :meth:`read` starts the span (or the first
    :meth:`read_if_due`, ``every`` seconds after the tally was made: most waits end
    sooner and read nothing). Each process counts from its reading at the start, or from
    0 if it first appears later (it was born meanwhile), to its last reading; one born and
    gone between two readings is missed, so a wait reads every ``every`` seconds."""

    def __init__(self, family: Callable[[], Iterable[int]], every: float = 0.25,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._family, self._every, self._clock = family, every, clock
        self._first: dict[ProcessKey, tuple[int, int]] = {}
        self._last: dict[ProcessKey, tuple[int, int]] = {}
        self._began: float | None = None
        self._due = clock() + every

    def read_if_due(self) -> None:
        if self._clock() >= self._due:
            self.read()

    def read(self) -> None:
        now = self._clock()
        for key, value in family_usage(self._family()).items():
            self._first.setdefault(key, value if self._began is None else (0, 0))
            self._last[key] = value
        if self._began is None:
            self._began = now
        self._due = now + self._every

    @property
    def span_seconds(self) -> float:
        """Wall seconds from the first reading to now (0 before it)."""
        return 0.0 if self._began is None else self._clock() - self._began

    def _summed(self, index: int) -> float:
        return sum(last[index] - self._first[key][index]
                   for key, last in self._last.items()) / 1e9

    @property
    def cpu_seconds(self) -> float:
        """CPU seconds the family used over the span."""
        return self._summed(0)

    @property
    def waited_seconds(self) -> float:
        """Seconds its threads, summed, spent runnable but waiting for a CPU."""
        return self._summed(1)


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
