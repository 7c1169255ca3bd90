"""The agent's run to a goal, watched from the world, and how it is judged.

The world records the robot's pose and speed at 50 Hz and every collision; the grader
never asks the node where it thinks it is.  The node is given its goal in the frame it
has, ``odom`` (REP 105: where the robot started), and judged in the world's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from std_msgs.msg import String

from autograder.core.errors import StudentFailure
from autograder.i18n import _
from autograder.plugin.collisions import with_front_beam_note
from sim.odometry import to_odom
from sim.worldfile import load_world

REACHED = 0.3              # m from the goal: inside counts as reached
STILL = 0.02               # m/s: slower than this counts as stopped
STATUS_WITHIN = 1.0        # s after arriving for agent_status to come
STALLED = 5.0              # s standing still, once moving, away from the goal ends the run
# Path length over the straight start-to-goal distance: up to FULL earns the bonus.
FULL = 1.5


def goal_parameters(world: str) -> dict[str, float]:
    """``goal_x``/``goal_y`` for ``world``: its goal in the odom frame of its start pose."""
    spec = load_world(world)
    x, y = to_odom(spec.start, spec.goal.x, spec.goal.y)
    return {"goal_x": round(x, 6), "goal_y": round(y, 6)}


@dataclass
class Mission:
    """What happened between the node's start and the end of its run."""

    start: tuple[float, float]
    goal: tuple[float, float]
    limit: float
    t0: float
    samples: list[Any] = field(default_factory=list)
    collisions: list[Any] = field(default_factory=list)
    arrived_at: float | None = None
    died_at: float | None = None
    end: float = 0.0
    statuses: list[tuple[float, str]] = field(default_factory=list)
    output_tail: str = ""
    geometry: Any = None  # the world's shapes (World.geometry), to tell where a hit was

    @property
    def distance(self) -> float:
        return math.dist(self.start, self.goal)

    def to_goal(self, sample: Any) -> float:
        return math.dist((sample.x, sample.y), self.goal)

    @property
    def hit(self) -> Any | None:
        """The first collision before arriving, if any."""
        end = self.arrived_at if self.arrived_at is not None else math.inf
        return next((c for c in self.collisions if c.t <= end), None)

    def progress(self) -> float:
        """Share of the start-to-goal distance covered (closest approach before a hit)."""
        until = self.hit.t if self.hit else math.inf
        closest = min((self.to_goal(s) for s in self.samples if s.t <= until),
                      default=self.distance)
        return max(0.0, min(1.0, (self.distance - closest) / self.distance))

    def path_length(self) -> float:
        end = self.arrived_at if self.arrived_at is not None else math.inf
        points = [(s.x, s.y) for s in self.samples if s.t <= end]
        return sum(math.dist(a, b) for a, b in zip(points, points[1:], strict=False))

    def state_at(self, t: float) -> Any | None:
        """The robot's last recorded state at or before ``t`` (what was true when a
        message was sent, not a moment later)."""
        return max((s for s in self.samples if s.t <= t), key=lambda s: s.t, default=None)

    def stopped_at_goal(self, sample: Any) -> bool:
        """Within REACHED of the goal, slower than STILL and turning slower than 5 * STILL
        rad/s: arrived, as :func:`fly` and the task have it."""
        return self.to_goal(sample) <= REACHED and abs(sample.v) < STILL \
            and abs(sample.w) < 5 * STILL


def fly(world: Any, probe: Any, student: Any, limit: float) -> Mission:
    """Watch the robot until it stops within REACHED of the goal (then STATUS_WITHIN more),
    collides, its node dies, or ``limit`` seconds of simulation time pass."""
    spec = world.world.spec
    status = probe.subscribe(String, "/agent_status", stamp="published")
    recording = world.recording
    samples = recording.samples  # appended by the world; read the last one lock-free
    mission = Mission(start=(spec.start.x, spec.start.y), goal=(spec.goal.x, spec.goal.y),
                      limit=limit, t0=probe.now)

    def arrived() -> bool:
        last = samples[-1] if samples else None
        return (last is not None and mission.to_goal(last) <= REACHED
                and abs(last.v) < STILL and abs(last.w) < 5 * STILL)

    moved = [math.inf]  # when the robot last moved (a slow start is no stall)

    def over() -> bool:
        last = samples[-1] if samples else None
        if last is not None and (abs(last.v) >= STILL or abs(last.w) >= 5 * STILL):
            moved[0] = last.t
        return (arrived() or bool(recording.collisions) or not student.running()
                or probe.now - mission.t0 >= limit or probe.now - moved[0] >= STALLED)

    probe.wait_for(over, limit)
    if arrived():
        mission.arrived_at = probe.now
        probe.wait_sim(STATUS_WITHIN)
        probe.settle(status)
    elif not student.running():
        mission.died_at = probe.now
    mission.end = probe.now
    mission.samples, mission.collisions = [
        s for s in recording.snapshot()[0] if s.t >= mission.t0], recording.snapshot()[1]
    mission.statuses = [(t, m.data) for t, m in status.items]
    mission.output_tail = student.output_tail(12)
    mission.geometry = world.world.geometry
    return mission


