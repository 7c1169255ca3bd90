"""Shell blocks of a README or a guide, run as a student pastes them (issue 35): each block
in a terminal of its own, in a fresh copy of the course, as an ordinary user when the tests
run as root, with a new login's environment (no venv active, no course variables)."""

from __future__ import annotations

import os
import random
import re
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from shapes import NOBODY, ordinary_user, world_readable_folder

AS_NOBODY = os.geteuid() == 0 and all(map(shutil.which, ("unshare", "setpriv")))


def as_a_terminal_starts_it() -> None:
    """Ctrl-C, Ctrl-\\, hang-up and termination at their defaults, as in a terminal (a
    ``preexec_fn``): a test run from a shell's background job inherits SIGINT and SIGQUIT
    ignored, one run under ``nohup`` SIGHUP, and so would the command it starts."""
    for signum in (signal.SIGINT, signal.SIGQUIT, signal.SIGHUP, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)


def commands(block: str) -> list[str]:
    """A shell block's commands, its comments left out."""
    lines = (re.sub(r"\s+#.*$", "", line).strip() for line in block.splitlines())
    return [line for line in lines if line and not line.startswith("#")]


def blocks(text: str) -> list[list[str]]:
    """Every ```sh block of a Markdown text, as its commands."""
    return [commands(b) for b in re.findall(r"^```sh\n(.*?)^```", text, re.M | re.S)]


class Terminal:
    """Terminals in ``folder`` (a fresh copy of a course), whose ``.venv`` is the venv these
    tests run in, so `. .venv/bin/activate` runs as pasted. ``skip`` names set-up commands
    that would reinstall that venv; the caller says where they are run instead."""

    def __init__(self, folder: Path, skip: tuple[str, ...] = ()) -> None:
        self.folder, self.skip = folder, skip
        (folder / ".venv").symlink_to(Path(sys.prefix))
        self.env = {"HOME": str(folder.parent), "PATH": "/usr/local/bin:/usr/bin:/bin",
                    "LANG": "C.UTF-8", "TERM": "dumb",
                    "ROS_DOMAIN_ID": str(random.randrange(150, 230))}
        self.prefix: list[str] = []
        if AS_NOBODY:
            subprocess.run(["chown", "-R", f"{NOBODY}:{NOBODY}", str(folder.parent)],
                           check=True)
            self.prefix = ordinary_user()

    def _argv(self, lines: list[str]) -> list[str]:
        script = "set -e\n" + "\n".join(c for c in lines if c not in self.skip) + "\n"
        return [*self.prefix, "bash", "-c", script]

    def run(self, lines: list[str], stdin: str = "", timeout: float = 600) -> str:
        done = subprocess.run(self._argv(lines), cwd=self.folder, env=self.env, input=stdin,
                              capture_output=True, text=True, timeout=timeout)
        assert done.returncode == 0, f"{lines}\n{done.stdout}\n{done.stderr}"
        return done.stdout + done.stderr

    def start(self, lines: list[str]) -> subprocess.Popen[str]:
        return subprocess.Popen(self._argv(lines), cwd=self.folder, env=self.env, text=True,
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT)


@contextmanager
def terminal_in(make: Callable[[Path], None], skip: tuple[str, ...]) -> Iterator[Terminal]:
    """A Terminal in a folder that ``make`` fills (a clone, a release), in a home every
    user can pass through (pytest's own folders are 0700)."""
    home = world_readable_folder("pasted-")
    try:
        make(home / "course")
        yield Terminal(home / "course", skip)
    finally:
        shutil.rmtree(home, ignore_errors=True)
