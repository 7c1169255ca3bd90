"""What a grading takes from the machine's memory: the proportional set size (PSS) of its
whole process tree, summed, sampled while it runs.

The child pytests' peak resident sizes (``ru_maxrss``, see
:func:`autograder.plugin.reporter.peak_memory`) count the pages their processes share
(libpython, librcl, Fast DDS, numpy, the page cache of the same files) once per process,
so their sum overstates a grading's memory. PSS divides each shared page among the
processes that share it: summed over the grading's processes it is what they add to the
machine's memory. The kernel gives it per process in ``/proc/PID/smaps_rollup``. A process
whose rollup cannot be read (another user's, without the right to trace it; a kernel
older than 4.14) counts its resident size from ``/proc/PID/statm`` instead, which anyone
may read: more than its PSS, so the sum errs upwards. One that ended between being listed
and being read counts nothing. A sample never fails.

The tree is the grader itself, the template the child pytests were forked from if they
were (:mod:`autograder.grading.template`), and each child pytest (which holds the world
and the probe) with all its descendants (the students' programs and anything they
started), found
through each thread's ``/proc/PID/task/TID/children``: that reads a file per thread of
the tree, where a scan of every ``/proc/PID/stat`` for parent ids would read one per
process on the machine. The grader and the template count alone: in ``grade-batch``
their other descendants are other gradings'. A process whose parent ended has left the tree (the
kernel gives it to init), so it is not counted; nor is a peak that comes and goes between
two samples.
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from collections.abc import Sequence
from pathlib import Path

from sim.procstate import descendants

PROC = Path("/proc")
# Seconds between samples: a grading's memory changes as its processes start, slower than
# that, and a sample's CPU (the kernel walks each process's page tables) must stay a small
# part of a grading's (docs/contributors/measurements.md, "Memory sampling").
INTERVAL = 1.0


def pss_kb(smaps_rollup: str) -> int | None:
    """A process's PSS in KB from its ``smaps_rollup`` text (the ``Pss:`` line), None if
    the text has none."""
    for line in smaps_rollup.splitlines():
        if line.startswith("Pss:"):
            fields = line.split()
            if len(fields) >= 2 and fields[1].isdigit():
                return int(fields[1])
    return None


def resident_kb(statm: str, page_kb: int) -> int | None:
    """A process's resident size in KB from its ``statm`` text (the second field, in pages
    of ``page_kb`` KB), None if the text is not that."""
    fields = statm.split()
    if len(fields) < 2 or not fields[1].isdigit():
        return None
    return int(fields[1]) * page_kb


def _page_kb() -> int:
    """The machine's page size in KB (``statm`` counts pages)."""
    return os.sysconf("SC_PAGE_SIZE") // 1024


def _read(path: str) -> str | None:
    """A /proc file's text, None if it cannot be read (gone, not ours, not there). Plain
    ``os`` calls on a string path: a sample reads about a hundred such files."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return None
    try:
        chunks = []
        while chunk := os.read(fd, 65536):
            chunks.append(chunk)
    except OSError:
        return None
    finally:
        os.close(fd)
    return b"".join(chunks).decode("ascii", "replace")


def process_kb(pid: int, proc: Path = PROC, page_kb: int | None = None) -> int:
    """Process ``pid``'s PSS in KB, else its resident size (an overestimate), else 0."""
    text = _read(f"{proc}/{pid}/smaps_rollup")
    found = pss_kb(text) if text is not None else None
    if found is not None:
        return found
    text = _read(f"{proc}/{pid}/statm")
    if page_kb is None:
        page_kb = _page_kb()
    found = resident_kb(text, page_kb) if text is not None else None
    return found or 0


def tree_kb(own: int, roots: Sequence[int], proc: Path = PROC,
            page_kb: int | None = None, alone: Sequence[int] = ()) -> int:
    """The summed memory in KB (PSS, see :func:`process_kb`) of processes ``own`` and
    ``alone`` by themselves and of each of ``roots`` with its descendants; each process
    counted once."""
    pids = dict.fromkeys([own, *alone])
    for root in roots:
        pids.update(dict.fromkeys([root, *descendants(root, proc)]))
    page_kb = _page_kb() if page_kb is None else page_kb
    return sum(process_kb(pid, proc, page_kb) for pid in pids)


@dataclasses.dataclass
class Footprint:
    """The peak summed PSS of a grading's tree: this process, the processes ``alone`` (the
    template the children were forked from) and the child pytests ``roots`` with their
    descendants, sampled at most every ``interval`` seconds."""

    roots: Sequence[int]
    interval: float = INTERVAL
    proc: Path = PROC
    own: int = dataclasses.field(default_factory=os.getpid)
    alone: Sequence[int] = ()
    peak_kb: int = 0
    samples: int = 0
    _last: float = dataclasses.field(default=-math.inf, init=False, repr=False)

    def sample(self, now: float | None = None) -> None:
        """Sum the tree now if ``interval`` seconds (less a tenth, for the callers' wake-ups
        that come a little early) have passed since the last sample; keep the peak."""
        now = time.monotonic() if now is None else now
        if now - self._last < self.interval * 0.9:
            return
        self._last = now
        self.peak_kb = max(self.peak_kb, tree_kb(self.own, self.roots, self.proc,
                                                 alone=self.alone))
        self.samples += 1

    @property
    def peak_mb(self) -> float | None:
        """The peak in MB (to 0.1), None before the first sample."""
        return round(self.peak_kb / 1024, 1) if self.samples else None
