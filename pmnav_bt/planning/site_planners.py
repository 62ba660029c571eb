"""The planners across levels by name, as the config's ``planner.backend`` names them.

``graph`` is ``site_plan.SitePlanner``; ``vlm`` is ``vlm.site_planner.SiteVlmPlanner``
(imported only when chosen). Each plans a ``SitePlan`` with
``plan(site_map, start_level, start, goal, constraints)``.
"""

from __future__ import annotations

from typing import Any

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.planning.site_plan import SitePlanner


def _graph(cfg, sm: SiteMap) -> SitePlanner:
    return SitePlanner(max_gap=cfg.planner.max_gap)


def _vlm(cfg, sm: SiteMap) -> Any:
    from pmnav_bt.vlm.site_planner import build

    return build(cfg, sm)


SITE_PLANNERS = {"graph": _graph, "vlm": _vlm}


def build_site_planner(name: str, cfg, sm: SiteMap):
    """The planner across levels of the planner back end ``name``, built from ``cfg``."""
    builder = SITE_PLANNERS.get(name)
    if builder is None:
        raise PmNavError(
            f"planner {name!r} cannot plan across levels: choose {', '.join(SITE_PLANNERS)}"
        )
    return builder(cfg, sm)
