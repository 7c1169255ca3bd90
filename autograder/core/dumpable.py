"""Close a process of ours to the other processes of its user."""

from __future__ import annotations

import ctypes

PR_SET_DUMPABLE = 4


def not_dumpable() -> None:
    """``PR_SET_DUMPABLE`` 0: in basic isolation the student runs as our user, and could
    otherwise trace this process (``PTRACE_ATTACH`` also stops it) or read its memory
    (``/proc/PID/mem``), the report's key with it. Programs it execs are dumpable again;
    only this process (and what it forks without exec) is closed."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_DUMPABLE, 0, 0, 0, 0)
