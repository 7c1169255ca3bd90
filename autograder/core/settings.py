"""What the grader tells the pytest child that runs one grading, as one document.

The grader (:mod:`autograder.grading.run`) writes a :class:`RunSettings` as JSON into the
child's single ``--autograder-settings`` option; the plugin (:mod:`autograder.plugin`)
reads it back. An instructor running an exercise's tests by hand gives the same settings
as ordinary options (``--exercise``, ``--submission``, ``--ros-domain``,
``--real-time-factor``, ``--record-bags``).
"""

from __future__ import annotations

import dataclasses
import json
from typing import Literal


@dataclasses.dataclass(frozen=True)
class RunSettings:
    """One grading run, as its pytest child needs to know it."""

    exercise: str  # the exercise's folder (or id, by hand)
    submission: str | None = None  # the student's file or folder; None: the solution
    course: str | None = None  # the course tree (becomes AUTOGRADER_COURSE in the child)
    report: str | None = None  # where the child writes the signed raw report
    key_fd: int | None = None  # a pipe holding the report's signing key
    lifeline_fd: int | None = None  # a pipe that closes when the grader dies
    domain: int | None = None  # the ROS domain the grader reserved; None: reserve one
    # Every domain of the grading, this child's among them: its other children's students
    # are the same student's program (the tampering guard tells them from strangers).
    domains: tuple[int, ...] = ()
    real_time_factor: float | None = None  # overrides the exercise's
    isolation: Literal["strict", "user", "basic"] = "basic"  # as the grader chose it
    lang: str = "en"
    record: str | None = None  # a folder: each test module's graph recorded as a bag in it
    # The student's file as they named it (``mywork/avoider.py``): tracebacks and messages
    # show it instead of the throwaway copy the program runs from. None: the file's name.
    submission_name: str | None = None
    # Folders whose tests are collected and counted but not run (``check``: the hidden
    # tests), so a partial run can say what the grade adds.
    count_only: tuple[str, ...] = ()

    @property
    def strict(self) -> bool:
        return self.isolation == "strict"

    @property
    def own_user(self) -> bool:
        """The student's program runs as a user of its own (strict or user isolation)."""
        return self.isolation in ("strict", "user")

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self))

    @classmethod
    def from_json(cls, text: str) -> RunSettings:
        """Read what :meth:`to_json` wrote (JSON's lists back as the fields' tuples); keys
        of no field are left out."""
        fields = {f.name for f in dataclasses.fields(cls)}
        return cls(**{k: tuple(v) if isinstance(v, list) else v
                      for k, v in json.loads(text).items() if k in fields})
