"""An earlier estimate of the pose: hypotheses near where it puts the robot are likelier.

Re-localizing after a blocked corner, the estimate the robot had is still worth much: a
Gaussian in the distance from it (at least half a metre wide), floored so that a far
place is unlikely but not ruled out, and a heading more than 60 degrees off it counts
like a missed sign.

An estimate that cannot be grossly wrong has no floor (``floor=None``): after a lift
ride the robot stands at that lift's doors on the level it asked for (the lift stops
nowhere else; a wrong floor is told by the signs, ``behaviours/lift.py``), so a place
far from them is as unlikely as the Gaussian says, and one misread plate across the
building cannot outweigh the lift's word. Its heading is a Gaussian too
(``ANCHORED_HEADING_SIGMA``): the robot turned round in the cabin on odometry, and a
hypothesis facing the other way along the corridor is ruled out, not a quarter as likely.
"""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.geometry import se2_apply, wrap_angle
from pmnav_bt.pose.hypotheses import Hypotheses
from pmnav_bt.seams import Pose2D

P_FAR = 0.005  # a place far from the estimate (the floor of the Gaussian)
P_TURNED = 0.25  # a heading more than TURNED off the estimate's
TURNED = math.radians(60.0)
MIN_SIGMA_M = 0.5  # the estimate is no surer of the place than a lattice step
# The heading of an estimate that cannot be grossly wrong: half of TURNED, so that the
# widest way into a lift's cabin (27.5 deg aside, not known to the estimate had it been
# lost) is about one sigma, and facing the other way along the corridor six.
ANCHORED_HEADING_SIGMA = TURNED / 2.0


def weigh_prior(
    logw: np.ndarray,
    hyps: Hypotheses,
    ref: Pose2D,
    map_T_odom: tuple[float, float, float],
    sigma: float,
    floor: float | None = P_FAR,
) -> None:
    """Add to ``logw`` how well each hypothesis agrees with ``map_T_odom`` (the earlier
    estimate, with its position uncertainty ``sigma`` m) at the reference ``ref``;
    ``floor``: how likely the estimate is to be grossly wrong (None: it cannot be)."""
    est = se2_apply(map_T_odom, (ref.x, ref.y))
    yaw = wrap_angle(map_T_odom[2] + ref.yaw)
    d = np.linalg.norm(hyps.xy - est, axis=1)
    turn = np.abs(np.angle(np.exp(1j * (hyps.yaw - yaw))))
    s = max(sigma, MIN_SIGMA_M)
    near = -0.5 * (d / s) ** 2
    if floor is None:
        logw += near - 0.5 * (turn / ANCHORED_HEADING_SIGMA) ** 2
        return
    logw += np.maximum(near, math.log(floor))
    logw += np.where(turn > TURNED, math.log(P_TURNED), 0.0)
