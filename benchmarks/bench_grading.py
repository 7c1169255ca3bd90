"""Grading speed: wall time to grade each exercise's reference solution, the time from
the student's process start to its node being seen on the graph, and how the world's
ticks went on (student idle, CPU share used, wall cap hit: see sim/bridge.py).

    python benchmarks/bench_grading.py [--runs 5] [EXERCISE ...]
"""

from __future__ import annotations

import argparse
import collections
import statistics
import time

from autograder.core.exercise import find_exercise, list_exercises
from autograder.grading.run import grade


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("exercises", nargs="*")
    args = parser.parse_args()
    exercises = [find_exercise(e) for e in args.exercises] or list_exercises()
    print(f"{'exercise':<22} {'score':>7} {'wall median':>12} {'min':>7} {'max':>7} "
          f"{'node seen after (median)':>25}  ticks idle/cpu share/cap")
    for exercise in exercises:
        walls, startups, scores = [], [], set()
        ticks: collections.Counter[str] = collections.Counter()
        for _ in range(args.runs):
            began = time.monotonic()
            result = grade(exercise, None)
            walls.append(time.monotonic() - began)
            startups += result.data.get("startup_seconds", [])
            scores.add(f"{result.score}/{result.max_score}")
            for module in result.data.get("pacing", {}).values():
                ticks.update({k: v for k, v in module.items() if k in ("idle", "budget", "cap")})
        startup = f"{statistics.median(startups):.2f} s" if startups else "-"
        print(f"{exercise.id:<22} {','.join(sorted(scores)):>7} "
              f"{statistics.median(walls):>10.2f} s {min(walls):>6.2f} {max(walls):>6.2f} "
              f"{startup:>25}  {ticks['idle']}/{ticks['budget']}/{ticks['cap']}", flush=True)


if __name__ == "__main__":
    main()
