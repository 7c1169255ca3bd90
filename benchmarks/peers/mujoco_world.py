"""MuJoCo: a planar robot (slide x, slide y, hinge yaw) driven by velocity actuators of
limited force, boxes and cylinders for the room, ``mj_multiRay`` for the 360 beams."""

from __future__ import annotations

import math
import time

import numpy as np

from peers.scenario import (
    BEAMS,
    DT,
    HEIGHT,
    RANGE_MAX,
    ROBOT_HEIGHT,
    SCAN_EVERY,
    Drive,
    Run,
    Scenario,
    beam_angles,
    timed,
)
from sim.physics import ROBOT_MASS
from sim.worldfile import ROBOT_RADIUS

NAME = "MuJoCo (mj_step, mj_multiRay)"
PACKAGE = "mujoco"


def mjcf(scenario: Scenario) -> str:
    """The scenario as an MJCF document."""
    h = HEIGHT / 2
    geoms = [f'<geom type="box" pos="{b.x} {b.y} {h}" size="{b.half_width} {b.half_height} '
             f'{h}" euler="0 0 {b.yaw}"/>' for b in scenario.blocks]
    geoms += [f'<geom type="cylinder" pos="{x} {y} {h}" size="{r} {h}"/>'
              for x, y, r in scenario.pillars]
    return f"""
<mujoco model="shared_scenario">
  <compiler angle="radian"/>
  <option timestep="{DT}" gravity="0 0 0" integrator="implicitfast"/>
  <worldbody>
    {"".join(geoms)}
    <body name="robot" pos="0 0 {ROBOT_HEIGHT / 2}">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="y" type="slide" axis="0 1 0"/>
      <joint name="yaw" type="hinge" axis="0 0 1"/>
      <geom type="cylinder" size="{ROBOT_RADIUS} {ROBOT_HEIGHT / 2}" mass="{ROBOT_MASS}"
            friction="0.3"/>
    </body>
  </worldbody>
  <actuator>
    <velocity joint="x" kv="200" forcelimited="true" forcerange="-40 40"/>
    <velocity joint="y" kv="200" forcelimited="true" forcerange="-40 40"/>
    <velocity joint="yaw" kv="20" forcelimited="true" forcerange="-2 2"/>
  </actuator>
</mujoco>
"""


def run(scenario: Scenario) -> Run:
    import mujoco

    model = mujoco.MjModel.from_xml_string(mjcf(scenario))
    data = mujoco.MjData(model)
    data.qpos[:] = scenario.start
    mujoco.mj_forward(model, data)
    robot = model.body("robot").id
    angles = beam_angles()
    vec = np.zeros((BEAMS, 3))
    geomid = np.zeros(BEAMS, dtype=np.int32)
    dist = np.zeros(BEAMS)
    point = np.zeros(3)
    point[2] = ROBOT_HEIGHT / 2
    qpos, ctrl = data.qpos, data.ctrl
    drive = Drive(scenario)
    step, multi_ray, perf = mujoco.mj_step, mujoco.mj_multiRay, time.perf_counter
    result = Run()
    with timed(result):
        for i in range(scenario.steps):
            v, w = drive.step(i)
            theta = qpos[2]
            ctrl[0], ctrl[1], ctrl[2] = v * math.cos(theta), v * math.sin(theta), w
            step(model, data)
            if (i + 1) % SCAN_EVERY == 0:
                began = perf()
                x, y, theta = float(qpos[0]), float(qpos[1]), float(qpos[2])
                a = theta + angles
                vec[:, 0], vec[:, 1] = np.cos(a), np.sin(a)
                point[0], point[1] = x, y
                multi_ray(model, data, point, vec.reshape(-1), None, 1, robot, geomid, dist,
                          None, BEAMS, RANGE_MAX)
                ranges = np.where(dist < 0, np.inf, dist)
                result.scan_seconds.append(perf() - began)
                result.record((x, y, theta), ranges)
    return result
