"""Driving from the keyboard: the key map as a pure function, and the terminal put back as
it was however the drive ends."""

from __future__ import annotations

import os
import pty
import termios

import pytest

from sim.keyboard import (
    ANGULAR_STEP,
    LINEAR_STEP,
    Command,
    NotATerminal,
    apply_key,
    raw_terminal,
    read_keys,
    split_keys,
)
from sim.worldfile import RobotLimits

UP, DOWN, RIGHT, LEFT = "\x1b[A", "\x1b[B", "\x1b[C", "\x1b[D"


@pytest.mark.parametrize(("keys", "expected"), [
    ("w", Command(LINEAR_STEP, 0.0)),
    (UP, Command(LINEAR_STEP, 0.0)),
    ("W", Command(LINEAR_STEP, 0.0)),
    ("x", Command(-LINEAR_STEP, 0.0)),
    (DOWN, Command(-LINEAR_STEP, 0.0)),
    ("a", Command(0.0, ANGULAR_STEP)),
    (LEFT, Command(0.0, ANGULAR_STEP)),
    ("d", Command(0.0, -ANGULAR_STEP)),
    (RIGHT, Command(0.0, -ANGULAR_STEP)),
    ("wwwa", Command(3 * LINEAR_STEP, ANGULAR_STEP)),
    ("wwas", Command()),
    ("ww ", Command()),
    ("w?z", Command(LINEAR_STEP, 0.0)),  # unknown keys change nothing
], ids=["w", "up", "shift-w", "x", "down", "a", "left", "d", "right", "combined", "s-stops",
        "space-stops", "unknown"])
def test_keys_change_the_command(keys: str, expected: Command) -> None:
    command = Command()
    for key in split_keys(keys):
        pressed = apply_key(command, key)
        assert pressed is not None
        command = pressed
    assert (command.linear, command.angular) == pytest.approx((expected.linear,
                                                                expected.angular))


@pytest.mark.parametrize("key", ["q", "Q", "\x03", "\x04"], ids=["q", "shift-q", "ctrl-c",
                                                                  "ctrl-d"])
def test_quit_keys(key: str) -> None:
    assert apply_key(Command(0.3, 0.2), key) is None


def test_speeds_stay_within_the_robots_limits() -> None:
    limits = RobotLimits(max_linear_speed=0.12, max_angular_speed=0.3)
    command = Command()
    for _ in range(10):
        command = apply_key(apply_key(command, "w", limits), "d", limits)
    assert command == Command(0.12, -0.3)
    for _ in range(20):
        command = apply_key(command, "x", limits)
    assert command.linear == -0.12


def test_arrow_keys_are_one_key_each_in_a_chunk_of_input() -> None:
    assert split_keys(f"w{UP}{LEFT}s q") == ["w", UP, LEFT, "s", " ", "q"]
    assert split_keys("\x1b") == ["\x1b"]  # a lone escape is not an arrow


def test_raw_terminal_reads_keys_and_restores_the_terminal() -> None:
    controller, terminal = pty.openpty()
    try:
        before = termios.tcgetattr(terminal)
        with raw_terminal(terminal):
            raw = termios.tcgetattr(terminal)
            assert not raw[3] & termios.ICANON and not raw[3] & termios.ECHO
            assert raw[3] & termios.ISIG  # Ctrl-C still interrupts
            os.write(controller, f"w{RIGHT}".encode())
            assert read_keys(terminal, 5.0) == ["w", RIGHT]
        assert termios.tcgetattr(terminal) == before
        with pytest.raises(RuntimeError), raw_terminal(terminal):
            raise RuntimeError("the drive failed")
        assert termios.tcgetattr(terminal) == before
    finally:
        os.close(controller)
        os.close(terminal)


def test_no_terminal_is_said_so() -> None:
    read_end, write_end = os.pipe()
    try:
        with pytest.raises(NotATerminal), raw_terminal(read_end):
            pass
    finally:
        os.close(read_end)
        os.close(write_end)
