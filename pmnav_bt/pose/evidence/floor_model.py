"""The walls the belief weighs depth against, by name: one seam, two back ends.

What depth shows (how far the floor runs along a bearing, a drive blocked, doors along
the walls) is evidence only against a model of where the walls are. Two models:

- ``corridors`` (``evidence.floor.CorridorFloor``): the building file's corridor
  rectangles. Everything outside them is wall: right for the built-ins, whose walls the
  simulator builds from those rectangles, and the only model a building without a grid
  has.
- ``grid`` (``evidence.likelihood_field.GridFloor``): the building's occupancy grid (its
  ``floor_plan.ros_map``), as AMCL's likelihood field model reads one: a distance
  transform of the occupied cells, a Gaussian on how far each depth return lies from the
  nearest wall, plus a term for returns no map explains. A real building is the grid, not
  its annotation: corridors drawn narrower or wider than they are, lobbies and waiting
  areas left out of the corridors, a recessed door, a pillar. Against the rectangles,
  the free floor seen across a lobby is "through a wall" under the true place.

Unset (``tree.localization_walls``), the grid is taken where the building has one, for
that reason; the rectangles elsewhere. ``wall_source`` makes the choice once per run (the
grid's distance transforms take tens of milliseconds); ``WallSource.floor`` builds the
chosen model for a belief.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from pmnav_bt.errors import ConfigError
from pmnav_bt.registry import Named, load

if TYPE_CHECKING:
    from pmnav_bt.map.floorplan import FloorPlanImage
    from pmnav_bt.map.priori_map import PrioriMap
    from pmnav_bt.pose.evidence.likelihood_field import LikelihoodField
    from pmnav_bt.pose.visibility import Visibility
    from pmnav_bt.seams import Pose2D


class FloorModel(Protocol):
    """Where the walls are, as the belief's depth evidence asks it. Positions are map
    points under each hypothesis (``here``: (N, 2), the robot; ``tfs``: (N, 3) the
    hypotheses' map_T_odom); log-likelihoods are added to ``logw`` in place."""

    def stand(self, logw: np.ndarray, here: np.ndarray) -> None:
        """A hypothesis that puts the robot inside a wall is unlikely."""

    def blocked_log(self, tfs: np.ndarray, xy, blocked: float) -> np.ndarray:
        """(N,) log-weights for a drive blocked from ``xy`` (straightened odometry) heading
        ``blocked``: a hypothesis under which the floor goes on just ahead is unlikely."""

    def depth_ray(
        self,
        logw: np.ndarray,
        tfs: np.ndarray,
        here: np.ndarray,
        odom: Pose2D,
        yaw: float,
        free: float,
        travelled: float,
        at_look: bool,
    ) -> None:
        """The free floor seen in depth along ``yaw`` from ``odom`` (``free`` m to the first
        thing standing on it): at a look round (``at_look``) or one view ahead while
        driving (weaker: the same wall is seen again every metre). ``travelled``: how far
        (m, odometry) ``odom`` is from the belief's reference, from which drift grows."""

    def clear(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(K,) whether the line of sight from each ``a`` to each ``b`` ((K, 2) map) stays
        on the floor (a door's front seen from the robot)."""

    def reach(self, xy: np.ndarray, angles: np.ndarray, most: float) -> np.ndarray:
        """(A,) how far (m, at most ``most``) the floor runs from ``xy`` along each of
        ``angles`` (map): what a look round from there shows in depth."""


@dataclass(frozen=True)
class FloorModelSpec:
    """A named wall model: its factory (``"module:function"``, ``(pm, vis, field) ->
    FloorModel``), whether it needs the building's grid, a summary."""

    name: str
    factory: str
    summary: str
    needs_grid: bool = False


WALL_MODELS = Named(
    "tree.localization_walls",
    "wall model",
    [
        FloorModelSpec(
            "corridors",
            "pmnav_bt.pose.evidence.floor:corridor_floor",
            "the building file's corridor rectangles; outside them is wall",
        ),
        FloorModelSpec(
            "grid",
            "pmnav_bt.pose.evidence.likelihood_field:grid_floor",
            "the building's occupancy grid (floor_plan.ros_map) as a likelihood field",
            needs_grid=True,
        ),
    ],
    FloorModelSpec,
)


@dataclass(frozen=True)
class WallSource:
    """The chosen wall model (``name``) and, for the grid, its likelihood field."""

    name: str
    field: LikelihoodField | None = None

    def floor(self, pm: PrioriMap, vis: Visibility) -> FloorModel:
        """The model for a belief on ``pm`` (``vis``: its lattice)."""
        return load(WALL_MODELS.spec(self.name).factory)(pm, vis, self.field)


CORRIDORS = WallSource("corridors")


def wall_source(name: str | None, grid: FloorPlanImage | None) -> WallSource:
    """The wall model ``name`` (None: ``grid`` where there is one, else ``corridors``),
    its field built from ``grid`` when it needs one. Naming ``grid`` for a building
    without one is a ConfigError."""
    if name is None:
        name = "corridors" if grid is None else "grid"
    spec = WALL_MODELS.spec(name)
    if not spec.needs_grid:
        return WallSource(name)
    if grid is None:
        raise ConfigError(
            f"tree.localization_walls: {name!r} needs the building's occupancy grid "
            "(floor_plan.ros_map; in the simulator, with sim.walls=grid), and there is none; "
            "use 'corridors' or unset it"
        )
    from pmnav_bt.pose.evidence.likelihood_field import LikelihoodField

    return WallSource(name, LikelihoodField.of(grid))


def building_grid(building, base_dir) -> FloorPlanImage | None:
    """The occupancy grid of ``building`` (a ``map.building.Building``): its
    ``floor_plan.ros_map``, relative to ``base_dir`` (the building file's folder); None
    without one (a plan image is a drawing, not a map of where the walls stand)."""
    spec = building.floor_plan
    if spec is None or spec.ros_map is None:
        return None
    from pathlib import Path

    from pmnav_bt.map.floorplan import load_ros_map

    return load_ros_map(Path(base_dir) / spec.ros_map)
