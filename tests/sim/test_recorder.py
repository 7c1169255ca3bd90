"""Recording to JSON, and what a replay needs. (The trajectory picture: tests/sim/test_svg.py.)"""

from __future__ import annotations

import json
import math
from dataclasses import astuple

import pytest
from recorded_runs import driven

from sim.engine import Simulation
from sim.physics import World
from sim.recorder import MAX_TRAJECTORY_ROWS, SCAN_BUDGET, Recording
from sim.worldfile import load_world


def test_recording_samples_every_odom_and_collisions() -> None:
    sim = driven("wall_ahead")
    data = json.loads(json.dumps(sim.recording.to_dict()))
    assert len(data["trajectory"]) == 800 // 4  # 50 Hz at dt 0.005
    assert data["trajectory"][0][0] == 0.02
    assert [c["what"] for c in data["collisions"]] == ["wall 4"]
    again = Recording.from_dict(data)
    for read, kept in zip(again.samples, sim.recording.samples, strict=True):
        # times to 1 ms, poses to 0.1 mm, velocities to 1 mm/s
        assert all(abs(a - b) <= 5e-4 for a, b in zip(astuple(read), astuple(kept),
                                                          strict=True))
    assert again.collisions == sim.recording.collisions
    assert again.to_dict() == data
    assert 0.85 < sim.recording.distance() < 0.9


# -- what a replay needs: commands and scans --------------------------------------------

def _drive(world: str, seconds: float) -> Simulation:
    """A run driven as a node would: a new command every 0.1 s of sim time."""
    sim = Simulation(World(load_world(world)))
    for i in range(round(seconds / sim.world.dt)):
        if i % 20 == 0:
            sim.set_command(0.3, 0.5 * math.sin(i / 400))
        sim.step()
    return sim


def test_commands_and_scans_are_recorded_at_their_sim_times() -> None:
    sim = Simulation(World(load_world("wall_ahead")))
    for command in [(0.5, 0.0), (0.5, 0.0), (0.2, 0.3)]:  # a repeat changes nothing
        sim.set_command(*command)
        for _ in range(100):
            sim.step()
    commands, scans = sim.recording.replay_snapshot()
    assert [(c.t, c.linear, c.angular) for c in commands] == [(0.0, 0.5, 0.0),
                                                              (1.0, 0.2, 0.3)]
    # /scan goes out at 10 Hz; the recording keeps one every 0.5 s of it.
    assert [s.t for s in scans] == pytest.approx([0.1, 0.6, 1.1])
    assert all(len(s.ranges) == 360 for s in scans)
    ahead = scans[0].ranges[0]  # beam 0 looks along the heading, at the wall
    assert 0.5 < ahead < 3.5
    assert sim.recording.scan_angle_increment == pytest.approx(2 * math.pi / 360)


def test_to_dict_writes_scans_rounded_with_null_for_no_reading_and_round_trips() -> None:
    recording = Recording(world="empty_room")
    recording.add_scan(0.1, [1.23456, math.inf, -math.inf, math.nan, 0.5])
    recording.add_command(0.05, 0.123456, -0.5)
    data = json.loads(json.dumps(recording.to_dict()))
    assert data["scans"] == [[0.1, [1.23, None, None, None, 0.5]]]
    assert data["commands"] == [[0.05, 0.123, -0.5]]
    assert data["scan"] == {"angle_min": 0.0, "angle_increment": pytest.approx(0.0174533)}
    again = Recording.from_dict(data)
    assert list(again.scans[0].ranges)[1] == math.inf
    assert again.to_dict() == data


@pytest.mark.parametrize("seconds", [30, 120, 600])
def test_to_dict_stays_within_its_budget_however_long_the_run(seconds: int) -> None:
    sim = _drive("obstacles", seconds)
    data = sim.recording.to_dict()
    size = len(json.dumps(data))
    assert size < 250_000, size  # measured: 205 KB at 30 s, 227 KB at 300 s
    assert len(json.dumps(data["scans"])) <= SCAN_BUDGET + 3000
    assert len(data["trajectory"]) <= MAX_TRAJECTORY_ROWS
    # Thinned evenly: the last sample is the run's end, scans span the whole run.
    assert data["trajectory"][-1][0] == pytest.approx(seconds)
    assert data["scans"][-1][0] > seconds - 1.5 and len(data["scans"]) >= 40


def test_a_recording_written_before_replays_reads_back_without_commands_or_scans() -> None:
    old = {"world": "empty_room", "fields": ["t", "x", "y", "theta", "v", "w"],
           "trajectory": [[0.02, 3.0, 3.0, 0.0, 0.0, 0.0]], "collisions": []}
    recording = Recording.from_dict(old)
    assert recording.samples and recording.commands == [] and recording.scans == []
