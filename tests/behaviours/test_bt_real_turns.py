"""The turn check on a real building's walls: the Open-RMF office imported, its grid as the
world's walls and the robot's map (skips without the shared maps folder).

The office is one open-plan floor; its lanes cross it in legs of 2-3 m. The plan's last
turn (the import's waypoint names follow its lane graph, so the test takes the step before
the arrival, not a name) leaves on a short leg whose slanted wall stands 2.8 m ahead: the floor band
shows no floor there (it sees none nearer than 3.7 m), and the check said "no corridor to
take" with the way open. Depth against the grid's floor tells the open way from a wall
just ahead.
"""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.motion import CheckOpening, floor_run, out_heading
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.building import read_building_file
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.rmf_import import import_rmf, write_import
from pmnav_bt.pose.evidence.floor_model import building_grid
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.oracle import oracle_config
from pmnav_bt.trees.runner import make_context

pytestmark = pytest.mark.world


@pytest.fixture(scope="module")
def office(rmf_maps, tmp_path_factory):
    out = tmp_path_factory.mktemp("office") / "office.yaml"
    write_import(import_rmf(rmf_maps / "office" / "office.building.yaml", out), out)
    return out


@pytest.mark.parametrize("short_m, open_", [(0.0, True), (2.0, False)])
def test_a_short_leg_across_open_floor_is_taken_and_a_wall_just_ahead_is_not(
    office, clean_blackboard, short_m, open_
):
    from blackboard_kit import writer

    from pmnav_bt.sim.robot import SimBase
    from pmnav_bt.sim.world import SimWorld

    b = read_building_file(office)
    pm = parse_building(b)
    cfg = oracle_config("sim.walls=grid")
    with SimWorld(office, walls="grid") as world:
        base = SimBase(world, pose=Pose2D(0.0, 0.0, 0.0), width=320, height=240)
        ctx = make_context(base, pm, cfg, grid=building_grid(b, office.parent))
        try:
            plan = ctx.planner.plan(pm, "branch4", "coe_door")
            assert plan.steps[-1].landmark == "coe_door"
            step = plan.steps[-2]
            yaw = out_heading(plan, step)
            x, y = step.position
            # The estimate says the turn; the truth is ``short_m`` further on, towards the wall.
            base.set_pose(
                Pose2D(x + short_m * math.cos(yaw), y + short_m * math.sin(yaw), yaw)
            )
            bb = writer()
            bb.set("plan", plan)
            bb.set("target", step)
            bb.set("map_T_odom", (-short_m * math.cos(yaw), -short_m * math.sin(yaw), 0.0))
            run = floor_run(ctx, step.position, yaw, Pose2D(x, y, yaw))
            assert 2.0 < run < 4.0  # the map's floor ends before the band shows any
            check = CheckOpening("ForkChoice", ctx)
            check.setup_with_descendants()
            for _ in range(200):  # a way found shut is looked at again, seconds later
                check.tick_once()
                if check.status != Status.RUNNING:
                    break
                ctx.worker.drain()
                base.clock.wait(0.1)
            failure = bb.get("failure") if not open_ else None
            assert check.status == (Status.SUCCESS if open_ else Status.FAILURE)
            if not open_:
                assert failure.code == FailureCode.TARGET_NOT_FOUND
                assert f"no corridor to take at {step.landmark}" in failure.message
        finally:
            ctx.worker.shutdown()
            base.close()
