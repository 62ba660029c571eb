"""The simulated robot in a building of several levels: one pybullet world per level, the
body in one of them at a time, moved to another by the lift (``sim.lift.SimLift``).

Each level is its own ``SimWorld`` (built from that level's ``Building``, with the lifts'
cabins behind their doors), in its own map frame. ``LevelBody`` is a ``SimBase`` for the
level it is on; a ride ends with ``carry``: the body leaves the cabin of one level's world
and stands at the same place in the cabin of the next.

Odometry does not jump with it: the wheels did not turn in the lift. ``pose`` is the
odometry pose, in a frame that starts as the first level's map frame and keeps the path
continuous across rides (on each level, a fixed transform from that level's world);
``world_pose`` is the truth in the world of the level the body is on (what the episode is
scored on). The tree sees a ``Base`` and nothing of this; the lift subtree drops its
estimate on arrival and localizes again on the new level's map.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

from pmnav_bt.geometry import se2_compose, se2_inverse
from pmnav_bt.hazards import Hazard
from pmnav_bt.seams import DiscreteAction, MotionStatus, Observation, Pose2D
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.robot import MotionStats, SimBase
from pmnav_bt.sim.world import SimWorld

PARK = Pose2D(-500.0, -500.0, 0.0)  # where a level's body waits while the robot is elsewhere


class LevelBody:
    """The robot's body over ``worlds`` (level name -> SimWorld), first on ``level`` at
    ``pose`` (that level's map frame); ``camera``: ``SimBase``'s keyword arguments (its
    camera, its limits), the same on every level. A ``seams.Base``, and the lift's
    ``Rider``."""

    def __init__(
        self,
        worlds: Mapping[str, SimWorld],
        level: str,
        pose: Pose2D,
        clock: SimClock | None = None,
        **camera,
    ) -> None:
        if level not in worlds:
            raise ValueError(f"no level {level!r}; levels: {', '.join(worlds)}")
        self.worlds = dict(worlds)
        self.clock = clock if clock is not None else SimClock()
        self._camera = camera
        self.level = level
        first = SimBase(worlds[level], self.clock, pose=pose, **camera)
        self._bodies: dict[str, SimBase] = {level: first}
        self._odom_T_world = (0.0, 0.0, 0.0)

    @property
    def body(self) -> SimBase:
        """The body in the world of the level the robot is on."""
        return self._bodies[self.level]

    @property
    def world(self) -> SimWorld:
        return self.worlds[self.level]

    @property
    def stats(self) -> MotionStats:
        """What the body has done on every level, together."""
        total = MotionStats()
        for b in self._bodies.values():
            total.path_length += b.stats.path_length
            total.rotation += b.stats.rotation
            total.collisions += b.stats.collisions
            total.actions += b.stats.actions
        return total

    # -- the lift's rider ------------------------------------------------------------------------

    def world_pose(self) -> Pose2D:
        """The true pose in the map frame of the level the body is on."""
        return self.body.pose()

    def carry(self, level: str, pose: Pose2D) -> None:
        """Move the body to ``level``'s world at ``pose`` (its map frame): the end of a
        ride. The odometry pose stays where it was."""
        odom = self.pose()
        self.body.set_pose(PARK)
        self.level = level
        if level in self._bodies:
            self._bodies[level].set_pose(pose)
        else:
            self._bodies[level] = SimBase(self.worlds[level], self.clock, pose=pose, **self._camera)
        self._odom_T_world = se2_compose(_t(odom), se2_inverse(_t(pose)))

    # -- seams.Base ------------------------------------------------------------------------------

    def pose(self) -> Pose2D:
        return self._to_odom(self.body.pose())

    def observe(self) -> Observation:
        obs = self.body.observe()
        return replace(obs, pose=self._to_odom(obs.pose))

    def step(self, action: DiscreteAction) -> None:
        self.body.step(action)

    def set_velocity(self, linear: float, angular: float) -> None:
        self.body.set_velocity(linear, angular)

    def motion_status(self) -> MotionStatus:
        return self.body.motion_status()

    def stop(self) -> None:
        self.body.stop()

    @property
    def velocity_command(self) -> tuple[float, float]:
        return self.body.velocity_command

    # -- the bumper (pmnav_bt.hazards.FeelsHazards) --------------------------------------------

    def hazards(self, since: float = -math.inf) -> list[Hazard]:
        """What the body felt on the level it is on since ``since``, in the odometry frame
        (what it felt on another floor is no obstacle here)."""
        return [h.moved(self._odom_T_world) for h in self.body.hazards(since)]

    def blocked_by(self) -> Hazard | None:
        """The bump that cut the body's latest motion, in the odometry frame."""
        hazard = self.body.blocked_by()
        return None if hazard is None else hazard.moved(self._odom_T_world)

    def close(self) -> None:
        """Detach every level's body from the clock (the worlds are closed by their owner)."""
        for b in self._bodies.values():
            b.close()

    def _to_odom(self, p: Pose2D) -> Pose2D:
        x, y, yaw = se2_compose(self._odom_T_world, _t(p))
        return Pose2D(x, y, yaw)


def _t(p: Pose2D) -> tuple[float, float, float]:
    return p.x, p.y, p.yaw
