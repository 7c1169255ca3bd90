"""Grading speed: wall time to grade each exercise's reference solution, the time from
the student's process start to its node being seen on the graph, and how the world's
ticks went on (student idle, CPU share used, wall cap hit: see sim/bridge.py); then where
the seconds went (the results file's ``timing``, summed over test modules, median over
the runs) and the peak memory of a grading (``memory``, the largest over the runs): the
children's resident sizes summed, an upper bound, and the footprint, the whole grading's
PSS summed (see autograder/grading/footprint.py).

Then the floor: the simulation seconds the tests took to their verdicts (setup and call;
time stands still while a node starts), summed, over the exercise's real-time factor: the
least wall time the tests could take at the exercise's pace, one after another; "longest
module" is the same for the module that takes longest, the least with modules at once. The
ratio is the grading's median wall time over the floor (one after another).

It also prints the CPU seconds of a grading (the grader's and every program it started,
median) and what they make a floor for a class: a batch cannot grade 100 students of
every exercise listed in less than their CPU seconds over the machine's cores, however
many gradings run at once.

    python benchmarks/bench_grading.py [--runs 5] [--module-jobs auto] [EXERCISE ...]

``--module-jobs`` as for ``autograder grade``; with more than 1 the modules overlap, so
their seconds add up to more than the wall time and ``rest`` reads 0.
"""

from __future__ import annotations

import argparse
import collections
import functools
import statistics
import time
from collections.abc import Sequence

from autograder.core.exercise import find_exercise, list_exercises
from autograder.core.results import MemoryUse, RunTiming
from autograder.grading.capacity import machine_cores, measured
from autograder.grading.footprint import INTERVAL
from autograder.grading.run import grade


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--module-jobs", default="auto",
                        type=lambda v: v if v == "auto" else int(v))
    parser.add_argument("exercises", nargs="*")
    args = parser.parse_args()
    exercises = [find_exercise(e) for e in args.exercises] or list_exercises()
    print(f"{'exercise':<22} {'score':>7} {'wall median':>12} {'min':>7} {'max':>7} "
          f"{'cpu median':>11} {'node seen after (median)':>25}  ticks idle/cpu share/cap")
    timings: dict[str, list[RunTiming]] = {}
    memory: dict[str, list[MemoryUse]] = {}
    cpu_medians: dict[str, float] = {}
    floors: dict[str, tuple[float, float, float, float]] = {}
    for exercise in exercises:
        walls, cpus, startups, scores = [], [], [], set()
        ticks: collections.Counter[str] = collections.Counter()
        for _ in range(args.runs):
            began = time.monotonic()
            result, share = measured(functools.partial(grade, exercise, None,
                                                       module_jobs=args.module_jobs))
            walls.append(time.monotonic() - began)
            cpus.append(share * walls[-1])
            startups += list(result.startup_seconds)
            scores.add(f"{result.score}/{result.max_score}")
            if result.timing is not None:
                timings.setdefault(exercise.id, []).append(result.timing)
            if result.memory is not None:
                memory.setdefault(exercise.id, []).append(result.memory)
            for module in result.pacing.values():
                ticks.update({k: module.count(k) for k in ("idle", "budget", "cap")})
        startup = f"{statistics.median(startups):.2f} s" if startups else "-"
        cpu_medians[exercise.id] = statistics.median(cpus)
        floors[exercise.id] = _floor(timings[exercise.id], exercise.real_time_factor,
                                     statistics.median(walls))
        print(f"{exercise.id:<22} {','.join(sorted(scores)):>7} "
              f"{statistics.median(walls):>10.2f} s {min(walls):>6.2f} {max(walls):>6.2f} "
              f"{cpu_medians[exercise.id]:>9.1f} s "
              f"{startup:>25}  {ticks['idle']}/{ticks['budget']}/{ticks['cap']}", flush=True)
    # Imported only after the gradings: the plugin's package brings rclpy and pytest into
    # this process, about 20 MB more of this process's PSS in each grading's footprint.
    from autograder.plugin.timing import PHASES

    print("\nthe floor (median over runs): sim seconds to the verdicts over the real-time "
          "factor")
    print(f"{'exercise':<22} {'sim s':>8} {'floor s':>9} {'longest module s':>17} "
          f"{'wall/floor':>11}")
    for name, (sim, floor, longest, ratio) in floors.items():
        print(f"{name:<22} {sim:>8.1f} {floor:>9.2f} {longest:>17.2f} {ratio:>11.2f}")
    columns = ("child_start", *PHASES, "checks", "rest", "total")
    print("\nwhere the seconds went (median over runs, summed over test modules; rest: "
          "the grader's own work outside the tests)")
    print(f"{'exercise':<22}" + "".join(f"{c:>12}" for c in columns))
    for name, runs in timings.items():
        rows = [_phases(timing, PHASES) for timing in runs]
        print(f"{name:<22}" + "".join(
            f"{statistics.median(r[c] for r in rows):>12.2f}" for c in columns))
    cores, cpu = machine_cores(), sum(cpu_medians.values())
    print(f"\nCPU of one student's gradings: {cpu:.1f} s; 100 students need at least "
          f"{100 * cpu / cores / 60:.0f} min on {cores:g} cores, however many at once")
    print("\npeak memory of a grading, MB (largest over runs). Resident sizes summed over "
          "the children at once, an upper bound (grader: pytest, world and probe in one "
          "process; student: its largest process);\nfootprint: the PSS of the grading's "
          f"whole process tree (this process included) summed, sampled every {INTERVAL:g} s")
    print(f"{'exercise':<22} {'grader':>8} {'student':>8} {'total':>8} {'footprint':>10}")
    for name, runs in memory.items():
        peak = max(runs, key=lambda m: m.total_mb or 0.0)
        footprints = [m.footprint_mb for m in runs if m.footprint_mb is not None]
        footprint = f"{max(footprints):>10.1f}" if footprints else f"{'-':>10}"
        print(f"{name:<22} {peak.grader_mb or 0.0:>8.1f} "
              f"{peak.student_mb or 0.0:>8.1f} {peak.total_mb or 0.0:>8.1f} "
              f"{footprint}")


def _floor(timings: Sequence[RunTiming], rtf: float,
           wall: float) -> tuple[float, float, float, float]:
    """(sim seconds summed, floor, longest module's floor, wall over floor), medians over
    the runs' ``timing``; floors are 0 for an exercise without a pace (``rtf`` 0)."""
    sums, longest = [], []
    for timing in timings:
        by_module: collections.Counter[str] = collections.Counter()
        for nodeid, seconds in timing.sim_seconds.items():
            by_module[nodeid.partition("::")[0]] += seconds
        sums.append(sum(by_module.values()))
        longest.append(max(by_module.values(), default=0.0))
    sim, most = statistics.median(sums), statistics.median(longest)
    floor = sim / rtf if rtf > 0 else 0.0
    return sim, floor, most / rtf if rtf > 0 else 0.0, wall / floor if floor else 0.0


def _phases(timing: RunTiming, phases: Sequence[str]) -> dict[str, float]:
    """One grading's seconds per column: ``child_start``, each of ``phases``, ``checks``,
    ``rest`` and ``total``."""
    modules = timing.modules.values()
    row = {p: sum(m[p] for m in modules) for p in (*phases, "checks")}
    row["child_start"] = timing.child_start or 0.0
    row["total"] = timing.total
    row["rest"] = max(0.0, row["total"] - row["child_start"] - timing.tests)
    return row


if __name__ == "__main__":
    main()
