"""``autograder sim run --node``: a student's node started with the world as grading starts
it. Simulation time starts only once the node is up, so two hand runs of one node in one
world give the same trajectory; Ctrl-C stops both and leaves nothing behind. (The hand
run's own parts: tests/commands/test_hand_run.py.)"""

from __future__ import annotations

import json
import os
import re
import selectors
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner
from pasted import as_a_terminal_starts_it

from autograder.cli import main

REPO = Path(__file__).resolve().parents[2]
NODES = REPO / "tests" / "fixtures" / "hand_node"
FIRST = re.compile(r"first command at ([\d.]+) s \(pid (\d+)\)")
WALL = 120.0  # generous wall-clock deadline for one hand run


def test_exercise_and_params_go_with_node() -> None:
    for option in (["--exercise", "timer_sync"], ["--param", "goal_x:=1.0"]):
        result = CliRunner().invoke(main, ["sim", "run", *option])
        assert result.exit_code == 2
        assert "--exercise and --param go with --node FILE" in result.output


def test_a_param_must_read_name_value() -> None:
    node = str(NODES / "steady_driver.py")
    result = CliRunner().invoke(main, ["sim", "run", "--node", node, "-p", "goal_x=1.0"])
    assert result.exit_code == 2
    assert "'goal_x=1.0' is not NAME:=VALUE" in result.output


def test_a_syntax_error_is_said_before_the_world_starts(tmp_path: Path) -> None:
    broken = tmp_path / "my_node.py"
    broken.write_text("import rclpy\n\ndef main(:\n    pass\n")
    result = CliRunner().invoke(main, ["sim", "run", "--node", str(broken)])
    assert result.exit_code == 2  # the student's bad input, as check and grade say it
    assert f'File "{broken}", line 3\n    def main(:\n' in result.output
    assert "World" not in result.output


def _command(domain: int, *args: str) -> list[str]:
    return [sys.executable, "-c", "from autograder.cli import main; main()", "sim", "run",
            "--domain", str(domain), *args]


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(
        filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}


def _hand_run(domain: int, record: Path) -> str:
    result = subprocess.run(_command(domain, "--node", str(NODES / "steady_driver.py"),
                                     "--duration", "2", "--record", str(record)),
                            env=_env(), capture_output=True, text=True, timeout=WALL)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


@pytest.mark.slow
def test_two_hand_runs_give_the_same_trajectory(ros_domain: int, tmp_path: Path) -> None:
    outputs = [_hand_run(ros_domain, tmp_path / f"run{i}.json") for i in (1, 2)]
    assert all("Node steady_driver is up; simulation time starts now." in out
               for out in outputs)
    # The node's own log reaches the terminal; its first command goes out on its first
    # 10 Hz tick of simulation time, not after however long its start-up took.
    firsts = [float(FIRST.search(out).group(1)) for out in outputs]
    assert firsts == [0.1, 0.1], outputs
    first, second = (json.loads((tmp_path / f"run{i}.json").read_text()) for i in (1, 2))
    assert first["trajectory"][-1][0] == pytest.approx(2.0)
    assert first["trajectory"][-1][1:3] != first["trajectory"][0][1:3]  # it moved
    assert first == second


def _read_until(stream, pattern: re.Pattern[str], wall: float) -> tuple[str, re.Match | None]:
    """What the stream said until a line matched ``pattern`` (or ``wall`` seconds passed)."""
    seen = ""
    deadline = time.monotonic() + wall
    with selectors.DefaultSelector() as selector:
        selector.register(stream, selectors.EVENT_READ)
        while time.monotonic() < deadline:
            if not selector.select(deadline - time.monotonic()):
                break
            line = stream.readline()
            if not line:
                break
            seen += line
            if found := pattern.search(line):
                return seen, found
    return seen, None


@pytest.mark.slow
def test_ctrl_c_stops_world_and_node_and_leaves_nothing(ros_domain: int) -> None:
    run = subprocess.Popen(_command(ros_domain, "--node", str(NODES / "steady_driver.py"),
                                    "--param", "speed:=0.2"),
                           env=_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, preexec_fn=as_a_terminal_starts_it)
    try:
        seen, found = _read_until(run.stdout, FIRST, WALL)
        assert found, seen
        assert "speed 0.2" in seen  # --param reached the node as -p speed:=0.2
        run.send_signal(signal.SIGINT)  # as Ctrl-C in its terminal
        rest, _ = run.communicate(timeout=WALL)
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
    assert run.returncode == 0, seen + rest
    assert "Sim time:" in rest  # the world's summary
    with pytest.raises(ProcessLookupError):
        os.kill(int(found.group(2)), 0)  # the node's process is gone


@pytest.mark.slow
def test_a_node_that_fails_at_start_is_said_so(ros_domain: int) -> None:
    result = subprocess.run(_command(ros_domain, "--node", str(NODES / "fails_at_start.py")),
                            env=_env(), capture_output=True, text=True, timeout=WALL)
    assert result.returncode == 1, result.stdout + result.stderr
    assert "RuntimeError: no node today" in result.stdout  # its output streamed as it came
    assert ("Your program exited with status 1 during start-up, before its node was up"
            in result.stderr)
