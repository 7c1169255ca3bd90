"""The cost of one look at a watched process, as the pacing takes it: the state and CPU
time of every thread, read from ``/proc``.

* fresh: :func:`sim.procstate.read_process_state`, which opens each thread's two files
  every time;
* held: :class:`sim.procstate.ProcessStateReader`, which keeps them open and rereads them.

A child python process with ``--threads`` idle threads stands in for a student's node (a
timer_sync node has about 21).  Median microseconds per look over ``--looks`` looks, wall
and CPU; a machine's own figures, never asserted anywhere.

    python benchmarks/bench_procstate.py [--threads 20] [--looks 2000]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from collections.abc import Callable

from sim.procstate import ProcessState, ProcessStateReader, read_process_state

CHILD = """
import sys, threading
gate = threading.Event()
for _ in range({threads}):
    threading.Thread(target=gate.wait, daemon=True).start()
print("ready", flush=True)
sys.stdin.read()
"""


def per_look(read: Callable[[int], ProcessState], pid: int, looks: int,
             rounds: int = 5) -> tuple[float, float]:
    """Median wall and CPU microseconds per look over ``rounds`` rounds."""
    walls, cpus = [], []
    for _ in range(rounds):
        wall, cpu = time.perf_counter(), time.process_time()
        for _ in range(looks):
            read(pid)
        walls.append((time.perf_counter() - wall) / looks * 1e6)
        cpus.append((time.process_time() - cpu) / looks * 1e6)
    return statistics.median(walls), statistics.median(cpus)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=20)
    parser.add_argument("--looks", type=int, default=2000)
    args = parser.parse_args()
    child = subprocess.Popen([sys.executable, "-c", CHILD.format(threads=args.threads)],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None and child.stdout.readline() == "ready\n"
        reader = ProcessStateReader()
        print(f"{args.threads + 1} threads, {args.looks} looks x 5 rounds, median per look")
        print(f"{'reader':<8} {'wall us':>8} {'cpu us':>8}")
        for name, read in (("fresh", read_process_state), ("held", reader)):
            wall, cpu = per_look(read, child.pid, args.looks)
            print(f"{name:<8} {wall:>8.0f} {cpu:>8.0f}")
        reader.close()
    finally:
        child.kill()
        child.wait()


if __name__ == "__main__":
    main()
