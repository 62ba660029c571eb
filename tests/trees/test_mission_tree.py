"""The mission's tree ticks as py_trees' does: the handlers, the statuses, every visitor
shown what it asks for (the nodes ticked, or every node); only the walk over the whole
tree with no visitor asking for it is left out."""

from __future__ import annotations

import py_trees
from py_trees.common import Status

from pmnav_bt.trees.mission import MissionTree


class Seen(py_trees.visitors.VisitorBase):
    def __init__(self, full: bool):
        super().__init__(full=full)
        self.names: list[str] = []

    def run(self, behaviour) -> None:
        self.names.append(behaviour.name)


def root() -> py_trees.behaviour.Behaviour:
    return py_trees.composites.Selector(
        "Root",
        memory=False,
        children=[
            py_trees.behaviours.Running(name="Runs"),
            py_trees.behaviours.Success(name="NeverReached"),
        ],
    )


def test_a_mission_tree_ticks_as_py_trees_does():
    ours, theirs = MissionTree(root()), py_trees.trees.BehaviourTree(root())
    for tree in (ours, theirs):
        tree.visitors += [Seen(full=False), Seen(full=True)]
        handled = []
        tree.add_pre_tick_handler(lambda t, h=handled: h.append("pre"))
        tree.add_post_tick_handler(lambda t, h=handled: h.append("post"))
        tree.tick()
        tree.tick()
        assert handled == ["pre", "post", "pre", "post"]
        assert tree.count == 2 and tree.root.status == Status.RUNNING
    for mine, py in zip(ours.visitors, theirs.visitors, strict=True):
        assert mine.names == py.names
    ticked, every = ours.visitors
    assert "NeverReached" not in ticked.names and "NeverReached" in every.names
