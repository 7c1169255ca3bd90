"""Wheel odometry in the odom frame (REP 105): it starts at (0, 0, 0), follows the robot
while it rolls, drifts where the body slips; ground truth stays in the recording."""

from __future__ import annotations

import dataclasses
import math

import pytest

from sim.engine import Simulation
from sim.odometry import WheelOdometry, to_odom, to_world
from sim.physics import World
from sim.recorder import Sample
from sim.worldfile import Pose, load_world


def _run(sim: Simulation, v: float, w: float, seconds: float) -> list[tuple[Sample, Sample]]:
    """Drive for ``seconds``; the (ground truth, wheel odometry) pairs that fell due."""
    sim.world.set_command(v, w)
    pairs = []
    for _ in range(round(seconds / sim.world.dt)):
        out = sim.step()
        if out.odom is not None:
            assert out.wheel_odom is not None and out.wheel_odom.t == out.odom.t
            pairs.append((out.odom, out.wheel_odom))
    return pairs


def _simulation(name: str = "obstacle_course", **changes: object) -> Simulation:
    return Simulation(World(dataclasses.replace(load_world(name), **changes)))


def test_odom_starts_at_the_origin_where_the_robot_starts() -> None:
    sim = _simulation(start=Pose(0.8, 0.8, 0.6))
    truth, wheel = _run(sim, 0.0, 0.0, 0.1)[0]
    assert (wheel.x, wheel.y, wheel.theta) == (0.0, 0.0, 0.0)
    assert (truth.x, truth.y, truth.theta) == pytest.approx((0.8, 0.8, 0.6))


def test_odom_follows_a_robot_rolling_freely() -> None:
    spec_start = Pose(3.0, 3.0, 0.6)
    sim = _simulation("open_room", start=spec_start)
    pairs = _run(sim, 0.4, 0.0, 3.0) + _run(sim, 0.3, 0.8, 2.0) + _run(sim, 0.0, 0.0, 1.0)
    truth, wheel = pairs[-1]
    assert not sim.recording.collisions
    assert math.dist((truth.x, truth.y), (spec_start.x, spec_start.y)) > 1.5
    assert to_world(spec_start, wheel.x, wheel.y) == pytest.approx((truth.x, truth.y),
                                                                   abs=0.005)
    heading = math.remainder(wheel.theta + spec_start.theta - truth.theta, math.tau)
    assert abs(heading) < 0.005


def test_its_twist_is_the_wheel_speeds_after_acceleration_limits() -> None:
    sim = _simulation()
    pairs = _run(sim, 0.5, 1.0, 0.02)  # one sample: 4 steps of 5 ms
    _truth, wheel = pairs[0]
    assert (wheel.v, wheel.w) == sim.world.command
    assert wheel.v == pytest.approx(2.5 * 0.02) and wheel.w == pytest.approx(6.0 * 0.02)


def test_a_pinned_robot_turns_its_wheels_and_odom_drifts() -> None:
    sim = _simulation("wall_ahead")  # the wall's face 1.0 m ahead
    truth, wheel = _run(sim, 0.3, 0.0, 8.0)[-1]
    assert sim.recording.collisions
    assert truth.x == pytest.approx(4.0 - 0.105, abs=0.01)  # held at the wall
    assert abs(truth.v) < 0.01  # the body stands still
    assert wheel.v == pytest.approx(0.3)  # its wheels do not
    assert wheel.x > 2.0  # odom believes it went on: 0.3 m/s for 8 s, less the start
    assert wheel.x - (truth.x - 3.0) > 1.0


def test_reset_puts_odom_back_at_the_origin() -> None:
    sim = _simulation()
    _run(sim, 0.4, 0.5, 1.0)
    sim.reset()
    _truth, wheel = _run(sim, 0.0, 0.0, 0.02)[0]
    assert (wheel.x, wheel.y, wheel.theta, wheel.v, wheel.w) == (0.0, 0.0, 0.0, 0.0, 0.0)


def test_the_recording_keeps_ground_truth_in_the_world_frame() -> None:
    sim = _simulation("open_room")
    _run(sim, 0.3, 0.0, 1.0)
    samples, _ = sim.recording.snapshot()
    assert samples[0].x == pytest.approx(3.0, abs=0.01) and samples[0].y == pytest.approx(3.0)
    assert samples[-1].x == pytest.approx(3.0 + 0.3 * 1.0 - 0.3 ** 2 / (2 * 2.5), abs=0.01)


