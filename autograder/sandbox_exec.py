"""The launcher between the grader and a student's program.

Runs as a fresh single-threaded process (so no ``preexec_fn`` runs in the threaded
grader): joins the run's cgroups, starts a new session, sets resource limits, then
``exec``s the student's command.  Usage::

    python -m autograder.sandbox_exec LIMITS_JSON CGROUP_DIR... -- COMMAND...
"""

from __future__ import annotations

import json
import os
import resource
import sys

_RLIMITS = {
    "cpu_seconds": (resource.RLIMIT_CPU, 1),
    "memory_mb": (resource.RLIMIT_AS, 1024 * 1024),
    "processes": (resource.RLIMIT_NPROC, 1),
    "open_files": (resource.RLIMIT_NOFILE, 1),
    "file_size_mb": (resource.RLIMIT_FSIZE, 1024 * 1024),
}


def apply_limits(limits: dict[str, int]) -> None:
    for key, (which, scale) in _RLIMITS.items():
        if key not in limits:
            continue
        value = int(limits[key]) * scale
        if which == resource.RLIMIT_NPROC and os.geteuid() == 0:
            continue  # root is exempt from RLIMIT_NPROC; the pids cgroup counts instead
        resource.setrlimit(which, (value, value))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def main(argv: list[str]) -> None:
    split = argv.index("--")
    limits = json.loads(argv[0])
    for cgroup in argv[1:split]:
        with open(os.path.join(cgroup, "cgroup.procs"), "w") as fh:
            fh.write(str(os.getpid()))
    apply_limits(limits)
    command = argv[split + 1:]
    os.execvp(command[0], command)


if __name__ == "__main__":
    main(sys.argv[1:])