def judge_reached(mission: Mission, world_name: str) -> None:
    """Full marks for stopping at the goal untouched; nothing otherwise, with what happened
    and the share of the way covered in the message.

    All or nothing, as the README says: where a run ends (the robot's stop, the point it
    meets an obstacle) turns on which tick its node's executor took odometry or the clock
    first, and a share of the way gave the same program scores that differed by
    hundredths from one grading to the next (a node stopping 0.6 m short stopped 0.51 to
    0.54 m short in five stressed gradings)."""
    if mission.arrived_at is not None and mission.hit is None:
        return
    progress = mission.progress()
    if mission.hit is not None:
        hit = mission.hit
        message = _("In the {world}, the robot hit {what} at `({x:.2f}, {y:.2f})` after "
                    "{seconds:.1f} s, having covered {share:.0%} of the way to the goal.").format(
            world=world_name, what=hit.hit_name, x=hit.x, y=hit.y,
            seconds=hit.t - mission.t0, share=progress)
        until = mission.died_at if mission.died_at is not None else math.inf
        message = with_front_beam_note(message, [hit], mission.samples, mission.geometry,
                                       since=mission.t0, until=until)
        hint = _("Steer by the lidar: never drive toward a direction whose readings are "
                 "closer than the robot needs to pass.")
    elif mission.died_at is not None:
        message = _("In the {world}, the node's process ended after {seconds:.1f} s, having "
                    "covered {share:.0%} of the way. Its last lines:\n{tail}").format(
            world=world_name, seconds=mission.died_at - mission.t0, share=progress,
            tail=mission.output_tail)
        hint = _("Run it yourself against the world and read the traceback.")
    else:
        last = mission.samples[-1] if mission.samples else None
        left = mission.to_goal(last) if last else mission.distance
        message = _("In the {world}, after {seconds:.0f} s the robot had not stopped within "
                    "{reached} m of the goal ({left:.2f} m away, moving at {speed:.2f} m/s; "
                    "the limit is {limit:.0f} s, or {stalled:.0f} s standing still); it "
                    "covered {share:.0%} of the way.").format(
            world=world_name, seconds=mission.end - mission.t0, limit=mission.limit,
            stalled=STALLED, reached=REACHED, left=left,
            speed=abs(last.v) if last else 0.0, share=progress)
        if last is not None and abs(last.v) < STILL and abs(last.w) < 5 * STILL:
            hint = _("It stood still outside {reached} m of the goal, which is not arriving: "
                     "drive on until the odometry puts you within {reached} m of "
                     "`(goal_x, goal_y)`, then stop.").format(reached=REACHED)
        else:
            hint = _("Stop (a zero Twist) once the odometry puts you within 0.3 m of "
                     "`(goal_x, goal_y)`; is the goal read from the parameters?")
    raise StudentFailure(message, hint)


def judge_efficiency(mission: Mission, world_name: str) -> None:
    """The path driven against the straight line: the bonus for up to FULL times it.

    All or nothing, as the README says: a path's length differs by a tick's drive from
    one grading to the next, and a share of the bonus would follow it."""
    if mission.arrived_at is None or mission.hit is not None:
        raise StudentFailure(
            _("In the {world} the robot did not reach the goal untouched, so its path "
              "cannot be judged.").format(world=world_name))
    ratio = mission.path_length() / mission.distance
    if ratio <= FULL:
        return
    raise StudentFailure(
        _("In the {world} the robot drove {length:.1f} m to a goal {straight:.1f} m away: "
          "{ratio:.1f} times the straight line; the bonus is for up to {full} times "
          "it.").format(world=world_name, length=mission.path_length(),
                        straight=mission.distance, ratio=ratio, full=FULL),
        _("Head for the goal whenever the way is clear; turn away only as far as an "
          "obstacle needs."))
