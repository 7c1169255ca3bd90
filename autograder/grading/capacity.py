"""How many gradings to run at once (``grade-batch --jobs auto``).

A grading paced by the simulated clock spends most of its wall time waiting for the next
tick, so several share a core; a CPU-bound one (``real_time_factor: 0``) fills a core by
itself.  :func:`choose_jobs` is a pure function of the machine (cores, free memory) and of
a grading (its CPU share, its memory); :class:`Tally` keeps what the gradings finished so
far showed, so that the choice is made again as each one ends (:func:`auto_chooser`); the
rest of this module reads those inputs.
"""

from __future__ import annotations

import dataclasses
import math
import os
import resource
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Literal, TypeVar

from autograder.core.results import RunResult
from autograder.grading.forked import forked_cpu_seconds
from autograder.i18n import _, ngettext

# Cores the gradings may ask for together, as a multiple of the cores there are. Above 1:
# a grading also waits on things that need no CPU (the clock's wall deadlines, a node's
# exit) and its demand comes in bursts, so the gaps fill only well past the cores; past
# that each grading only stretches, the pacing holding simulation time for a process that
# waits for a CPU (the figures: docs/contributors/measurements.md, "--jobs auto").
TARGET_LOAD = 2.0
# Most gradings at once per core: the most shown to keep every score full (the same
# section). Eight at once on 2 cores lost a correct error_handling node's test in 1 to 3
# of 100 gradings (the pacing took the node's middleware taking a tick in for the node
# hearing it; fixed since, and twelve error_handling at once then kept 96 of 96); four at
# once lost none of 100. Kept at two: a class of 100 at up to four a core was only 8 %
# faster, slower for ai_bridge, and a world took a command seven ticks late; at three a
# core in 22 % less time, every score full, but a command six ticks late, past error_handling's
# watchdog (benchmarks/RESULTS.md, 2026-11-28). Measured on 2 cores only.
JOBS_PER_CORE = 2
# Resident memory of one grading (pytest child, simulator, student node), with room for a
# node that allocates more than a reference solution does.
GRADING_MB = 400.0
# Least CPU share believed of a grading: a first student that only hangs measures little.
MIN_SHARE = 0.15
CGROUP = Path("/sys/fs/cgroup")

# A measured footprint (the PSS of a grading's whole tree) times this is what a grading is
# believed to need: students' programs differ, and the footprint is sampled once a second.
MEMORY_MARGIN = 1.5

Bound = Literal["cpu", "memory", "students", "ceiling", "strained"]
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


def max_jobs(cores: float) -> int:
    """The most gradings at once on ``cores`` cores, whatever they measure:
    :data:`JOBS_PER_CORE` a core, at least one."""
    return max(1, math.floor(cores * JOBS_PER_CORE + 1e-9))


def choose_jobs(*, cores: float, memory_mb: float, cpu_share: float, grading_mb: float,
                students: int, ceiling: int | None = None, load: float = TARGET_LOAD,
                strained: int | None = None) -> Choice:
    """Gradings at once: as many as keep ``load`` of ``cores`` busy at ``cpu_share`` cores
    each, fit in ``memory_mb`` at ``grading_mb`` each, and no more than ``students``,
    ``ceiling`` (None: :func:`max_jobs` of the cores) or ``strained`` (fewer than the most
    at once seen to starve a student's program); always at least one."""
    if ceiling is None:
        ceiling = max_jobs(cores)
    share = max(cpu_share, MIN_SHARE)
    limits: dict[Bound, int] = {"cpu": math.floor(cores * load / share + 1e-9)}
    if grading_mb > 0 and math.isfinite(memory_mb):  # unknown free memory bounds nothing
        limits["memory"] = math.floor(memory_mb / grading_mb)
    limits.update(students=students, ceiling=ceiling)
    if strained is not None:
        limits["strained"] = strained
    bound = min(limits, key=lambda name: limits[name])  # first listed wins a tie
    return Choice(max(1, limits[bound]), bound, cores, share, memory_mb, grading_mb)


