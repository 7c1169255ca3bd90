"""Batch throughput: N copies of an exercise's reference graded by `grade-batch` at each
--jobs, in wall seconds and students per hour, and whether every score was full (the batch
must never change a verdict).  Heavy: run it under `flock /tmp/agheavy.lock`.

With ``auto``, the jobs column lists each concurrency chosen, in order (the batch chooses
again as gradings end), and each line auto printed follows the row.

"late cmds" sums the results' ``pacing.late_commands`` over the batch: commands a world
took in a later tick than the one they were sent in (ticks that went on without them; the
tests allow one tick), with the most sim seconds one was late.  Students whose score was
not full are named with their lost tests.

    python benchmarks/bench_batch.py [--students 8] [--jobs 1,2,4,8,auto] [--exercise EX ...]

For each ``--jobs`` it also prints the whole course: every exercise's batch one after
another, as an instructor grades a class (``--students 100 --jobs auto``: the issue's
class of 100).
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from autograder.core.exercise import Exercise, find_exercise, list_exercises

CHOSEN = re.compile(r"--jobs auto: (\d+) grading.*")


def run(exercise: Exercise, copies: int, jobs: str, workdir: Path) -> dict[str, str]:
    """One batch of ``copies`` references at ``jobs``: its row of the table."""
    folder = workdir / f"{exercise.id}-{jobs}"
    for i in range(copies):
        (folder / "submissions" / f"student{i:02d}").mkdir(parents=True)
        (folder / "submissions" / f"student{i:02d}" / exercise.file).write_bytes(
            exercise.solution.read_bytes())
    book = folder / "gradebook.csv"
    began = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", "autograder.cli", "grade-batch", exercise.id,
                           str(folder / "submissions"), "--jobs", jobs, "--csv", str(book),
                           "--out", str(folder / "out")], capture_output=True, text=True)
    wall = time.monotonic() - began
    with book.open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh)) if proc.returncode == 0 else []
    full = len(rows) == copies and all(r["score"] == r["max_score"] for r in rows)
    chosen = list(CHOSEN.finditer(proc.stderr))  # auto chooses again as gradings end
    late, latest, lost = _results(folder / "out")
    steps = "->".join(c[1] for c in chosen)
    return {"exercise": exercise.id, "jobs": jobs + (f" ({steps})" if chosen else ""),
            "wall s": f"{wall:.1f}", "s/student": f"{wall / copies:.1f}",
            "students/h": f"{3600 * copies / wall:.0f}",
            "all full": "yes" if full else f"NO ({proc.returncode})",
            "late cmds": f"{late} ({latest:.2f} s)" if late else "0",
            "said": "\n  ".join(c[0] for c in chosen), "lost": "; ".join(lost)}


def _results(out: Path) -> tuple[int, float, list[str]]:
    """From each student's results file: late commands summed, the latest, and who lost
    which tests."""
    late, latest, lost = 0, 0.0, []
    for path in sorted(out.glob("*/results.json")):
        data = json.loads(path.read_text(encoding="utf-8"))
        for module in data.get("pacing", {}).values():
            late += module.get("late_commands", 0)
            latest = max(latest, module.get("latest_command", 0.0))
        missed = [t["name"] for t in data.get("tests", [])
                  if t.get("score", 0) < t.get("max_score", 0)]
        if missed or data.get("grader_error"):
            lost.append(f"{path.parent.name}: {', '.join(missed) or data['grader_error']}")
    return late, latest, lost


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=8)
    parser.add_argument("--jobs", default="1,2,4,8,auto")
    parser.add_argument("--exercise", action="append", default=[])
    args = parser.parse_args()
    exercises = [find_exercise(e) for e in args.exercise] or list_exercises()
    columns = ["exercise", "jobs", "wall s", "s/student", "students/h", "all full",
               "late cmds"]
    print(" | ".join(columns), flush=True)
    course: dict[str, list[dict[str, str]]] = {}
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as tmp:
        for exercise in exercises:
            for jobs in args.jobs.split(","):
                row = run(exercise, args.students, jobs, Path(tmp))
                course.setdefault(jobs, []).append(row)
                print(" | ".join(row[c] for c in columns), flush=True)
                if row["said"]:
                    print(f"  {row['said']}", flush=True)
                if row["lost"]:
                    print(f"  lost: {row['lost']}", flush=True)
    for jobs, rows in course.items():
        wall = sum(float(r["wall s"]) for r in rows)
        full = all(r["all full"] == "yes" for r in rows)
        print(f"course at --jobs {jobs}: {len(rows)} exercises x {args.students} students in "
              f"{wall / 60:.1f} min ({wall:.0f} s), every score full: {'yes' if full else 'NO'}")


if __name__ == "__main__":
    main()
