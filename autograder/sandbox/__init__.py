"""Containing untrusted student programs, by the process each part runs in.

In the grader and the pytest child: :mod:`.isolation` (how strongly this machine can
isolate, and the namespaces of a run), :mod:`.domains` (ROS domain reservations),
:mod:`.cgroups`, :mod:`.sweep` (ending all of a student user's leftovers),
:mod:`.leftovers`, and :mod:`.privileged` (starting our own privileged Python). In the
pytest child: :mod:`.process` (a student's program, started and stopped). In a process of
its own: :mod:`.startup_check` (isolation's check that a test program runs as a student's
would). In the contained program's process: :mod:`.contained`.
"""
