"""The navigation task's numbers, defined once: success radius, stop offset, action budget.

- Success: the agent stops within ``SUCCESS_RADIUS_M`` of the goal room's door point.
- The tree stops ``STOP_OFFSET_M`` from the door towards the corridor (``tree.goal_offset``),
  well inside the success radius.
- The action budget is ``BUDGET_ACTIONS`` (Habitat ObjectNav), raised to
  ``BUDGET_PATH_FACTOR`` times the forward steps the corridor route alone needs when
  that is more (long routes in large buildings).
"""

from __future__ import annotations

import math

from pmnav_bt.seams import FORWARD_STEP_M

SUCCESS_RADIUS_M = 1.0  # stop within this distance (m) of the goal door point
STOP_OFFSET_M = 0.6  # the tree's stop point: this far from the door towards the corridor
BUDGET_ACTIONS = 500  # actions per episode (Habitat ObjectNav)
BUDGET_PATH_FACTOR = 3.0  # ... or this many times the forward steps of the route, if more


def action_budget(
    route_m: float | None,
    actions: int = BUDGET_ACTIONS,
    path_factor: float = BUDGET_PATH_FACTOR,
) -> int:
    """Actions allowed for an episode whose corridor route is ``route_m`` metres long.

    ``max(actions, ceil(path_factor * route_m / FORWARD_STEP_M))``; ``actions`` alone
    when the route is unknown (None).
    """
    if route_m is None:
        return int(actions)
    return max(int(actions), int(math.ceil(path_factor * route_m / FORWARD_STEP_M)))


def budget_rule(actions: int = BUDGET_ACTIONS, path_factor: float = BUDGET_PATH_FACTOR) -> str:
    """The budget rule in words, to print with results."""
    return (
        f"Action budget: max({actions}, {path_factor:g} x corridor route length / "
        f"{FORWARD_STEP_M:g} m) actions."
    )
