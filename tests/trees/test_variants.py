"""Tree variants by name (pmnav_bt/tree_variants.py): one registry builds each variant's context
and tree, refuses unknown names in one line that lists the known ones, and the evaluation's
rows name only registered variants."""

from __future__ import annotations

import dataclasses

import py_trees
import pytest

from pmnav_bt.backends import Backends
from pmnav_bt.behaviours.motion import Approach
from pmnav_bt.behaviours.policy_approach import PolicyApproach
from pmnav_bt.config import load_config
from pmnav_bt.errors import ConfigError
from pmnav_bt.experiments.variants import VARIANTS, Variant, variant_configs
from pmnav_bt.testing.doubles import (
    FakeBase,
    FakeCoarseDirection,
    FakePlanner,
    FakeRefiner,
    ScriptedGrounder,
)
from pmnav_bt.testing.oracle import ORACLE
from pmnav_bt.tree_variants import PRIORI_MAP, TREE_VARIANTS, TreeVariant
from pmnav_bt.trees.runner import build_tree, make_context


@dataclasses.dataclass
class DrivingRefiner(FakeRefiner):
    """A refiner that declares it drives the approach (as a pixel-goal policy does)."""

    drives_approach = True
    max_steps = 8


def context(fig2_map, variant: str, refiner=None):
    backends = Backends(
        ScriptedGrounder(fig2_map), FakeCoarseDirection(), refiner or FakeRefiner(), FakePlanner()
    )
    cfg = load_config(overrides=[ORACLE, f"tree.variant={variant}"])
    return make_context(FakeBase(), fig2_map, cfg, backends=backends)


def approaches(ctx) -> set[type]:
    py_trees.blackboard.Blackboard.clear()
    try:
        tree = build_tree(ctx, "room4")
    finally:
        ctx.worker.shutdown()
    return {type(n) for n in tree.root.iterate() if isinstance(n, Approach)}


def test_an_unknown_tree_variant_is_one_line_that_lists_the_known_ones(fig2_map):
    with pytest.raises(ConfigError) as info:
        context(fig2_map, "fancy")
    msg = str(info.value)
    assert "\n" not in msg and "tree.variant: unknown tree variant 'fancy'" in msg
    assert "registered: pmnav, coarse_only, mapless" in msg
    row = Variant("fancy", "fancy", (("tree.variant", "pmnav_fancy"),))
    with pytest.raises(ConfigError, match="variant fancy: .*unknown tree variant 'pmnav_fancy'"):
        row.config(load_config())


def test_every_evaluation_row_names_a_registered_tree_variant():
    configs = variant_configs(load_config(), list(VARIANTS))
    assert {c.tree.variant for c in configs.values()} <= set(TREE_VARIANTS.names())
    assert configs["mapless"].tree.variant == "mapless"


def test_the_refiner_says_whether_it_drives_the_approach(fig2_map):
    assert approaches(context(fig2_map, "pmnav")) == {Approach}
    assert approaches(context(fig2_map, "pmnav", DrivingRefiner())) == {PolicyApproach}
    # coarse-only uses no refiner at all, so none drives its approach
    assert approaches(context(fig2_map, "coarse_only", DrivingRefiner())) == {Approach}


def _tiny(ctx, goal):
    return py_trees.trees.BehaviourTree(py_trees.behaviours.Success(name=f"Tiny {goal}"))


def test_a_new_variant_registers_by_name_and_gets_its_context_and_tree(fig2_map):
    TREE_VARIANTS.register(TreeVariant("tiny", f"{__name__}:_tiny", PRIORI_MAP, "tiny", "one leaf"))
    try:
        ctx = context(fig2_map, "tiny")
        try:
            assert ctx.pm is fig2_map and ctx.planner is not None
            assert build_tree(ctx, "room4").root.name == "Tiny room4"
        finally:
            ctx.worker.shutdown()
    finally:
        TREE_VARIANTS._specs.pop("tiny")
    with pytest.raises(TypeError, match="TreeVariant"):
        TREE_VARIANTS.register(object())


def test_a_nodes_back_ends_are_built_on_what_its_variant_may_read(fig2_map):
    from pmnav_bt.trees.runner import variant_backends

    cfg = load_config(overrides=[ORACLE, "tree.variant=mapless"])
    mapless = variant_backends(cfg, fig2_map, on_robot=False)
    assert mapless.planner is None and mapless.grounder is not None
    pmnav = variant_backends(load_config(overrides=[ORACLE]), fig2_map, on_robot=False)
    assert pmnav.planner is not None
    with pytest.raises(ConfigError, match="registered: pmnav, coarse_only, mapless"):
        variant_backends(load_config(overrides=["tree.variant=fancy"]), fig2_map, on_robot=False)
