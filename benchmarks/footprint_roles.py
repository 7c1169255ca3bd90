"""Where a grading's footprint goes: the PSS of its process tree at its peak, by what each
process is, for issue 36's "footprint <= 150 MB".

Each grading is ``autograder grade EXERCISE SOLUTION`` as a process of its own (the
reference solution), its tree sampled every 0.25 s (:func:`sim.procstate.descendants`,
each process's PSS as :mod:`autograder.grading.footprint` reads it); the sample with the
largest sum is the peak, and its processes are summed by role:

* ``grader``: the ``autograder grade`` process (the CLI, the children's supervision);
* ``template``: the process the child pytests are forked from (strict and user isolation,
  :mod:`autograder.grading.template`), what it holds that its children do not share;
* ``child pytest``: each test module's pytest with the world and the probe in it;
* ``zygote``: the warm interpreter students' programs are forked from (one per child);
* ``student``: the students' programs (forked from a zygote, or exec'd);
* ``other``: anything else in the tree at that moment (the isolation check's program).

    python benchmarks/footprint_roles.py [--runs 3] [--module-jobs auto] [EXERCISE ...]

A role's MB is the sum over its processes (the count in brackets). Runs on the machine as
it is: run it with nothing else running.
"""

from __future__ import annotations

import argparse
import collections
import statistics
import subprocess
import sys
import time
from pathlib import Path

from autograder.core.exercise import find_exercise, list_exercises
from autograder.grading.footprint import process_kb
from sim.procstate import descendants

REPO = Path(__file__).resolve().parents[1]
AUTOGRADER = Path(sys.executable).with_name("autograder")
ROLES = ("grader", "template", "child pytest", "zygote", "student", "other")
INTERVAL = 0.25


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(
            errors="replace")
    except OSError:
        return ""


def _parent(pid: int) -> int:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return 0
    return int(stat.rsplit(")", 1)[1].split()[1])


def role(command: str, parent_command: str) -> str:
    """What a process of a grading's tree is, from its command line and its parent's."""
    if "autograder.grading.template" in command:
        return "child pytest" if "autograder.grading.template" in parent_command else "template"
    if "-m pytest" in command:
        return "child pytest"  # exec'd (basic isolation)
    if "autograder.sandbox.contained.zygote" in command:
        return "student" if "autograder.sandbox.contained.zygote" in parent_command else "zygote"
    if "startup_check" in command or "autograder-check-" in command:
        return "other"
    return "student" if command.endswith(".py") or ".py " in command else "other"


def sample(root: int) -> tuple[int, collections.Counter[str], collections.Counter[str]]:
    """The tree of ``root`` now: its KB summed, KB by role, processes by role."""
    kb: collections.Counter[str] = collections.Counter()
    count: collections.Counter[str] = collections.Counter()
    for pid in [root, *descendants(root)]:
        name = "grader" if pid == root else role(_cmdline(pid), _cmdline(_parent(pid)))
        kb[name] += process_kb(pid)
        count[name] += 1
    return sum(kb.values()), kb, count


def peak(exercise_id: str, module_jobs: str) -> tuple[collections.Counter[str],
                                                      collections.Counter[str], str]:
    """One grading's peak sample (KB by role, processes by role) and its exit status."""
    solution = find_exercise(exercise_id).folder / "solution"
    proc = subprocess.Popen([str(AUTOGRADER), "grade", exercise_id, str(solution),
                             "--module-jobs", module_jobs],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=REPO)
    best: tuple[int, collections.Counter[str], collections.Counter[str]] = (
        0, collections.Counter(), collections.Counter())
    while proc.poll() is None:
        found = sample(proc.pid)
        if found[0] > best[0]:
            best = found
        time.sleep(INTERVAL)
    return best[1], best[2], f"exit {proc.returncode}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("exercises", nargs="*")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--module-jobs", default="auto")
    args = parser.parse_args()
    ids = args.exercises or [e.id for e in list_exercises()]
    print(f"peak PSS of a grading's tree by role, MB (median over {args.runs} runs; the "
          f"processes at the peak in brackets), --module-jobs {args.module_jobs}")
    print(f"{'exercise':<22}" + "".join(f"{r:>16}" for r in ROLES) + f"{'total':>9}")
    for exercise_id in ids:
        runs = [peak(exercise_id, args.module_jobs) for _ in range(args.runs)]
        cells = []
        for name in ROLES:
            mb = statistics.median(kb[name] / 1024 for kb, _count, _status in runs)
            processes = max(count[name] for _kb, count, _status in runs)
            cells.append(f"{mb:>10.1f} [{processes}]" if processes else f"{'-':>16}")
        total = statistics.median(sum(kb.values()) / 1024 for kb, _c, _s in runs)
        statuses = ",".join(sorted({status for _kb, _c, status in runs}))
        print(f"{exercise_id:<22}" + "".join(f"{c:>16}" for c in cells)
              + f"{total:>9.1f}  {statuses}", flush=True)


if __name__ == "__main__":
    main()
