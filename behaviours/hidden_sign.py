"""A sign not seen because something stands in front of it: look again later.

In a corridor at 10 a.m. a sign is often hidden for a moment: a group talking under it, a
cart parked before it. A search that did not find the target's sign says "not there" only
when the views could have shown it; where the depth of the view that faces the sign shows
something standing on the floor well before the wall the sign hangs on, the sign was
hidden, not absent. ``SignHidden`` says so (SUCCESS), and the step's tree then waits a
moment and searches again instead of moving on as for a sign that is not there; at most
``LOOKS_AGAIN`` times a target, so a cart that stays costs little.

``HIDDEN_MARGIN_M`` (1.0 m): something nearer than the sign by more than this (and than
where its own wall, seen at a slant, enters the line of sight) stands in front of it (a
person is 0.5 m deep, a cart 0.6 m).
"""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import map_pose
from pmnav_bt.behaviours.search import target_entity
from pmnav_bt.geometry import heading, wrap_angle
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.planning.resolve import entity_position

HIDDEN_MARGIN_M = 1.0
VIEW_MARGIN = math.radians(5.0)  # a sign this close to the image border is not judged
BAND_M = 0.15  # half the width of the line of sight checked for something before the sign
MIN_SLANT = math.radians(15.0)  # a sign seen more slanted than this is not judged
LOOKS_AGAIN = 1  # times a target's search waits and looks again for a hidden sign
LOOK_AGAIN_AFTER_S = 4.0  # how long the tree waits before it looks again


class SignHidden(PmNavBehaviour):
    """SUCCESS when a view of the last search faced the target's sign and its depth shows
    something standing before it (``HIDDEN_MARGIN_M``), at most ``LOOKS_AGAIN`` times a
    target; FAILURE otherwise. Reads ``views``, ``target``, ``map_T_odom``."""

    READS = ("views", "target", "map_T_odom")

    def __init__(self, name, ctx):
        super().__init__(name, ctx)
        self._looked: dict[str, int] = {}  # target landmark -> times it looked again

    def update(self) -> Status:
        t, entity = self.get("target"), target_entity(self)
        if t is None or entity is None or self._looked.get(t.landmark, 0) >= LOOKS_AGAIN:
            return Status.FAILURE
        sign = entity_position(self.ctx.pm, entity)
        tf = self.get("map_T_odom")
        for view in self.get("views") or ():
            obs = view.observation
            if obs.depth is None:
                continue
            est = map_pose(tf, obs.pose)
            far = math.dist((est.x, est.y), sign)
            bearing = wrap_angle(heading((est.x, est.y), sign) - est.yaw)
            if abs(bearing) > abs(obs.intrinsics.pixel_bearing(0.0)) - VIEW_MARGIN:
                continue
            # the sign's wall runs along the corridor: seen at a slant, it enters the band
            # looked along before the sign does
            slant = abs(wrap_angle(2.0 * (est.yaw + bearing - t.heading))) / 2.0
            if slant < MIN_SLANT:
                continue
            before = free_distance(obs, bearing, half_width=BAND_M)
            if before < far - HIDDEN_MARGIN_M - BAND_M / math.tan(slant):
                self._looked[t.landmark] = self._looked.get(t.landmark, 0) + 1
                self.ctx.log("sign_hidden", t.landmark, sign_m=far, before_m=before)
                self.feedback_message = (
                    f"{t.look_for}'s sign hidden: something {before:.1f} m ahead of it "
                    f"({far:.1f} m): look again later"
                )
                return Status.SUCCESS
        return Status.FAILURE
