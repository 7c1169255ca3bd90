"""Where the CPU of a whole grading goes: every process and thread the grading started,
counted by ``perf`` (a sample every 4 ms of each thread's CPU time), summed by what it is.

Each grading runs in a process of its own under ``perf record`` (``autograder.grading.run.
grade`` on the reference solution). Its child pytests load ``benchmarks.threadnames``,
which names each Python thread after its ``threading`` name (the world's ``sim-physics``
and ``sim-executor``, the ``probe-executor``, ``graph-watch``...); Fast DDS names its own
(``dds.udp.PORT``, ``dds.ev.N``...). Processes are told apart by where they were forked
(perf's task events). The rows:

* ``grader``: the grading's own process (the CLI's part: children, reports, footprint);
* ``pytest child: THREAD``: the child pytests by thread: ``pytest-main`` is pytest itself,
  its imports, the tests' code and the fixtures' work (starting nodes, the world and
  probe); ``pytest child: dds.KIND`` Fast DDS's threads; ``python`` a thread started
  before the names were given;
* ``zygote``: the warm interpreter students are forked from (its imports, once a child);
* ``student: main`` / ``student: dds``: the students' programs, their Python (rclpy's
  executor included) and Fast DDS's threads;
* ``other``: the grader's other programs (the isolation check's test program).

    python benchmarks/cpu_breakdown.py [--runs 1] [--module-jobs auto] [EXERCISE ...]

Needs ``perf`` and leave to use it (root, or ``kernel.perf_event_paranoid`` <= 1).
"""

from __future__ import annotations

import argparse
import collections
import json
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from autograder.core.exercise import find_exercise, list_exercises

PERIOD_NS = 4_000_000  # one sample per 4 ms of a thread's CPU time
_PLUGIN = "-p benchmarks.threadnames"
_FORK = re.compile(r"PERF_RECORD_FORK\((\d+):(\d+)\):\((\d+):(\d+)\)")
_LINE = re.compile(r"^\s*(.*?)\s+(\d+)/(\d+)\s+(.*)$")
_DDS = re.compile(r"^dds\.([a-z]+)")


def _inner(exercise_id: str, module_jobs: str) -> None:
    """The grading itself, in the process ``perf`` watches: its score and wall as JSON."""
    import resource

    from autograder.grading import children
    from autograder.grading.forked import forked_cpu_seconds
    from autograder.grading.run import grade

    # The grader keeps the caller's pytest settings from its child pytests; this process
    # only measures, and gives them the plugin that names their threads.
    scrubbed = children.pytest_env
    children.pytest_env = lambda env: {**scrubbed(env), "PYTEST_ADDOPTS": _PLUGIN}
    began = time.monotonic()
    result = grade(find_exercise(exercise_id), None,
                   module_jobs=module_jobs if module_jobs == "auto" else int(module_jobs))
    own, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF,
                                                 resource.RUSAGE_CHILDREN))
    print(json.dumps({"score": f"{result.score}/{result.max_score}",
                      "wall": time.monotonic() - began,
                      # the child pytests forked from the template are its children,
                      # not this process's: counted as they end (grading.forked)
                      "cpu": own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime
                      + forked_cpu_seconds()}))


