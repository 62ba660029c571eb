"""What every tree variant's tree is made of at the top: its mission beside the Monitor
(action budget, body faults), the goal on the blackboard; and the one composite the
missions are strung from, a sequence that remembers where it is."""

from __future__ import annotations

import py_trees
from py_trees.common import Access
from py_trees.composites import Parallel, Sequence

from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.monitor import Monitor


def sequence(name: str, *children: py_trees.behaviour.Behaviour) -> Sequence:
    """``children`` one after the other, each ticked until it ends (py_trees' Sequence with
    memory): a child that succeeds is not ticked again until the sequence starts over."""
    return Sequence(name, memory=True, children=list(children))


def monitored_mission(
    ctx: Context, name: str, mission: py_trees.behaviour.Behaviour, goal: str
) -> py_trees.trees.BehaviourTree:
    """The tree ``name``: ``mission`` and the Monitor side by side (the first to succeed
    ends it; the Monitor fails it on a spent budget or a body fault), ``goal`` (a room as
    a person names it) written to the blackboard for the mission's first leaf."""
    root = Parallel(
        name,
        policy=py_trees.common.ParallelPolicy.SuccessOnOne(),
        children=[Monitor("Monitor", ctx), mission],
    )
    bb = py_trees.blackboard.Client(name="setup", namespace=NAMESPACE)
    bb.register_key(key="goal", access=Access.WRITE)
    bb.goal = goal
    return py_trees.trees.BehaviourTree(root)
