"""The declarative terminate of PmNavBehaviour: JOBS are cancelled whenever a leaf ends,
the body is stopped only when the leaf is interrupted (the test doubles' body, and a
simulated one), and every leaf that submits a worker job names it in JOBS."""

from __future__ import annotations

import ast
import inspect
import math
from pathlib import Path

import pytest
from py_trees.common import Status

from pmnav_bt import behaviours
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.seams import Pose2D

SOUTH_AT_20 = Pose2D(0.0, 20.0, math.radians(-90))


class _Waits(PmNavBehaviour):
    """Submits a job and fails on its second tick, whatever the job does."""

    JOBS = ("_job",)
    STOPS_BASE = True

    def initialise(self) -> None:
        self._ticks = 0
        self._job = self.ctx.worker.submit(lambda c: 42)

    def update(self) -> Status:
        self._ticks += 1
        if self._ticks < 2:
            self.ctx.base.set_velocity(0.2, 0.0)
            return Status.RUNNING
        return Status.FAILURE


def test_a_leaf_that_fails_with_its_job_in_flight_cancels_the_job(make_rig):
    rig = make_rig(SOUTH_AT_20)
    release = rig.hold_worker()
    leaf = _Waits("Waits", rig.ctx)
    assert rig.tick(leaf) == Status.RUNNING
    job = leaf._job
    assert rig.tick(leaf) == Status.FAILURE  # not interrupted: it ended on its own
    assert job.cancelled.is_set() and leaf._job is None
    assert rig.body.velocity_command == (0.2, 0.0)  # the body is left as the leaf left it
    release.set()


@pytest.mark.parametrize("body", ["doubles", "pybullet"], indirect=True)
def test_an_interrupted_leaf_cancels_its_job_and_stops_the_body(make_rig):
    rig = make_rig(SOUTH_AT_20)
    release = rig.hold_worker()
    leaf = _Waits("Waits", rig.ctx)
    assert rig.tick(leaf) == Status.RUNNING
    job = leaf._job
    leaf.stop(Status.INVALID)
    assert job.cancelled.is_set()
    assert rig.stopped()
    release.set()


def _leaf_classes() -> list[type[PmNavBehaviour]]:
    root = Path(inspect.getfile(behaviours)).parent
    found = []
    for path in sorted(root.glob("*.py")):
        module = __import__(f"pmnav_bt.behaviours.{path.stem}", fromlist=["_"])
        for obj in vars(module).values():
            if (
                inspect.isclass(obj)
                and issubclass(obj, PmNavBehaviour)
                and obj.__module__ == module.__name__
            ):
                found.append(obj)
    return found


def _submitted_attributes(cls: type) -> set[str]:
    """``self.X`` names assigned a value that calls ``worker.submit`` in the class body."""
    tree = ast.parse(inspect.getsource(cls).lstrip())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and any(
            isinstance(n, ast.Attribute) and n.attr == "submit" for n in ast.walk(node.value)
        ):
            for t in node.targets:
                if isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name):
                    names.add(t.attr)
    return names


@pytest.mark.parametrize("cls", _leaf_classes(), ids=lambda c: c.__name__)
def test_every_worker_job_a_leaf_holds_is_named_in_jobs(cls):
    missing = _submitted_attributes(cls) - set(cls.JOBS)
    assert not missing, f"{cls.__name__} submits into {sorted(missing)} but JOBS = {cls.JOBS}"
