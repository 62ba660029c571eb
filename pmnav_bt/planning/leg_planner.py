"""The planner of a leg that ends at a lift: a mission across levels walks each level but
the last to the lobby of the lift it rides next (``planning/site_plan.py``), so that
leg's plan goes to the lift's landmark, not to the goal room.

``LobbyPlanner`` is a ``seams.Planner`` for such a leg: whatever goal it is asked for
(the tree's ``goal`` is the room on the last level), it plans from the start to its
``lobby`` with the graph planner (``GraphPlanner.plan_to_landmark``), under the same
constraints a replan passes (landmarks to avoid, corridors found blocked).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.planning.graph_planner import GraphPlanner
from pmnav_bt.planning.plan import Plan
from pmnav_bt.seams import PlanConstraints, PlanStart


@dataclass(frozen=True)
class LobbyPlanner:
    """Plans every request to the lift landmark ``lobby`` (see the module)."""

    lobby: str
    inner: GraphPlanner = field(default_factory=GraphPlanner)

    def plan(
        self,
        pm: PrioriMap,
        start: PlanStart,
        goal: str,
        constraints: PlanConstraints = PlanConstraints(),
    ) -> Plan:
        return self.inner.plan_to_landmark(pm, start, self.lobby, constraints)
