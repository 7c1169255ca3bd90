"""Real-time factor of the standard world (``obstacles``): physics + lidar alone, then
with the ROS bridge publishing as fast as it can (RTF 0, no watched process).

Measured on a 2-core AMD EPYC shared with other work (2026-11, Python 3.11, pymunk 7.3,
NumPy 2.4): physics + lidar 917x real time (median of 5 runs, 877 to 953 over runs), a
scan 25 us; before the ray cast was rewritten, 339x and 110 us in the same hour.  With
the ROS bridge, 36x (the clock cap bounds it).  Later, on a busier machine, trimming the
step (odometry in closed form, Chipmunk's step called directly) took physics + lidar from
654x to 755x (medians of 3, same hour), the scan 40 us with its noise.
``benchmarks/bench_peers.py`` runs the same loop beside MuJoCo, PyBullet and ir-sim.

Run: ``python benchmarks/bench_sim.py [--sim-seconds 60] [--runs 5] [--domain 99]``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

from sim.engine import Simulation
from sim.lidar import Lidar
from sim.pacing import DEFAULT_CLOCK_HZ
from sim.physics import World
from sim.worldfile import load_world


def bench_headless(sim_seconds: float) -> float:
    """Sim seconds per wall second stepping physics, lidar and faults with no ROS."""
    sim = Simulation(World(load_world("obstacles")))
    steps = round(sim_seconds / sim.world.dt)
    start = time.perf_counter()
    for i in range(steps):
        if i % 200 == 0:  # a new command every second: wander in arcs
            sim.world.set_command(0.4, math.sin(i / 200))
        sim.step()
    return sim_seconds / (time.perf_counter() - start)


def bench_scan(scans: int = 2000) -> float:
    """Seconds per 360-beam scan of the standard world, from its start pose."""
    world, lidar = World(load_world("obstacles")), Lidar()
    lidar.scan(world)  # the geometry is prepared once, before timing
    start = time.perf_counter()
    for _ in range(scans):
        lidar.scan(world)
    return (time.perf_counter() - start) / scans


def bench_bridge(sim_seconds: float, domain: int) -> tuple[float, float]:
    """(overall, last-window) RTF with the bridge publishing /clock, /odom and /scan."""
    import rclpy
    from rclpy.context import Context

    from sim.bridge import SimBridge

    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    ctx = Context()
    rclpy.init(context=ctx, domain_id=domain)
    bridge = SimBridge(World(load_world("obstacles")), ctx, real_time_factor=0.0)
    bridge.world.set_command(0.4, 0.3)
    start = time.perf_counter()
    bridge.start()
    try:
        bridge.wait_until(sim_seconds, wall_timeout=600)
        overall = bridge.now / (time.perf_counter() - start)
        window = bridge.effective_rtf
    finally:
        bridge.stop()
        rclpy.try_shutdown(context=ctx)
    return overall, window


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sim-seconds", type=float, default=60.0)
    parser.add_argument("--domain", type=int, default=99)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    bench_headless(2.0)  # warm-up: imports, first-call caches
    rtfs = [bench_headless(args.sim_seconds) for _ in range(args.runs)]
    print(f"physics + lidar, no ROS: RTF {statistics.median(rtfs):.0f}x median, "
          f"{max(rtfs):.0f}x best of {args.runs}")
    scan = statistics.median(bench_scan() for _ in range(args.runs))
    print(f"one 360-beam scan: {scan * 1e6:.1f} us (median of {args.runs})")
    overall, window = bench_bridge(args.sim_seconds, args.domain)
    print(f"with ROS bridge (RTF 0, {DEFAULT_CLOCK_HZ:g} Hz clock cap): RTF {overall:.1f}x "
          f"overall, {window:.1f}x at the end")


if __name__ == "__main__":
    main()
