"""Repeatability: grade each reference solution N times, with and without CPU load beside
it, and print the distinct scores seen (must be one) and the spread of grading times.

    python benchmarks/repeatability.py [--runs 5] [--load-procs 2] [EXERCISE ...]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

from autograder.core.exercise import find_exercise, list_exercises
from autograder.grading.run import grade


def busy_loops(count: int) -> list[subprocess.Popen[bytes]]:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--load-procs", type=int, default=os.cpu_count() or 2,
                        help="busy loops beside the gradings under load (default: one a core)")
    parser.add_argument("exercises", nargs="*")
    args = parser.parse_args()
    exercises = [find_exercise(e) for e in args.exercises] or list_exercises()
    print(f"{'exercise':<22} {'load':<10} {'runs':>4} {'distinct scores':<18} "
          f"{'wall min':>8} {'median':>7} {'max':>7}")
    for exercise in exercises:
        for load in (0, args.load_procs):
            hogs = busy_loops(load)
            try:
                scores, walls = [], []
                for _ in range(args.runs):
                    began = time.monotonic()
                    result = grade(exercise, None)
                    walls.append(time.monotonic() - began)
                    scores.append(f"{result.score}/{result.max_score}"
                                  + (" (grader error)" if result.grader_error else ""))
            finally:
                for hog in hogs:
                    hog.kill()
                    hog.wait()
            label = f"{load} busy" if load else "idle"
            print(f"{exercise.id:<22} {label:<10} {args.runs:>4} "
                  f"{', '.join(sorted(set(scores))):<18} {min(walls):>7.1f}s "
                  f"{statistics.median(walls):>6.1f}s {max(walls):>6.1f}s", flush=True)


if __name__ == "__main__":
    main()
