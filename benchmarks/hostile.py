"""Grade each hostile submission and print: submission, score, message, wall time,
processes left behind (must be 0), grader unharmed (must be yes).

    python benchmarks/hostile.py [--jobs 2] [NAME ...]

"Unharmed" means: the grading ended with a result and no grader error, within the
exercise's time limit, and the course tree was not changed.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COURSE = ROOT / "tests" / "fixtures" / "mini_course"
CORPUS = ROOT / "tests" / "submissions" / "hostile"


def tree_digest(folder: Path) -> str:
    digest = hashlib.sha256()
    for path in sorted(folder.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            digest.update(str(path).encode() + path.read_bytes())
    return digest.hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("names", nargs="*")
    args = parser.parse_args()
    os.environ["AUTOGRADER_COURSE"] = str(COURSE)
    from autograder.core.exercise import find_exercise
    from autograder.grading.run import grade
    from autograder.sandbox.isolation import detect
    from autograder.sandbox.leftovers import leftovers

    exercise = find_exercise("shout")
    names = args.names or sorted(p.name for p in CORPUS.iterdir())
    before = tree_digest(COURSE)
    print(f"isolation: {detect().mode} {detect().reason}".rstrip())

    def run(name: str) -> tuple[str, object, float, list[int]]:
        began = time.monotonic()
        result = grade(exercise, CORPUS / name)
        return name, result, time.monotonic() - began, leftovers(result)

    print(f"{'submission':<24} {'score':>5} {'wall':>6} {'left':>4} {'unharmed':>8}  message")
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for name, result, wall, left in pool.map(run, names):
            failed = [t for t in result.tests if not t.passed]
            message = (failed[0].message if failed else "all tests passed").splitlines()[0]
            unharmed = result.grader_error is None and wall < exercise.time_limit
            print(f"{name:<24} {str(result.score) + '/' + str(result.max_score):>5} "
                  f"{wall:>5.1f}s {len(left):>4} {'yes' if unharmed else 'NO':>8}  "
                  f"{message[:90]}", flush=True)
    print("course tree unchanged:", "yes" if tree_digest(COURSE) == before else "NO")


if __name__ == "__main__":
    main()
