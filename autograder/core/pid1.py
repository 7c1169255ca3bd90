"""The grader as a container's first process.

A Kubernetes Job's command, or ``docker run IMAGE autograder ...``, is PID 1 of its
container, and the kernel hands PID 1 every orphan of the container to reap. Students'
programs leave orphans (the daemons the sweep ends), and a zombie still counts against
its user's ``RLIMIT_NPROC``: never reaped, they would starve the next grading that runs as
that user. So as PID 1 the grader forks, as tini does: the first process reaps whatever
the kernel hands it and passes signals on; its child runs the command, and its exit
status is the container's.
"""

from __future__ import annotations

import os
import signal

PASSED_ON = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1,
             signal.SIGUSR2)


def reap_as_init() -> None:
    """Return at once unless this process is PID 1; as PID 1, return in a child that
    runs the command, while this process reaps until that child ends, then exits with
    its status."""
    if os.getpid() != 1:
        return
    child = os.fork()
    if child == 0:
        return
    for signum in PASSED_ON:
        signal.signal(signum, lambda signum, _frame: os.kill(child, signum))
    while True:
        try:
            pid, status = os.wait()  # any child: the command, or an orphan handed over
        except ChildProcessError:  # nothing left to wait for (cannot happen before child)
            os._exit(1)
        if pid == child:
            code = os.waitstatus_to_exitcode(status)
            os._exit(code if code >= 0 else 128 - code)