def classify(script: str) -> dict[str, float]:
    """CPU seconds by row (see the module's docstring) from ``perf script
    --show-task-events -F comm,pid,tid,event``'s text."""
    samples: collections.Counter[tuple[int, int]] = collections.Counter()
    names: dict[tuple[int, int], str] = {}
    parent: dict[int, int] = {}
    execed: set[int] = set()
    root = None
    for line in script.splitlines():
        fork = _FORK.search(line)
        if fork:
            pid, tid, ppid = int(fork[1]), int(fork[2]), int(fork[3])
            if pid == tid and pid != ppid:
                parent[pid] = ppid
            continue
        match = _LINE.match(line)
        if not match:
            continue
        comm, pid, tid, rest = match[1], int(match[2]), int(match[3]), match[4]
        if rest.startswith("PERF_RECORD_COMM exec"):
            execed.add(pid)
            root = pid if root is None else root
        names[(pid, tid)] = comm  # a thread's name as last seen
        if rest.startswith("task-clock"):
            samples[(pid, tid)] += 1
    pids = {p for p, _t in names}
    pytests = {pid for (pid, _tid), name in names.items() if name == "pytest-main"}
    # The zygote: exec'd by a child pytest, it forks programs that run without an exec
    # (a program exec'd the ordinary way forks only helpers that use no CPU to speak of).
    spent = collections.Counter()
    for (pid, _tid), count in samples.items():
        spent[pid] += count
    zygotes = {p for p in pids if parent.get(p) in pytests and p in execed and any(
        parent.get(c) == p and c not in execed and spent[c] >= 10 for c in pids)}
    kinds: dict[int, str] = {}
    for pid in pids:
        up, top = parent.get(pid), pid
        while parent.get(top) is not None and parent[top] not in pytests:
            top = parent[top]
        if pid == root:
            kinds[pid] = "grader"
        elif pid in pytests:
            kinds[pid] = "pytest child"
        elif pid in zygotes:
            kinds[pid] = "zygote"
        elif up is not None and parent.get(top) in pytests:
            kinds[pid] = "student"
        else:
            kinds[pid] = "other"  # the grader's other programs: the isolation check
    rows: collections.Counter[str] = collections.Counter()
    for (pid, tid), count in samples.items():
        kind, name = kinds.get(pid, "other"), names[(pid, tid)]
        dds = _DDS.match(name)
        if kind == "pytest child":
            row = f"{kind}: dds.{dds[1]}" if dds else f"{kind}: {name}"
        elif kind == "student":
            row = (f"{kind}: dds" if dds else f"{kind}: main" if pid == tid
                   else f"{kind}: other threads")
        else:
            row = kind
        rows[row] += count * PERIOD_NS / 1e9
    return dict(rows)


def measure(exercise_id: str, workdir: Path, module_jobs: str = "auto",
            ) -> tuple[dict[str, float], dict[str, float | str]]:
    """One grading under ``perf``: its rows and its score, wall and rusage CPU."""
    data = workdir / "perf.data"
    done = subprocess.run(["perf", "record", "-q", "-e", "task-clock", "-c", str(PERIOD_NS),
                           "-o", str(data), "--", sys.executable, __file__, "--inner",
                           exercise_id, "--module-jobs", module_jobs],
                          capture_output=True, text=True, check=True)
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    script = subprocess.run(["perf", "script", "-i", str(data), "--show-task-events",
                             "-F", "comm,pid,tid,event"], capture_output=True, text=True,
                            check=True).stdout
    return classify(script), summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1)
    parser.add_argument("--module-jobs", default="auto", help="as for `autograder grade`")
    parser.add_argument("--inner", help=argparse.SUPPRESS)
    parser.add_argument("exercises", nargs="*")
    args = parser.parse_args()
    if args.inner:
        _inner(args.inner, args.module_jobs)
        return
    exercises = [find_exercise(e).id for e in args.exercises] or [
        e.id for e in list_exercises()]
    table: dict[str, dict[str, list[float]]] = {}
    totals: dict[str, list[dict[str, float | str]]] = {}
    with tempfile.TemporaryDirectory(prefix="cpu-breakdown-") as tmp:
        for name in exercises:
            for _run in range(args.runs):
                rows, summary = measure(name, Path(tmp), args.module_jobs)
                for row, seconds in rows.items():
                    table.setdefault(row, {}).setdefault(name, []).append(seconds)
                summary["sampled"] = sum(rows.values())
                totals.setdefault(name, []).append(summary)
                print(f"{name}: {summary['score']} in {summary['wall']:.1f} s, cpu "
                      f"{summary['cpu']:.1f} s (perf: {summary['sampled']:.1f} s)", flush=True)
    print(f"\nCPU seconds by process and thread (median over {args.runs} run(s))")
    print(f"{'':<34}" + "".join(f"{n[:15]:>16}" for n in exercises) + f"{'all':>9}")
    order = sorted(table, key=lambda r: -sum(statistics.median(v) for v in
                                             table[r].values()))
    for row in order:
        cells = [statistics.median(table[row].get(n, [0.0])) for n in exercises]
        if sum(cells) >= 0.05:
            print(f"{row:<34}" + "".join(f"{c:>16.2f}" for c in cells) + f"{sum(cells):>9.2f}")
    for label, key in (("perf total", "sampled"), ("cpu (rusage)", "cpu"), ("wall", "wall")):
        cells = [statistics.median(float(t[key]) for t in totals[n]) for n in exercises]
        print(f"{label:<34}" + "".join(f"{c:>16.2f}" for c in cells) + f"{sum(cells):>9.2f}")


if __name__ == "__main__":
    main()