def test_world_and_odom_frames_convert_both_ways() -> None:
    start = Pose(0.8, 0.8, math.pi / 2)
    assert to_odom(start, 0.8, 1.8) == pytest.approx((1.0, 0.0))  # 1 m straight ahead
    assert to_odom(start, -0.2, 0.8) == pytest.approx((0.0, 1.0))  # 1 m to its left
    for x, y in ((5.2, 5.0), (0.0, 0.0), (3.3, -1.0)):
        assert to_world(start, *to_odom(start, x, y)) == pytest.approx((x, y))
    open_room = load_world("open_room")
    assert to_odom(open_room.start, open_room.goal.x, open_room.goal.y) == pytest.approx(
        (-1.5, 1.8))


def test_integration_of_an_arc() -> None:
    odom = WheelOdometry()
    for _ in range(1000):  # a quarter turn of radius 1 m in 1000 steps
        odom.step(math.pi / 2, math.pi / 2, 0.001)
    assert odom.pose == pytest.approx((1.0, 1.0, math.pi / 2), abs=1e-6)


def _per_step(commands: list[tuple[float, float]], dt: float) -> tuple[float, float, float]:
    """The integration as it was, step by step (second-order Runge-Kutta)."""
    x = y = theta = 0.0
    for v, w in commands:
        heading = theta + w * dt / 2
        x += v * dt * math.cos(heading)
        y += v * dt * math.sin(heading)
        theta += w * dt
    return x, y, math.atan2(math.sin(theta), math.cos(theta))


def _drive() -> list[tuple[float, float]]:
    """Ramps (a new velocity every step), long arcs, straight runs, turns on the spot."""
    steps: list[tuple[float, float]] = [(0.01 * i, -0.02 * i) for i in range(40)]
    steps += [(0.4, 0.7)] * 3000 + [(0.22, 0.0)] * 1500 + [(0.0, -1.3)] * 700
    steps += [(-0.3, 2.8)] * 12000 + [(0.5, 1e-9)] * 400
    steps += [(0.4 - 0.01 * i, 0.3) for i in range(40)]
    return steps


def test_runs_in_closed_form_equal_the_step_by_step_integration() -> None:
    odom = WheelOdometry()
    for v, w in _drive():
        odom.step(v, w, 0.005)
    assert odom.pose == pytest.approx(_per_step(_drive(), 0.005), rel=1e-9, abs=1e-9)


def test_the_pose_does_not_depend_on_how_the_steps_came_nor_when_it_was_read() -> None:
    one_by_one, in_runs = WheelOdometry(), WheelOdometry()
    for v, w in _drive():
        one_by_one.step(v, w, 0.005)
        _ = one_by_one.pose
    commands = _drive()
    i = 0
    while i < len(commands):
        j = i
        while j < len(commands) and commands[j] == commands[i] and j - i < 7:
            j += 1
        in_runs.run(*commands[i], 0.005, j - i)
        i = j
    assert in_runs.pose == one_by_one.pose  # bit for bit


def test_the_simulation_odometry_equals_the_step_by_step_integration() -> None:
    """The simulation hands the odometry runs of steps; every /odom sample is still the
    step-by-step pose, and its velocities the ones driven in the last step."""
    sim = Simulation(World(load_world("obstacles")))
    x = y = theta = 0.0
    dt = sim.world.dt
    samples = 0
    for i in range(3000):
        if i % 600 == 0:
            sim.world.set_command(0.3 + i / 10000, math.sin(i / 300))
        out = sim.step()
        v, w = sim.world.command
        heading = theta + w * dt / 2
        x, y, theta = x + v * dt * math.cos(heading), y + v * dt * math.sin(heading), theta + w * dt
        expected = (x, y, math.atan2(math.sin(theta), math.cos(theta)))
        if out.wheel_odom is not None:
            samples += 1
            wheel = out.wheel_odom
            assert (wheel.x, wheel.y, wheel.theta) == pytest.approx(expected, rel=1e-9, abs=1e-9)
            assert (wheel.v, wheel.w) == (v, w)
        if i % 7 == 0:  # read between samples too: up to date with the last step
            assert sim.odometry.pose == pytest.approx(expected, rel=1e-9, abs=1e-9)
    assert samples == 750
