"""ir-sim (headless): the room as rectangle and circle obstacles, a differential-drive
circle robot with a 360-beam ``lidar2d``, contacts resolved (``collision_mode: contact``).

ir-sim steps every sensor at every step and has no rate for one, so the lidar is taken
off the robot's sensor list and stepped only at the scan times, like the others.
"""

from __future__ import annotations

import contextlib
import io
import math
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from peers.scenario import BEAMS, DT, RANGE_MAX, SCAN_EVERY, Drive, Run, Scenario, timed
from sim.worldfile import ROBOT_RADIUS

NAME = "ir-sim (env.step, lidar2d)"
PACKAGE = "ir-sim"


def world_file(scenario: Scenario) -> dict:
    """The scenario as an ir-sim world document."""
    width, height = scenario.spec.size
    obstacles = [{"shape": {"name": "rectangle", "length": 2 * b.half_width,
                            "width": 2 * b.half_height},
                  "state": [b.x, b.y, b.yaw], "kinematics": None, "static": True}
                 for b in scenario.blocks]
    obstacles += [{"shape": {"name": "circle", "radius": r}, "state": [x, y, 0.0],
                   "kinematics": None, "static": True} for x, y, r in scenario.pillars]
    limits = scenario.spec.limits
    # 359/360 of a turn: ir-sim spaces beams over [-range/2, range/2] inclusive.
    span = 2 * math.pi * (BEAMS - 1) / BEAMS
    return {
        "world": {"height": height, "width": width, "step_time": DT, "sample_time": DT,
                  "collision_mode": "contact"},
        "robot": [{"kinematics": {"name": "diff"},
                   "shape": {"name": "circle", "radius": ROBOT_RADIUS},
                   "state": list(scenario.start),
                   "vel_max": [limits.max_linear_speed, limits.max_angular_speed],
                   "sensors": [{"name": "lidar2d", "range_min": 0.0, "range_max": RANGE_MAX,
                                "angle_range": span, "number": BEAMS}]}],
        "obstacle": obstacles,
    }


def run(scenario: Scenario) -> Run:
    with contextlib.redirect_stdout(io.StringIO()):  # it prints the GUI backends it tried
        import irsim

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "shared_scenario.yaml"
        path.write_text(yaml.safe_dump(world_file(scenario)), encoding="utf-8")
        env = irsim.make(str(path), display=False, headless=True, log_level="WARNING")
    robot = env.robot
    lidar, robot.sensors = robot.sensors[0], []
    drive = Drive(scenario)
    perf = time.perf_counter
    action = np.zeros((2, 1))
    result = Run(angles=np.asarray(lidar.angle_list, dtype=float))
    with timed(result):
        for i in range(scenario.steps):
            action[0, 0], action[1, 0] = drive.step(i)
            env.step(action)
            if (i + 1) % SCAN_EVERY == 0:
                began = perf()
                state = robot.state
                lidar.step(state[0:3])
                ranges = np.where(lidar.valid, lidar.range_data, np.inf)
                result.scan_seconds.append(perf() - began)
                result.record((float(state[0, 0]), float(state[1, 0]), float(state[2, 0])),
                              ranges)
    env.end(0)
    return result
