"""Tree variants by name (``tree.variant``): the one place that says how each variant's
context and tree are built and what of the building it may read.

A variant is a ``TreeVariant``: its tree builder (``"package.module:function"``, imported
when the tree is built, as back-end factories are: this core module imports neither
py_trees nor a tree, so the config checks ``tree.variant`` against it when it loads) and
its ``Knowledge``, what it may read of the building:

- ``PRIORI_MAP``: the whole priori-map; a planner; drives round obstacles only to points
  inside the map's corridors (PM-Nav and its ablations).
- ``SIGN_VOCABULARY``: only which sign names which room (``map.signs_only.SignsOnly``),
  no planner, and no walls to check a detour against beyond what depth shows (the
  map-less baseline). A leaf that reads the map anyway fails on it (``MapAccessError``).

    >>> TREE_VARIANTS.names()
    ['pmnav', 'coarse_only', 'mapless']

New variants: ``TREE_VARIANTS.register(TreeVariant("mine", "my_pkg.tree:build",
PRIORI_MAP, "my tree", "what it does"))`` and ``--set tree.variant=mine``. The context
(``trees.runner.make_context``) and the tree (``trees.runner.build_tree``) follow.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pmnav_bt.map.signs_only import SignsOnly
from pmnav_bt.registry import Named, load

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.map.priori_map import PrioriMap

# Whether a point (x, y) round an obstacle stays ``margin`` m clear of the walls, by what
# the tree variant knows of them (PM-Nav: the priori-map's corridors); the drive's depth
# has already shown the floor free up to it. Given to the Context where the variant is
# built; None: the variant knows no walls (the map-less baseline).
DetourCheck = Callable[[tuple[float, float], float], bool]


def within_corridors(pm: PrioriMap) -> DetourCheck:
    """A detour point must lie ``margin`` m inside one of the priori-map's corridors."""

    def clear(p: tuple[float, float], margin: float) -> bool:
        loc = pm.locate(*p)
        return loc.offset <= loc.segment.width / 2.0 - margin

    return clear


@dataclass(frozen=True)
class Knowledge:
    """What a variant may read of the building, and what follows from it: ``known(pm)``
    is what its Context's ``pm`` is (the back ends are built on it too); ``plans``: it gets
    the configured planner; ``detour_check(known)``: its drives' check of a point round an
    obstacle (``DetourCheck``; None: depth only)."""

    name: str
    known: Callable[[PrioriMap], Any]
    plans: bool
    detour_check: Callable[[Any], DetourCheck | None]


PRIORI_MAP = Knowledge("the priori-map", lambda pm: pm, True, within_corridors)
SIGN_VOCABULARY = Knowledge(
    "the sign vocabulary", lambda pm: SignsOnly(pm.building), False, lambda _signs: None
)


@dataclass(frozen=True)
class TreeVariant:
    """A named tree variant: ``tree``, its builder ``(ctx, goal) -> BehaviourTree`` as
    ``"package.module:function"``; ``knows``, what it may read; ``label``, its name in
    results; ``summary``, one line for people."""

    name: str
    tree: str
    knows: Knowledge
    label: str
    summary: str

    def build_tree(self, ctx: Any, goal: str) -> Any:
        """This variant's tree (a py_trees ``BehaviourTree``) for ``goal`` on ``ctx`` (a
        ``behaviours.context.Context`` built for it)."""
        return load(self.tree)(ctx, goal)


TREE_VARIANTS = Named(
    "tree.variant",
    "tree variant",
    [
        TreeVariant(
            "pmnav",
            "pmnav_bt.trees.pmnav:build_pmnav_tree",
            PRIORI_MAP,
            "PM-Nav",
            "localize, plan on the priori-map, then per step search, verify and approach",
        ),
        TreeVariant(
            "coarse_only",
            "pmnav_bt.trees.pmnav:build_coarse_only_tree",
            PRIORI_MAP,
            "coarse-only",
            "PM-Nav without grounding or refinement of the view direction (paper Table 4)",
        ),
        TreeVariant(
            "mapless",
            "pmnav_bt.trees.mapless:build_mapless_tree",
            SIGN_VOCABULARY,
            "map-less baseline",
            "frontier exploration on depth, no priori-map, no plan (docs/baseline.md)",
        ),
    ],
    TreeVariant,
)