def describe(choice: Choice) -> str:
    """One line: the number chosen and why."""
    head = ngettext("--jobs auto: {jobs} grading at a time.",
                    "--jobs auto: {jobs} gradings at a time.", choice.jobs).format(
        jobs=choice.jobs)
    share, cores = f"{choice.cpu_share:.2f}", f"{choice.cores:g}"
    if choice.bound == "cpu":
        why = _("Bound by the CPU: a grading uses {share} of a core as measured so far, on "
                "{cores} cores.").format(share=share, cores=cores)
    elif choice.bound == "memory":
        why = _("Bound by memory: {free} MB free, about {each} MB per grading.").format(
            free=round(choice.memory_mb), each=round(choice.grading_mb))
    elif choice.bound == "students":
        why = _("Every student left to grade at once (a grading uses {share} of a core as "
                "measured so far, on {cores} cores).").format(share=share, cores=cores)
    elif choice.bound == "strained":
        why = _("At most {jobs}: with more at once, a student's program had to wait for a "
                "CPU longer than the world holds its clock for it.").format(jobs=choice.jobs)
    else:
        why = _("At most {ceiling}, the most measured to keep every score (a grading uses "
                "{share} of a core as measured so far, on {cores} cores).").format(
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
    """This process's CPU time and its ended children's: those it waited for, and the
    template and the child pytests it forked (their parent is the template, which is
    waited for only at exit)."""
    own, children = (resource.getrusage(who) for who in
                     (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return (own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime
            + forked_cpu_seconds())


def measured(work: Callable[[], T]) -> tuple[T, float]:
    """``work()``'s value and the cores it kept busy on average (CPU time of this process
    and its waited-for children over wall time).  Only meaningful while nothing else runs
    in this process: the batch grades its first student alone to measure it."""
    cpu, wall = _cpu_seconds(), time.monotonic()
    value = work()
    elapsed = time.monotonic() - wall
    return value, (_cpu_seconds() - cpu) / elapsed if elapsed > 0 else 0.0


@dataclasses.dataclass(frozen=True)
class Tally:
    """What the gradings of a batch finished so far showed: the first one's wall time (it
    ran alone: the wall a grading takes without others), their CPU seconds summed (the
    grader's and every program it started), the largest footprint, and the most gradings
    that ran at once while one of them starved a student's program (None: never)."""

    first_wall: float = 0.0
    graded: int = 0
    cpu_seconds: float = 0.0
    footprint_mb: float | None = None
    strained_at: int | None = None

    def add(self, *, wall: float, cpu_seconds: float, footprint_mb: float | None,
            strained: bool, at_once: int) -> Tally:
        """This tally with one more grading: its wall, the batch's CPU seconds since the
        last one ended, its footprint, whether it starved a student's program and how many
        gradings were running when it ended (itself included)."""
        peaks = [m for m in (self.footprint_mb, footprint_mb) if m is not None]
        strained_at = self.strained_at
        if strained:
            strained_at = at_once if strained_at is None else min(strained_at, at_once)
        return Tally(first_wall=self.first_wall if self.graded else wall,
                     graded=self.graded + 1, cpu_seconds=self.cpu_seconds + cpu_seconds,
                     footprint_mb=max(peaks) if peaks else None, strained_at=strained_at)

    @property
    def cpu_share(self) -> float:
        """The cores a grading keeps busy when it runs alone: its CPU seconds (the mean so
        far) over the first grading's wall. Walls at concurrency are not used: contention
        stretches them, and a share read from them would fall as concurrency rises and
        raise it again."""
        if not self.graded or self.first_wall <= 0:
            return 0.0
        return self.cpu_seconds / self.graded / self.first_wall

    def grading_mb(self, default: float = GRADING_MB) -> float:
        """Memory a grading is believed to need: the largest footprint seen with a margin,
        else ``default``."""
        return default if self.footprint_mb is None else self.footprint_mb * MEMORY_MARGIN


def decide(tally: Tally, *, cores: float, memory_mb: float, students: int,
           ceiling: int | None = None) -> Choice:
    """The concurrency for the ``students`` left from what ``tally`` showed: as
    :func:`choose_jobs`, and one fewer than the most at once that starved a student."""
    strained = None if tally.strained_at is None else max(1, tally.strained_at - 1)
    return choose_jobs(cores=cores, memory_mb=memory_mb, cpu_share=tally.cpu_share,
                       grading_mb=tally.grading_mb(), students=students, ceiling=ceiling,
                       strained=strained)


def starved(result: RunResult) -> bool:
    """Whether a grading's results show a student's program starved of CPU: a world that
    went on at its wall cap while the program still had work (``pacing``)."""
    return any(module.count("cap") for module in result.pacing.values())


class AutoChooser:
    """``--jobs auto`` for ``run_batch``: told of each grading as it starts and ends, it
    gives the concurrency for the rest (see :func:`decide`) and tells ``report`` when it
    changes.

    The batch's CPU shows in this process's counters as its gradings' processes end (a
    module's child at the end of that module), whichever grading they were part of, so
    each reading's growth is shared among the gradings that ran since the last reading, in
    proportion to how long each ran in that time: a grading's CPU is what it was dealt
    while it ran. (Counting all of it as the grading that ended read seven gradings' CPU as
    one's, and the choice swung from 7 to 2 and back, `benchmarks/RESULTS.md`.) Without
    ``started`` calls, what grew since the last end is the ending grading's."""

    def __init__(self, report: Callable[[str], None] | None = None,
                 cores: Callable[[], float] | None = None,
                 memory_mb: Callable[[], float] | None = None,
                 cpu: Callable[[], float] | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._report = report
        self._cores = cores or machine_cores
        self._memory_mb = memory_mb or machine_memory_mb
        self._cpu = cpu or _cpu_seconds
        self._clock = clock
        self._lock = threading.Lock()
        self._last_cpu = self._cpu()
        self._last_read = clock()
        self._running: list[list[float]] = []  # [started, CPU seconds dealt so far]
        self.tally = Tally()
        self.jobs: int | None = None

    def _deal(self) -> float:
        """Share the CPU grown since the last reading among the running gradings by the
        time each ran since then; what grew (also when none was running)."""
        now, cpu = self._clock(), self._cpu()
        grown = cpu - self._last_cpu
        spans = [now - max(started, self._last_read) for started, _dealt in self._running]
        total = sum(spans)
        for grading, span in zip(self._running, spans, strict=True):
            grading[1] += grown * span / total if total > 0 else grown / len(self._running)
        self._last_cpu, self._last_read = cpu, now
        return grown

    def started(self) -> None:
        """A grading starts now."""
        with self._lock:
            self._deal()
            self._running.append([self._clock(), 0.0])

    def __call__(self, wall: float, result: RunResult, at_once: int, students: int) -> int:
        """One grading ended after ``wall`` seconds with ``result``, ``at_once``
        running then (itself included), ``students`` left to grade (running or not)."""
        with self._lock:
            grown = self._deal()
            if self._running:  # the one that started closest to ``wall`` ago
                began = self._clock() - wall
                ended = min(self._running, key=lambda grading: abs(grading[0] - began))
                self._running.remove(ended)
                cpu_seconds = ended[1]
            else:
                cpu_seconds = grown
            memory = result.memory
            self.tally = self.tally.add(wall=wall, cpu_seconds=cpu_seconds,
                                        footprint_mb=memory and memory.footprint_mb,
                                        strained=starved(result), at_once=at_once)
            choice = decide(self.tally, cores=self._cores(), memory_mb=self._memory_mb(),
                            students=max(1, students))
            if choice.jobs != self.jobs and self._report is not None:
                self._report(describe(choice))
            self.jobs = choice.jobs
            return choice.jobs


def auto_chooser(report: Callable[[str], None] | None = None) -> AutoChooser:
    """What ``run_batch`` calls as each grading ends: the concurrency for this machine
    and the gradings so far, told to ``report`` in one line whenever it changes."""
    return AutoChooser(report)
