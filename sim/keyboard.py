"""Driving from a terminal's keys: the key map as pure functions, and a raw terminal.

``w``/up arrow faster, ``x``/down arrow slower (or backwards), ``a``/left arrow turn
left, ``d``/right arrow turn right, ``s`` or space stop, ``q`` quit (Ctrl-C too), as in
ROS's ``teleop_twist_keyboard``.
"""

from __future__ import annotations

import contextlib
import os
import select
from collections.abc import Iterator
from dataclasses import dataclass

from sim.worldfile import RobotLimits

LINEAR_STEP = 0.05
"""m/s a key press changes the linear velocity by."""
ANGULAR_STEP = 0.2
"""rad/s a key press changes the angular velocity by."""

# What each key does; arrow keys arrive as ANSI escape sequences (ESC [ A ...).
KEY_ACTIONS: dict[str, str] = {
    "w": "faster", "\x1b[A": "faster",
    "x": "slower", "\x1b[B": "slower",
    "a": "left", "\x1b[D": "left",
    "d": "right", "\x1b[C": "right",
    "s": "stop", " ": "stop",
    "q": "quit", "\x03": "quit", "\x04": "quit",  # q, Ctrl-C, Ctrl-D
}


@dataclass(frozen=True)
class Command:
    """A velocity command: linear (m/s, forward) and angular (rad/s, counter-clockwise)."""

    linear: float = 0.0
    angular: float = 0.0


def apply_key(command: Command, key: str, limits: RobotLimits | None = None) -> Command | None:
    """The command after pressing ``key``; None to quit. Unknown keys change nothing;
    speeds stay within the robot's ``limits``."""
    limits = limits or RobotLimits()
    action = KEY_ACTIONS.get(key.lower() if len(key) == 1 else key)
    if action == "quit":
        return None
    if action == "stop":
        return Command()
    linear, angular = command.linear, command.angular
    if action in ("faster", "slower"):
        step = LINEAR_STEP if action == "faster" else -LINEAR_STEP
        linear = _clamp(round(linear + step, 6), limits.max_linear_speed)
    elif action in ("left", "right"):
        step = ANGULAR_STEP if action == "left" else -ANGULAR_STEP
        angular = _clamp(round(angular + step, 6), limits.max_angular_speed)
    return Command(linear, angular)


def split_keys(data: str) -> list[str]:
    """The key presses in a chunk of terminal input: single characters, and arrow keys as
    one three-character escape sequence each."""
    keys: list[str] = []
    i = 0
    while i < len(data):
        if data.startswith("\x1b[", i) and i + 2 < len(data):
            keys.append(data[i:i + 3])
            i += 3
        else:
            keys.append(data[i])
            i += 1
    return keys


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


class NotATerminal(Exception):
    """Standard input is not a terminal, so there are no keys to read."""


@contextlib.contextmanager
def raw_terminal(fd: int) -> Iterator[None]:
    """Keys arrive one by one and are not echoed inside the block (Ctrl-C still
    interrupts); the terminal's settings are restored however the block ends."""
    import termios
    import tty

    if not os.isatty(fd):
        raise NotATerminal
    saved = termios.tcgetattr(fd)
    tty.setcbreak(fd)
    try:
        yield
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def read_keys(fd: int, timeout: float) -> list[str]:
    """The keys pressed, waiting at most ``timeout`` wall seconds for the first."""
    ready, _w, _x = select.select([fd], [], [], timeout)
    if not ready:
        return []
    return split_keys(os.read(fd, 64).decode("utf-8", "ignore"))
