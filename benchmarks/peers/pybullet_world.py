"""PyBullet (DIRECT, no GUI): boxes and cylinders for the room, a cylinder robot whose
base velocity is set every step, ``rayTestBatch`` for the 360 beams."""

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

NAME = "PyBullet (stepSimulation, rayTestBatch)"
PACKAGE = "pybullet"
_ROOM, _ROBOT = 1, 2
"""Collision groups: beams test the room only, never the robot they start in."""


def _build(p, client: int, scenario: Scenario) -> int:
    """The room and the robot in ``client``; returns the robot's body id."""
    h = HEIGHT / 2
    for b in scenario.blocks:
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[b.half_width, b.half_height, h],
                                       physicsClientId=client)
        body = p.createMultiBody(0, shape, basePosition=[b.x, b.y, h],
                                 baseOrientation=p.getQuaternionFromEuler([0, 0, b.yaw]),
                                 physicsClientId=client)
        p.setCollisionFilterGroupMask(body, -1, _ROOM, _ROOM | _ROBOT, physicsClientId=client)
    for x, y, r in scenario.pillars:
        shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=r, height=HEIGHT,
                                       physicsClientId=client)
        body = p.createMultiBody(0, shape, basePosition=[x, y, h], physicsClientId=client)
        p.setCollisionFilterGroupMask(body, -1, _ROOM, _ROOM | _ROBOT, physicsClientId=client)
    x, y, theta = scenario.start
    shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=ROBOT_RADIUS, height=ROBOT_HEIGHT,
                                   physicsClientId=client)
    robot = p.createMultiBody(ROBOT_MASS, shape, basePosition=[x, y, ROBOT_HEIGHT / 2],
                              baseOrientation=p.getQuaternionFromEuler([0, 0, theta]),
                              physicsClientId=client)
    p.setCollisionFilterGroupMask(robot, -1, _ROBOT, _ROOM, physicsClientId=client)
    p.changeDynamics(robot, -1, lateralFriction=0.3, physicsClientId=client)
    return robot


def run(scenario: Scenario) -> Run:
    import pybullet as p

    client = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, 0, physicsClientId=client)
        p.setTimeStep(DT, physicsClientId=client)
        robot = _build(p, client, scenario)
        angles = beam_angles()
        drive = Drive(scenario)
        step, perf = p.stepSimulation, time.perf_counter
        z = ROBOT_HEIGHT / 2
        result = Run()
        with timed(result):
            for i in range(scenario.steps):
                v, w = drive.step(i)
                (x, y, _), orientation = p.getBasePositionAndOrientation(robot, client)
                theta = p.getEulerFromQuaternion(orientation)[2]
                p.resetBaseVelocity(robot, [v * math.cos(theta), v * math.sin(theta), 0],
                                    [0, 0, w], physicsClientId=client)
                step(physicsClientId=client)
                if (i + 1) % SCAN_EVERY == 0:
                    began = perf()
                    (x, y, _), orientation = p.getBasePositionAndOrientation(robot, client)
                    theta = p.getEulerFromQuaternion(orientation)[2]
                    a = theta + angles
                    ends = np.stack([x + RANGE_MAX * np.cos(a), y + RANGE_MAX * np.sin(a),
                                     np.full(BEAMS, z)], axis=1)
                    hits = p.rayTestBatch([[x, y, z]] * BEAMS, ends.tolist(),
                                          collisionFilterMask=_ROOM, physicsClientId=client)
                    fraction = np.array([hit[2] if hit[0] >= 0 else np.inf for hit in hits])
                    result.scan_seconds.append(perf() - began)
                    result.record((x, y, theta), fraction * RANGE_MAX)
    finally:
        p.disconnect(client)
    return result
