"""The back ends of one run, built from the config by name (the simulator and the robot alike).

``build_backends`` reads each seam's ``backend`` key of the config and asks that seam's
registry (``pmnav_bt.registry``) to build it; every factory gets the same
``BackendDeps``: the config, the priori-map, the seed, whether the run is on a robot
(where back ends that read the simulator's labels are refused), and for coarse
direction the grounder built first.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from pmnav_bt.registry import COARSE, GROUNDERS, PLANNERS, REFINERS

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import Config
    from pmnav_bt.map.priori_map import PrioriMap
    from pmnav_bt.seams import CoarseDirection, Grounder, Planner, Refiner


@dataclass
class BackendDeps:
    """What a factory may use to build its back end."""

    config: Config
    pm: PrioriMap
    seed: int = 0
    on_robot: bool = False
    grounder: Grounder | None = None  # built first; for back ends that ground (coarse)


@dataclass
class Backends:
    """The back ends of one run, built from the config."""

    grounder: Grounder
    coarse: CoarseDirection
    refiner: Refiner
    planner: Planner | None  # None: the map-less baseline plans nothing


def build_backends(
    config: Config, pm: PrioriMap, *, on_robot: bool, seed: int = 0, planner: bool = True
) -> Backends:
    """Every seam's back end, as ``config`` names them (the simulator and the robot alike);
    ``planner=False``: no planner (a tree variant that plans nothing, e.g. the map-less
    baseline, whose ``pm`` is then its sign vocabulary: ``map.signs_only.SignsOnly``)."""
    deps = BackendDeps(config=config, pm=pm, seed=seed, on_robot=on_robot)
    deps.grounder = GROUNDERS.build(config.grounder.backend, deps)
    return Backends(
        grounder=deps.grounder,
        coarse=COARSE.build(config.coarse.backend, deps),
        refiner=REFINERS.build(config.refiner.backend, deps),
        planner=PLANNERS.build(config.planner.backend, deps) if planner else None,
    )
