"""How many gradings to run at once (``grade-batch --jobs auto``).

A grading paced by the simulated clock spends most of its wall time waiting for the next
tick, so several share a core; a CPU-bound one (``real_time_factor: 0``) fills a core by
itself.  :func:`choose_jobs` is a pure function of the machine (cores, free memory) and of
one grading (its CPU share, its memory); the rest of this module reads those inputs.
"""

from __future__ import annotations

import dataclasses
import math
import os
import resource
import time
from collections.abc import Callable
from pathlib import Path
from typing import Literal, TypeVar

from autograder.i18n import _, ngettext

# Cores the gradings may ask for together, as a multiple of the cores there are. Above 1:
# a grading also waits on things that need no CPU (the clock's wall deadlines, a node's
# exit) and its demand comes in bursts, so the gaps fill only well past the cores; past
# that each grading only stretches, the pacing holding simulation time for a process that
# waits for a CPU (the figures: docs/contributors/measurements.md, "--jobs auto").
TARGET_LOAD = 2.0
# Most gradings at once: the most shown to keep every score full (the same section).
MAX_JOBS = 8
# Resident memory of one grading (pytest child, simulator, student node), with room for a
# node that allocates more than a reference solution does.
GRADING_MB = 400.0
# Least CPU share believed of a grading: a first student that only hangs measures little.
MIN_SHARE = 0.15
CGROUP = Path("/sys/fs/cgroup")

Bound = Literal["cpu", "memory", "students", "ceiling"]
T = TypeVar("T")


@dataclasses.dataclass(frozen=True)
class Choice:
    """A concurrency and what bounded it (the inputs kept so the choice can be explained)."""

    jobs: int
    bound: Bound
    cores: float
    cpu_share: float
    memory_mb: float
    grading_mb: float


def choose_jobs(*, cores: float, memory_mb: float, cpu_share: float, grading_mb: float,
                students: int, ceiling: int = MAX_JOBS, load: float = TARGET_LOAD) -> Choice:
    """Gradings at once: as many as keep ``load`` of ``cores`` busy at ``cpu_share`` cores
    each, fit in ``memory_mb`` at ``grading_mb`` each, and no more than ``students`` or
    ``ceiling``; always at least one."""
    share = max(cpu_share, MIN_SHARE)
    limits: dict[Bound, int] = {"cpu": math.floor(cores * load / share + 1e-9)}
    if grading_mb > 0 and math.isfinite(memory_mb):  # unknown free memory bounds nothing
        limits["memory"] = math.floor(memory_mb / grading_mb)
    limits.update(students=students, ceiling=ceiling)
    bound = min(limits, key=lambda name: limits[name])  # first listed wins a tie
    return Choice(max(1, limits[bound]), bound, cores, share, memory_mb, grading_mb)


def describe(choice: Choice) -> str:
    """One line: the number chosen and why."""
    head = ngettext("--jobs auto: {jobs} grading at a time.",
                    "--jobs auto: {jobs} gradings at a time.", choice.jobs).format(
        jobs=choice.jobs)
    share, cores = f"{choice.cpu_share:.2f}", f"{choice.cores:g}"
    if choice.bound == "cpu":
        why = _("Bound by the CPU: the first grading used {share} of a core, on {cores} "
                "cores.").format(share=share, cores=cores)
    elif choice.bound == "memory":
        why = _("Bound by memory: {free} MB free, about {each} MB per grading.").format(
            free=round(choice.memory_mb), each=round(choice.grading_mb))
    elif choice.bound == "students":
        why = _("Every student left to grade at once (the first grading used {share} of a "
                "core, on {cores} cores).").format(share=share, cores=cores)
    else:
        why = _("At most {ceiling}, the most measured to keep every score (the first "
                "grading used {share} of a core, on {cores} cores).").format(
            ceiling=choice.jobs, share=share, cores=cores)
    return f"{head} {why}"


# -- the machine --------------------------------------------------------------------------

def _read(path: Path) -> str | None:
    try:
        return path.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None


def cgroup_cpus(root: Path = CGROUP) -> float | None:
    """Cores the cgroup's CPU quota allows (v2 ``cpu.max``, v1 ``cpu.cfs_quota_us``), or
    None without a quota."""
    text = _read(root / "cpu.max")
    if text is not None:
        quota, _sep, period = text.partition(" ")
        if quota != "max" and period:
            return int(quota) / int(period)
        return None
    quota, period = _read(root / "cpu" / "cpu.cfs_quota_us"), _read(
        root / "cpu" / "cpu.cfs_period_us")
    if quota and period and int(quota) > 0:
        return int(quota) / int(period)
    return None


def cgroup_free_mb(root: Path = CGROUP) -> float | None:
    """Memory the cgroup may still use in MB (limit less usage, v2 or v1), or None."""
    for limit_name, usage_name in (("memory.max", "memory.current"),
                                   ("memory/memory.limit_in_bytes",
                                    "memory/memory.usage_in_bytes")):
        limit, usage = _read(root / limit_name), _read(root / usage_name)
        if limit is None or usage is None:
            continue
        if not limit.isdigit() or int(limit) >= 1 << 60:  # "max", or v1's "no limit"
            return None
        return (int(limit) - int(usage)) / 2**20
    return None


def available_mb(meminfo: Path = Path("/proc/meminfo")) -> float | None:
    """``MemAvailable`` in MB, or None where /proc/meminfo has none."""
    for line in (_read(meminfo) or "").splitlines():
        if line.startswith("MemAvailable:"):
            return int(line.split()[1]) / 1024
    return None


def machine_cores(root: Path = CGROUP) -> float:
    """Cores this process may use: its CPU affinity, less if a cgroup quota says so."""
    cores = float(len(os.sched_getaffinity(0)))
    quota = cgroup_cpus(root)
    return min(cores, quota) if quota else cores


def machine_memory_mb(root: Path = CGROUP) -> float:
    """Memory free for gradings in MB: the lesser of the system's and the cgroup's."""
    found = [m for m in (available_mb(), cgroup_free_mb(root)) if m is not None]
    return min(found) if found else math.inf


# -- one grading ----------------------------------------------------------------------------

def _cpu_seconds() -> float:
    own, children = (resource.getrusage(who) for who in
                     (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def measured(work: Callable[[], T]) -> tuple[T, float]:
    """``work()``'s value and the cores it kept busy on average (CPU time of this process
    and its waited-for children over wall time).  Only meaningful while nothing else runs
    in this process: the batch grades its first student alone to measure it."""
    cpu, wall = _cpu_seconds(), time.monotonic()
    value = work()
    elapsed = time.monotonic() - wall
    return value, (_cpu_seconds() - cpu) / elapsed if elapsed > 0 else 0.0


def auto_chooser(report: Callable[[str], None] | None = None,
                 grading_mb: float = GRADING_MB) -> Callable[[float, int], int]:
    """What ``run_batch`` calls with the first grading's CPU share and the students left:
    the concurrency for this machine, told to ``report`` in one line."""
    def choose(cpu_share: float, students: int) -> int:
        choice = choose_jobs(cores=machine_cores(), memory_mb=machine_memory_mb(),
                             cpu_share=cpu_share, grading_mb=grading_mb, students=students)
        if report is not None:
            report(describe(choice))
        return choice.jobs
    return choose
