"""The lift's timings: one model of a building's lift in time, shared by the pybullet
simulator's lift (``sim/lift.py``, ``SimLift``) and the simulated lift node's
(``hardware/lift_bank.py``, ``LiftBank``, behind ``pmnav-sim-lift``).

The numbers are a typical hospital bed lift's (the lift a robot rides in a hospital: a
cabin deep enough for a bed, 1,600-2,000 kg, about 1 m/s):

- ``door_s`` 3 s: a door 1.3-1.6 m wide, two panels opening from the centre (or
  telescopic to one side), opens or shuts in 2.5-3.5 s; a passenger lift's narrower door
  takes 2 s.
- ``ride_s_per_level`` 8 s: one storey of about 4 m at 1 m/s is some 4 s at full speed,
  and a bed lift spends about 2 s starting and 2 s levelling gently at the floor.
- ``dwell_s`` 5 s: a door held by no one stays open about 5 s after the last passenger
  (bed lifts longer than the 3 s of a passenger lift, for the bed to clear the sill).
- ``call_delay_s`` up to 40 s: before it comes, a called lift serves the calls of the
  people already in it or waiting on other floors; at a quiet hour it comes at once, at a
  busy one in 30-60 s or more (``tree.lift_wait_s``, how long the tree waits, is 3 min).
"""

from __future__ import annotations

from dataclasses import dataclass

from pmnav_bt.errors import PmNavError


@dataclass(frozen=True)
class LiftTiming:
    """How long a lift takes (seconds): its door to open or to shut, a ride of one level,
    the door left open after its session ends, and the longest wait before it answers a
    call (each call's wait is drawn uniformly from 0 to this). See the module."""

    door_s: float = 3.0
    ride_s_per_level: float = 8.0
    dwell_s: float = 5.0
    call_delay_s: float = 40.0

    def __post_init__(self) -> None:
        for name in ("door_s", "ride_s_per_level", "dwell_s", "call_delay_s"):
            v = getattr(self, name)
            if not v >= 0.0:
                raise PmNavError(f"{name} must be 0 or more seconds, not {v}")


BED_LIFT = LiftTiming()  # the defaults: a hospital bed lift (the module's numbers)
