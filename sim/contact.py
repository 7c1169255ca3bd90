"""A contact the robot made: the plain fact physics reports and a recording keeps.

Apart from :mod:`sim.physics` so that reading a recording (the grader does, for every
grading) imports neither pymunk nor numpy.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Contact:
    """The robot started touching something: when, where the robot was, what it hit."""

    t: float
    x: float
    y: float
    what: str

    @property
    def description(self) -> str:
        """What it hit, for people, in the active language ("wall 3" in English)."""
        from sim.physics import describe  # the names' catalogue lives with the world

        return describe(self.what)

    @property
    def hit_name(self) -> str:
        """What it hit, as a sentence that says so names it: before a postposition, in the
        oblique case ("the robot hit {what}": Urdu "ڈبے 2 سے ٹکرایا")."""
        from sim.physics import describe

        return describe(self.what, oblique=True)
