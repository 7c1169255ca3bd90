"""The report's pictures of the world: one figure per world, every run in it, replayable.

Test modules that ran in the same world become one figure: each run's path, end pose and
collisions over the world's drawing (``sim.svg.scene_svg``), and the tests each run
belongs to.  A run recorded with its commands and scans also gets a replay: the moving
parts (the robot at the slider's time, its last scan as rays and points, the command in
force) are an overlay the page's script (``autograder/static/replay.js``) moves, from the
run's data embedded as JSON.  A results file written before commands and scans were
recorded gives the static picture alone, as before.
"""

from __future__ import annotations

import base64
import functools
import hashlib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from markupsafe import Markup

from autograder.core.results import RunResult
from autograder.i18n.text import Text

if TYPE_CHECKING:  # sim is imported when a report is drawn, not with the renderers
    from sim.recorder import Recording
    from sim.worldfile import WorldSpec

# Drawn in world coordinates, hidden until the script shows them (no script: no robot
# standing at some arbitrary time).
_OVERLAY = (
    '<g class="replay" visibility="hidden">'
    '<path class="replay-rays" d="" fill="none" stroke="#ef6c00" stroke-opacity="0.18" '
    'stroke-width="0.008"/>'
    '<path class="replay-scan" d="" fill="none" stroke="#e65100" stroke-width="0.045" '
    'stroke-linecap="round"/>'
    '<g class="replay-robot" transform="translate(0 0)">'
    '<circle r="{radius}" fill="#ffb74d" fill-opacity="0.55" stroke="#e65100" '
    'stroke-width="0.02"/>'
    '<line class="replay-heading" x1="0" y1="0" x2="{radius}" y2="0" stroke="#e65100" '
    'stroke-width="0.025"/>'
    '<path class="replay-command" d="" fill="none" stroke="#6a1b9a" stroke-width="0.025" '
    'stroke-linejoin="round"/>'
    "</g></g>"
)


@dataclass(frozen=True)
class Run:
    """One test module's run in a world: its name and the tests that ran in it."""

    module: str
    labels: tuple[Text, ...]
    collisions: int
    data: dict[str, Any] | None  # what the replay needs; None: recorded without commands
    # and scans (an older results file), drawn as a static picture


@dataclass(frozen=True)
class Figure:
    """One world's picture: the drawing, its title and its runs."""

    world: Text
    svg: Markup
    runs: tuple[Run, ...] = ()

    @property
    def collisions(self) -> int:
        return sum(run.collisions for run in self.runs)

    @property
    def replay(self) -> list[dict[str, Any]] | None:
        """The runs' data for the script, or None for a static picture."""
        data = [run.data for run in self.runs if run.data is not None]
        return data if data and len(data) == len(self.runs) else None


@functools.cache
def script() -> tuple[Markup, str]:
    """The replay script, and its hash for the report's Content-Security-Policy."""
    text = resources.files("autograder").joinpath("static/replay.js").read_text("utf-8")
    digest = base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode()
    return Markup(text), f"'sha256-{digest}'"


def figures(result: RunResult, exercise_folder: Path | None) -> list[Figure]:
    """One figure per world the robot moved in, in the order the worlds were first used."""
    from sim.svg import scene_svg
    from sim.worldfile import ROBOT_RADIUS, load_world, title_of

    labels: dict[str, list[Text]] = {}
    for test in result.tests:
        module = test.module
        if module:
            labels.setdefault(module, []).append(Text(test.label, result.lang))
    worlds: dict[str, list[tuple[str, Recording]]] = {}
    for module, recording in result.recordings.items():
        if not recording.samples or recording.distance() < 0.05:
            continue  # the robot stood still: nothing to look at
        worlds.setdefault(recording.world, []).append((module, recording))
    found = []
    for name, runs in worlds.items():
        local = exercise_folder / f"{name}.yaml" if exercise_folder else None
        try:
            spec = load_world(local if local and local.exists() else name)
        except Exception:  # a picture we cannot draw is left out
            continue
        title = title_of(spec)  # in English when not translated: marked so
        english = result.lang != "en" and title in (spec.title, spec.name)
        replayable = any(recording.scans or recording.commands for _m, recording in runs)
        overlay = _OVERLAY.format(radius=ROBOT_RADIUS) if replayable else ""
        svg = scene_svg(spec, [recording for _m, recording in runs], spec.goal, overlay)
        found.append(Figure(
            world=Text(title, "en" if english else result.lang, english),
            svg=Markup(svg),
            runs=tuple(Run(module, tuple(labels.get(module, [])), len(recording.collisions),
                           _replay_data(spec, recording) if replayable else None)
                       for module, recording in runs)))
    return found


def _replay_data(spec: WorldSpec, recording: Recording) -> dict[str, Any]:
    """What the script needs of one run, in the units of the recording (no English text:
    a collision is its time; what it hit is in the drawing's tooltips).  A run starts at
    sim time 0 at the world's start pose (the first odometry sample comes 0.02 s later)."""
    recorded = recording.to_dict()  # the results' precision and bounds
    start = spec.start
    poses = [[0.0, start.x, start.y, start.theta]]
    poses += [row[:4] for row in recorded["trajectory"] if row[0] > 0]
    commands, scans = recorded["commands"], recorded["scans"]
    end = max([poses[-1][0]] + [row[0] for row in commands[-1:]]
              + [row[0] for row in scans[-1:]])
    # How far apart the kept scans are: a scan older than 1.5 times that is not drawn, so
    # a silent lidar (a dropout, or a test feeding scans of its own) shows as none.
    every = (scans[-1][0] - scans[0][0]) / (len(scans) - 1) if len(scans) > 1 else 0.5
    return {"end": end, "poses": poses, "scan_every": max(every, 0.5),
            "commands": commands, "scans": scans,
            "scan": recorded["scan"],
            "collisions": [c.t for c in recording.collisions]}
