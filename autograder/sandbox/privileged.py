"""How the grader starts a Python process of its own that runs with privileges a student's
program must not have (the launcher and the start-up check run as root until they have
contained the program): nothing of the student's may be on its module path.

``python -m MODULE`` puts its working directory first on the module path, and so does
``python -c``: started from the student's folder, a ``json.py`` placed beside the node
would be imported as root, before any namespace, limit or change of user. So such a
process is started in isolated mode (``-I``: no
working directory or script folder on the path, no ``PYTHON*`` variables, no user
site-packages), from ``/``, with only this platform's own checkout put on the path.
"""

from __future__ import annotations

import sys
from pathlib import Path

SAFE_CWD = "/"
"""The working directory of a privileged process: a folder no student can write."""

PACKAGE_PARENT = str(Path(__file__).resolve().parents[2])
"""The folder holding the ``autograder`` package (a checkout, or site-packages)."""

_BOOT = ("import runpy, sys; sys.path.insert(0, {parent!r}); "
         "runpy.run_module({module!r}, run_name='__main__', alter_sys=True)")


def module_command(module: str, args: list[str], python: str | None = None) -> list[str]:
    """The command that runs ``module`` as ``python -m module args...`` would, isolated:
    the module path is the interpreter's own and this platform's package, nothing else.
    Start it with ``cwd=SAFE_CWD``."""
    boot = _BOOT.format(parent=PACKAGE_PARENT, module=module)
    return [python or sys.executable, "-I", "-c", boot, *args]
