"""The cost of one node start, as a grading pays it: a program started as a student's is
(forked from the zygote, or exec'd through the launcher) that creates an rclpy node, split
into

* process start + python: from the launch to the program's first line running;
* rclpy import: ``import rclpy`` and ``rclpy.node``;
* init + node: ``rclpy.init()`` and creating the node;
* discovery: from the node existing to the grader's node seeing it on the graph;
* CPU: the CPU seconds the program had used when its node was seen.

Medians (and min/max) over N starts, in wall seconds, for each way of starting; the
zygote's first start (which starts the zygote) is left out of its medians and printed
apart.  A machine's own figures, never asserted anywhere.

    python benchmarks/bench_startup.py [--runs 10] [--exercise timer_sync] [--launch both]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# The program under test prints the monotonic clock (the same in every process on Linux)
# after each stage; the grader reads it back from its output.
PROGRAM = """\
import time
print("main", time.monotonic(), flush=True)
import rclpy
from rclpy.node import Node
print("imported", time.monotonic(), flush=True)
rclpy.init()
node = Node("startup_probe")
print("created", time.monotonic(), flush=True)
try:
    rclpy.spin(node)
except BaseException:
    pass
"""

STAGES = ("process start + python", "rclpy import", "init + node", "discovery", "total",
          "CPU")


def one_start(graph: object, exercise: object, domain: int, folder: Path,
              strict: bool) -> list[float]:
    """Start the program once; the seconds of each stage (see :data:`STAGES`)."""
    from autograder.plugin.graph import node_endpoints
    from autograder.sandbox.process import student_process
    from sim.procstate import read_process_state

    script = folder / "startup_probe.py"
    stale = set(node_endpoints(graph, "startup_probe"))  # type: ignore[arg-type]
    process = student_process(script, [], exercise.limits,  # type: ignore[attr-defined]
                              domain=domain, strict=strict,
                              course=exercise.folder.parent.parent)  # type: ignore[attr-defined]
    launched = time.monotonic()
    process.start()
    try:
        while not set(node_endpoints(graph, "startup_probe")) - stale:  # type: ignore[arg-type]
            if not process.running() or time.monotonic() - launched > 30:
                raise RuntimeError(f"the node never appeared:\n{process.output_text()}")
            time.sleep(0.002)
        seen = time.monotonic()
        cpu = read_process_state(process.pid).cpu_ns / 1e9
        stamps: dict[str, float] = {}
        while len(stamps) < 3 and time.monotonic() - seen < 5:
            stamps = {line.split()[0]: float(line.split()[1])
                      for line in process.output_text().splitlines()
                      if line.split() and line.split()[0] in ("main", "imported", "created")}
            time.sleep(0.01)
    finally:
        process.stop()
    return [stamps["main"] - launched, stamps["imported"] - stamps["main"],
            stamps["created"] - stamps["imported"], max(0.0, seen - stamps["created"]),
            seen - launched, cpu]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--exercise", default="timer_sync", help="whose limits apply")
    parser.add_argument("--isolation", choices=("auto", "basic", "strict"), default="auto",
                        help="as a grading would run (auto: what the machine allows)")
    parser.add_argument("--launch", choices=("both", "zygote", "exec"), default="both",
                        help="fork from the zygote, exec through the launcher, or both")
    args = parser.parse_args()
    strict = _isolate(args.isolation)

    import rclpy
    from rclpy.context import Context
    from rclpy.node import Node

    from autograder.core.exercise import find_exercise
    from autograder.sandbox import process as process_module
    from autograder.sandbox.domains import reserve_domain
    from autograder.sandbox.isolation import Isolation, dds_env
    from sim.procstate import read_process_state

    exercise = find_exercise(args.exercise)
    for key, value in dds_env(Isolation("strict" if strict else "basic")).items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value
    ways = ("zygote", "exec") if args.launch == "both" else (args.launch,)
    runs: dict[str, list[list[float]]] = {way: [] for way in ways}
    with reserve_domain(None) as domain, tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "program"
        folder.mkdir()
        (folder / "startup_probe.py").write_text(PROGRAM)
        context = Context()
        rclpy.init(context=context, domain_id=domain)
        graph = Node("startup_grader", context=context)
        try:
            for way in ways:
                os.environ["AUTOGRADER_ZYGOTE"] = "1" if way == "zygote" else "0"
                for _ in range(args.runs + (way == "zygote")):
                    runs[way].append(one_start(graph, exercise, domain, folder, strict))
            zygote_cpu = sum(read_process_state(z.process.pid).cpu_ns / 1e9
                             for z in process_module._zygotes.values())
        finally:
            graph.destroy_node()
            rclpy.try_shutdown(context=context)
    print(f"one node start, {args.runs} runs each, {'strict' if strict else 'basic'} "
          "isolation (wall seconds; CPU seconds)")
    print(f"{'stage':<24} " + " ".join(f"{way + ' ' + k:>14}" for way in ways
                                       for k in ("median", "min", "max")))
    starts = {way: runs[way][1:] if way == "zygote" else runs[way] for way in ways}
    for i, stage in enumerate(STAGES):
        cells = []
        for way in ways:
            column = [run[i] for run in starts[way]]
            cells += [statistics.median(column), min(column), max(column)]
        print(f"{stage:<24} " + " ".join(f"{c:>14.3f}" for c in cells))
    if "zygote" in ways:
        first = runs["zygote"][0]
        print(f"the zygote's first start (the zygote starting too): total {first[4]:.3f} s, "
              f"CPU of the program {first[5]:.3f} s; the zygote's own CPU "
              f"{zygote_cpu:.3f} s (its imports, and its forks)")


def _isolate(wanted: str) -> bool:
    """Whether this run is strict; a strict one re-runs this script in a grading's own
    namespaces (as ``autograder.grading.run`` starts its child) and brings up ``lo``."""
    from autograder.sandbox.isolation import bring_up_loopback, detect, run_prefix

    if os.environ.get(INSIDE) == "1":
        bring_up_loopback()
        return True
    isolation = detect()
    if wanted == "basic" or not isolation.strict:
        if wanted == "strict":
            raise SystemExit(f"strict isolation is not available here: {isolation.to_dict()}")
        return False
    command = [*run_prefix(isolation), sys.executable, *sys.argv]
    raise SystemExit(subprocess.call(command, env={**os.environ, INSIDE: "1"}))


INSIDE = "AUTOGRADER_BENCH_STARTUP_INSIDE"


if __name__ == "__main__":
    main()
