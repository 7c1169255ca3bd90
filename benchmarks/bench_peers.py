"""The world against its peers on one shared scenario, in one process, one after another.

The scenario (``benchmarks/peers/scenario.py``): the standard world's 6 x 6 m room with
three boxes and three pillars, 60 s of simulation at 200 Hz physics, the same open-loop
commands, a 360-beam scan every 0.1 s, every scan checked against the analytic geometry.
This world runs through ``Simulation.step`` (physics, lidar, faults and recording; no
ROS).  The peers are optional (``pip install -e '.[peers]'``): MuJoCo, PyBullet, ir-sim;
a missing one is listed as not installed.  Runs are interleaved (each simulator once per
round) so a machine that slows down or speeds up does so for all of them.

Printed per simulator: real-time factor (simulated over wall seconds, median and best of
the runs; and over CPU seconds of the process, which other load on the machine disturbs
less), the median time of one scan, the largest range error over all scans and the beams
more than 1 cm off, and each real-time factor as a ratio to this world's.

Run: ``python benchmarks/bench_peers.py [--runs 5] [--only ours,mujoco]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import importlib.metadata
import importlib.util
import os
import statistics
from types import ModuleType

from peers import scenario as shared

PEERS = {"ours": "peers.ours", "mujoco": "peers.mujoco_world",
         "pybullet": "peers.pybullet_world", "irsim": "peers.irsim_world"}
_IMPORT_NAMES = {"mujoco": "mujoco", "pybullet": "pybullet", "ir-sim": "irsim"}


def _installed(module: ModuleType) -> bool:
    package = module.PACKAGE
    return package is None or importlib.util.find_spec(_IMPORT_NAMES[package]) is not None


def _label(module: ModuleType) -> str:
    if module.PACKAGE is None:
        return module.NAME
    return f"{module.NAME} {importlib.metadata.version(module.PACKAGE)}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3, help="timed runs of each simulator")
    parser.add_argument("--only", default=",".join(PEERS),
                        help="comma-separated subset of " + ", ".join(PEERS))
    args = parser.parse_args()
    os.environ.setdefault("MPLBACKEND", "Agg")  # ir-sim imports matplotlib; no window
    scenario = shared.load()
    chosen = [importlib.import_module(PEERS[key]) for key in args.only.split(",")]
    present = [m for m in chosen if _installed(m)]
    missing = [m for m in chosen if not _installed(m)]

    warmup = dataclasses.replace(scenario, steps=round(2.0 / shared.DT))  # 2 s
    failed: dict[str, str] = {}
    for module in present:
        try:
            module.run(warmup)  # imports, first-call caches, allocator
        except Exception as error:  # a peer's API changed: report it, measure the rest
            failed[module.NAME] = f"{type(error).__name__}: {error}"
    present = [m for m in present if m.NAME not in failed]
    runs: dict[str, list[shared.Run]] = {m.NAME: [] for m in present}
    for _ in range(args.runs):
        for module in present:
            runs[module.NAME].append(module.run(scenario))

    sim_seconds = scenario.steps * shared.DT
    print(f"shared scenario: world '{shared.WORLD}', {sim_seconds:g} s at "
          f"{1 / shared.DT:g} Hz physics, {shared.BEAMS}-beam scan every "
          f"{shared.SCAN_EVERY * shared.DT:g} s; {args.runs} interleaved runs each")
    header = (f"{'simulator':<52} {'RTF wall med':>12} {'best':>6} {'RTF cpu med':>11} "
              f"{'scan us':>8} {'max error m':>11} {'beams >1cm':>10} {'wall ratio':>10} "
              f"{'cpu ratio':>9}")
    print(header)
    ours_wall = ours_cpu = None
    for module in present:
        done = runs[module.NAME]
        wall = statistics.median(sim_seconds / r.wall for r in done)
        best = max(sim_seconds / r.wall for r in done)
        cpu = statistics.median(sim_seconds / r.cpu for r in done)
        scan_us = statistics.median(s for r in done for s in r.scan_seconds) * 1e6
        check = shared.check(scenario, done[-1])
        if module.PACKAGE is None:
            ours_wall, ours_cpu = wall, cpu
        wall_ratio = f"{wall / ours_wall:.2f}" if ours_wall else "-"
        cpu_ratio = f"{cpu / ours_cpu:.2f}" if ours_cpu else "-"
        print(f"{_label(module):<52} {wall:>12.0f} {best:>6.0f} {cpu:>11.0f} {scan_us:>8.1f} "
              f"{check.max_error:>11.2g} {check.off:>10} {wall_ratio:>10} {cpu_ratio:>9}")
    for module in missing:
        print(f"{module.NAME:<52} not installed (pip install {module.PACKAGE})")
    for name, error in failed.items():
        print(f"{name:<52} failed: {error}")
    if ours_wall:
        print("ratio: a simulator's real-time factor over this world's (below 1: slower)")


if __name__ == "__main__":
    main()
