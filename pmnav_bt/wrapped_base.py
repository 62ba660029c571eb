"""A ``Base`` around another: motion commands pass through unchanged; a subclass changes
what the body reports (its pose, its observations). Odometry models wrap bodies this
way (``sim.odometry.NoisyOdometry``, ``pose.odometry.CalibratedBase``)."""

from __future__ import annotations

from pmnav_bt.seams import Base, DiscreteAction, MotionStatus


class WrappedBase:
    """Passes ``step``, ``set_velocity``, ``motion_status`` and ``stop`` to ``inner``."""

    def __init__(self, inner: Base) -> None:
        self.inner = inner
        self.clock = inner.clock

    def step(self, action: DiscreteAction) -> None:
        self.inner.step(action)

    def set_velocity(self, linear: float, angular: float) -> None:
        self.inner.set_velocity(linear, angular)

    def motion_status(self) -> MotionStatus:
        return self.inner.motion_status()

    def stop(self) -> None:
        self.inner.stop()
