"""One simulation run without ROS: physics, lidar, faults and recording, step by step.

Both the ROS bridge and the benchmark drive a :class:`Simulation`; it says which sensor
outputs fall due at each physics step (odometry at 50 Hz, scans at 10 Hz of sim time) and
the bridge only turns them into messages.  Odometry comes twice: the ground truth in the
world frame, which the recording keeps for the grader, and the wheel odometry in the
robot's ``odom`` frame (REP 105), integrated over every step (each run of unchanged
velocities at once), which goes out on /odom.
"""

from __future__ import annotations

from dataclasses import dataclass

from sim.faults import FaultInjector, Scan
from sim.lidar import Lidar
from sim.odometry import WheelOdometry
from sim.physics import World
from sim.recorder import Recording, Sample
from sim.worldfile import Fault

ODOM_HZ = 50.0
SCAN_HZ = 10.0


@dataclass(frozen=True)
class Outputs:
    """Sensor outputs due after one step: odometry (ground truth and the wheels'), and a
    scan unless dropped out."""

    odom: Sample | None = None
    """Ground truth: the pose in the world frame and the body's measured velocities."""
    scan: Scan | None = None
    scan_due: bool = False
    wheel_odom: Sample | None = None
    """What the robot knows: the pose in its ``odom`` frame and its wheel speeds."""


_NOTHING = Outputs()


class Simulation:
    """A :class:`World` plus its sensors, faults and recording."""

    def __init__(self, world: World, lidar: Lidar | None = None) -> None:
        self.world = world
        self.lidar = lidar or Lidar.from_spec(world.spec.lidar)
        self._odometry = WheelOdometry()
        self.faults = FaultInjector(world.spec.faults, world.seed, self.lidar)
        self.recording = Recording(world=world.spec.name,
                                   scan_angle_min=self.lidar.angle_min,
                                   scan_angle_increment=self.lidar.angle_increment)
        self._drive = world.command  # the wheels' velocities, unchanged since step
        self._drive_since = 0  # (handed to the odometry in one run when they change)
        self._odom_every = max(1, round(1.0 / (ODOM_HZ * world.dt)))
        self._scan_every = max(1, round(1.0 / (SCAN_HZ * world.dt)))

    def step(self) -> Outputs:
        """Advance one physics step and return what the sensors produce now."""
        world = self.world
        if self.faults.obstacles_pending:
            for obstacle in self.faults.due_obstacles(world.time):
                world.add_obstacle(obstacle)
        world.step()
        if world.command != self._drive:  # the odometry integrates each run at once
            self._hand_drive()
        if world.has_contacts:
            for contact in world.drain_contacts():
                self.recording.add_collision(contact)
        steps = world.steps
        odom_due, scan_due = steps % self._odom_every == 0, steps % self._scan_every == 0
        if not (odom_due or scan_due):
            return _NOTHING  # most steps: the bridge runs this 200 times a simulated second
        odom = wheel = scan = None
        if odom_due:
            odom = Sample(world.time, *world.pose, *world.velocity)
            self.recording.add_sample(odom)
            self._hand_drive()
            wheel = Sample(world.time, *self._odometry.pose, self._odometry.v,
                           self._odometry.w)
        if scan_due:
            scan = self.faults.apply(world.time, self.lidar.scan(world))
            if scan is not None:
                self.recording.add_scan(scan.t, scan.ranges)
        return Outputs(odom, scan, scan_due, wheel)

    @property
    def odometry(self) -> WheelOdometry:
        """The wheel odometry, up to date with the last step."""
        self._hand_drive()
        return self._odometry

    def _hand_drive(self) -> None:
        """Give the odometry the steps driven at the previous velocities (the one just
        taken at the new ones included, if they changed)."""
        world = self.world
        changed = world.command != self._drive
        upto = world.steps - 1 if changed else world.steps
        self._odometry.run(*self._drive, world.dt, upto - self._drive_since)
        if changed:
            self._odometry.run(*world.command, world.dt, 1)
            self._drive, self._drive_since = world.command, world.steps
        else:
            self._drive_since = upto

    def set_command(self, linear: float, angular: float) -> None:
        """Drive the robot (body-frame velocities) from now on; the recording keeps it."""
        self.recording.add_command(self.world.time, linear, angular)
        self.world.set_command(linear, angular)

    def inject(self, fault: Fault) -> None:
        """Add a fault at run time."""
        self.faults.add(fault)

    def reset(self) -> None:
        """Back to time 0 and the start pose; the recording starts afresh."""
        self.world.reset()
        self._odometry.reset()
        self._drive, self._drive_since = self.world.command, 0
        self.faults.reset()
        self.recording.clear()
