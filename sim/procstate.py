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
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path


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
    """The state of ``pid`` now, from ``/proc``; :data:`IDLE` if it is gone."""
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
    except OSError:
        return IDLE
    busy, cpu = False, 0
    for task in tasks:
        try:  # a thread may end between listing and reading: skip it
            stat = (task / "stat").read_bytes()
            cpu += int((task / "schedstat").read_bytes().split()[0])
            busy = busy or _thread_running(stat)
        except (OSError, ValueError, IndexError):
            continue
    return ProcessState(busy, cpu)


def process_busy(pid: int) -> bool:
    """True if any thread of ``pid`` is running or runnable; False if idle or gone."""
    return read_process_state(pid).busy
